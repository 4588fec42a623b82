// A watch output wider than a pin port (70 bits): bit 0 is high for the one cycle the counter
// is 3, bit 64 when it is 20, bit 69 when it is 40; the rest never (tests/test_pin_watch.py).
module watch_wide (
  input clk,
  input rst,
  input bump_i,  // unused: a pin design has a connector
  output signed [11:0] left_dps,
  output signed [11:0] right_dps,
  output [69:0] flags
);
  reg [7:0] count;
  always @(posedge clk)
    if (rst) count <= 8'd0;
    else if (count != 8'hff) count <= count + 8'd1;
  assign flags = {count == 8'd40, 4'b0, count == 8'd20, 63'b0, count == 8'd3};
  assign left_dps = 12'sd0;
  assign right_dps = 12'sd0;
endmodule
