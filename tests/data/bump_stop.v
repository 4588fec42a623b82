// A bumper-stop design in plain Verilog (tests/test_foreign_pins.py, docs/foreign.md): drives
// on at 300 DPS until the bumper closes, then stops for good. The same logic as docs/
// connectors.md's Amaranth BumpStop, with an active-low reset and 12-bit wheel speeds that the
// port map sign-extends.
module bump_stop (
  input clk,
  input rst_n,
  input bump_i,
  output signed [11:0] left_dps,
  output signed [11:0] right_dps,
  output hit_o
);
  reg hit;
  always @(posedge clk)
    if (!rst_n) hit <= 1'b0;
    else if (bump_i) hit <= 1'b1;
  assign left_dps = hit ? 12'sd0 : 12'sd300;
  assign right_dps = left_dps;
  assign hit_o = hit;
endmodule
