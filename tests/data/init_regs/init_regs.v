// No reset: an LFSR and a counter that start from initial values with ones in them, on the
// wheels, held while the bumper is pressed. A copy that started its registers anywhere else
// drives otherwise.
module init_regs (
  input clk,
  input bump_i,
  output signed [15:0] left,
  output signed [15:0] right
);
  reg [15:0] lfsr = 16'hA5C3;
  reg [3:0] count = 4'b1011;
  always @(posedge clk) if (!bump_i) begin
    lfsr <= {lfsr[14:0], lfsr[15] ^ lfsr[13] ^ lfsr[12] ^ lfsr[10]};
    count <= count + 4'd1;
  end
  assign left = lfsr;
  assign right = {12'd0, count};
endmodule
