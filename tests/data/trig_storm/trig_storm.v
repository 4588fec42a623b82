// A wall-free drive whose ultrasound trigger is quiet, or, with the runtime input `storm`
// set, toggles at every clock edge: a stand-in for a mutant that makes the loop stop at every
// edge (tests/test_stop_budget.py).
module trig_storm (
  input clk,
  input rst,
  input storm,
  input echo_i,
  output signed [11:0] left_dps,
  output signed [11:0] right_dps,
  output trig_o
);
  reg trig;
  always @(posedge clk)
    if (rst) trig <= 1'b0;
    else if (storm) trig <= ~trig;
  assign left_dps = 12'sd200;
  assign right_dps = 12'sd200;
  assign trig_o = trig;
endmodule
