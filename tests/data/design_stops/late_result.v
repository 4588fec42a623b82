// A camera design whose result strobe `done` rises `wait_cycles` edges after the edge that
// takes a frame's last pixel (the pixel count reaches PIXELS), or never when `silent` is 1.
// The wheels stand still.
module late_result #(parameter integer PIXELS = 1200) (
  input clk,
  input rst,
  input px_valid,
  input [13:0] px_payload,
  input [15:0] wait_cycles,
  input silent,
  output reg done,
  output signed [15:0] ml,
  output signed [15:0] mr
);
  reg [15:0] seen;
  reg [15:0] left;
  reg counting;
  always @(posedge clk) begin
    done <= 1'b0;
    if (rst) begin
      seen <= 16'd0; counting <= 1'b0; left <= 16'd0;
    end else begin
      if (px_valid) seen <= (px_payload[12] ? 16'd0 : seen) + 16'd1;
      if (px_valid && (px_payload[12] ? 16'd0 : seen) == PIXELS - 1) begin
        counting <= 1'b1; left <= wait_cycles;
      end else if (counting) begin
        if (left <= 16'd1) begin counting <= 1'b0; done <= !silent; end
        else left <= left - 16'd1;
      end
    end
  end
  assign ml = 16'sd0;
  assign mr = 16'sd0;
endmodule
