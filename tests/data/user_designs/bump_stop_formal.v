// bump_stop_noreset.v with its promises as immediate assertions (read by Yosys with
// read_verilog -formal; `fpga-robotics formal --design verilog:bump_stop_formal.v`).
module bump_stop_formal (
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
`ifdef FORMAL
  reg past_valid = 1'b0;
  always @(posedge clk) past_valid <= 1'b1;
  // Once stopped, stopped for good; both wheels the same speed, 300 DPS or 0.
  always @(posedge clk) if (past_valid && $past(hit)) assert(hit);
  always @(*) assert(left_dps == right_dps);
  always @(*) assert(left_dps == 12'sd0 || left_dps == 12'sd300);
  // The bump is reachable: a cycle where the robot stops.
  always @(posedge clk) cover(past_valid && !$past(hit) && hit);
`endif
endmodule
