// Constants of red_count.v.
`define RED_MIN 4'd8
`define MIN_PIXELS 17'd20
`define ROWS 9'd120
`define SPEED 16'sd200
