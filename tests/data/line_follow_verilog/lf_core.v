`include "lf_defs.vh"
// Control law core: a 2-flop synchroniser WITHOUT reset (power-on value 0 by initial),
// last-seen side with a synchronous active-high reset.
module lf_core #(parameter signed [15:0] BASE = 16'sd450) (
  input clk,
  input rst,
  input [2:0] raw,
  output reg signed [15:0] left,
  output reg signed [15:0] right,
  output reg [1:0] act
);
  reg [2:0] s1 = 3'b000;
  reg [2:0] s2 = 3'b000;
  always @(posedge clk) begin
    s1 <= raw;
    s2 <= s1;
  end
  reg side_right;
  always @(posedge clk) begin
    if (rst) begin
      side_right <= 1'b0;
      left <= 16'sd0; right <= 16'sd0; act <= 2'd0;
    end else begin
      if (s2[0] && !s2[2]) side_right <= 1'b0;
      else if (s2[2] && !s2[0]) side_right <= 1'b1;
      case (s2)
        3'b010, 3'b111, 3'b101: begin left <= BASE; right <= BASE; act <= 2'd1; end
        3'b001: begin left <= BASE - `LF_SHARP; right <= BASE + `LF_SHARP; act <= 2'd2; end
        3'b011: begin left <= BASE - `LF_GENTLE; right <= BASE + `LF_GENTLE; act <= 2'd2; end
        3'b100: begin left <= BASE + `LF_SHARP; right <= BASE - `LF_SHARP; act <= 2'd3; end
        3'b110: begin left <= BASE + `LF_GENTLE; right <= BASE - `LF_GENTLE; act <= 2'd3; end
        default: begin
          act <= 2'd0;
          if (side_right) begin left <= `LF_SEARCH; right <= -`LF_SEARCH; end
          else begin left <= -`LF_SEARCH; right <= `LF_SEARCH; end
        end
      endcase
    end
  end
endmodule
