`define LF_GENTLE 16'sd100
`define LF_SHARP  16'sd250
`define LF_SEARCH 16'sd150
