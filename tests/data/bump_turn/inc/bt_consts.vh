localparam signed [11:0] FWD = 12'sd250;
localparam signed [11:0] REV = -12'sd200;
