`include "lf_defs.vh"
module lf_top #(parameter integer SPEED = 300) (
  input clock,
  input resetn,
  input [2:0] sens,
  output signed [15:0] wl,
  output signed [15:0] wr,
  output [1:0] act_o
);
  lf_core #(.BASE(SPEED)) core (.clk(clock), .rst(!resetn), .raw(sens), .left(wl), .right(wr), .act(act_o));
endmodule
