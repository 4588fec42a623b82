// tests/data/bump_stop.v without a reset: its register starts at its initial value, as an
// FPGA's do after configuration. Drives on at 300 DPS until the bumper closes, then stops.
module bump_stop_noreset (
  input clk,
  input bump_i,
  output signed [11:0] left_dps,
  output signed [11:0] right_dps,
  output hit_o
);
  reg hit = 1'b0;
  always @(posedge clk)
    if (bump_i) hit <= 1'b1;
  assign left_dps = hit ? 12'sd0 : 12'sd300;
  assign right_dps = left_dps;
  assign hit_o = hit;
endmodule
