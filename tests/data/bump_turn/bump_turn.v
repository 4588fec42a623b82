// Drive forward; on a bump reverse for HOLD cycles, then spin for HOLD cycles, then forward.
module bump_turn #(parameter integer HOLD = 5000) (
  input wire clk,
  input wire rst,
  input wire bumper_n,     // despite the name: 1 = pressed
  output reg signed [11:0] ml,
  output reg signed [11:0] mr,
  output wire [1:0] st_o
);
`include "inc/bt_consts.vh"
  reg [1:0] st;
  reg [15:0] cnt;
  reg sync_b = 1'b0;       // no reset: power-on value only
  always @(posedge clk) sync_b <= bumper_n;
  always @(posedge clk) begin
    if (rst) begin st <= 2'd0; cnt <= 16'd0; end
    else case (st)
      2'd0: if (sync_b) begin st <= 2'd1; cnt <= HOLD; end
      2'd1: if (cnt == 0) begin st <= 2'd2; cnt <= HOLD; end else cnt <= cnt - 1;
      2'd2: if (cnt == 0) st <= 2'd0; else cnt <= cnt - 1;
      default: st <= 2'd0;
    endcase
  end
  always @(*) case (st)
    2'd1: begin ml = REV; mr = REV; end
    2'd2: begin ml = FWD; mr = -FWD; end
    default: begin ml = FWD; mr = FWD; end
  endcase
  assign st_o = st;
endmodule
