// A camera design in plain Verilog with no reset that remembers across frames: it counts the
// frames it has seen and drives both wheels at that count in DPS. Its registers start at
// their initial values; a run that starts anywhere else shows at once in the wheels.
module frame_counter #(
  parameter ROWS = 120
) (
  input clk,
  input pix_valid,
  input [13:0] pix_payload,  // data[11:0], first[12], last[13]
  output signed [15:0] left,
  output signed [15:0] right,
  output reg done = 1'b0
);
  reg [15:0] frames = 16'd0;
  reg [8:0] row = 9'd0;
  wire first = pix_payload[12];
  wire last = pix_payload[13];
  always @(posedge clk) begin
    done <= 1'b0;
    if (pix_valid) begin
      row <= first ? 9'd0 : row + last;
      if (last && row == ROWS - 1) begin
        frames <= frames + 16'd1;
        done <= 1'b1;
      end
    end
  end
  assign left = frames;
  assign right = frames;
endmodule
