// A camera design in plain Verilog with no reset (its registers start at their initial
// values) and its constants in an included header: counts the pixels whose red nibble is at
// least `RED_MIN in each frame and drives on while the frame has more than `MIN_PIXELS.
`include "red_count_defs.vh"
module red_count (
  input clk,
  input pix_valid,
  input [13:0] pix_payload,  // data[11:0] (RGB444, red in [11:8]), first[12], last[13]
  output signed [15:0] left,
  output signed [15:0] right,
  output reg done = 1'b0
);
  reg [16:0] count = 17'd0;
  reg [16:0] seen = 17'd0;
  reg [8:0] row = 9'd0;
  wire red = pix_payload[11:8] >= `RED_MIN;
  wire first = pix_payload[12];
  wire last = pix_payload[13];
  always @(posedge clk) begin
    done <= 1'b0;
    if (pix_valid) begin
      count <= (first ? 17'd0 : count) + red;
      row <= first ? 9'd0 : row + last;
      if (last && row == `ROWS - 1) begin
        seen <= count + red;
        done <= 1'b1;
      end
    end
  end
  assign left = seen > `MIN_PIXELS ? `SPEED : 16'sd0;
  assign right = left;
endmodule
