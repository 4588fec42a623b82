// Counts clock edges from the reset; at the edge that samples n == 5499 (edge 5500) it calls
// the system task the `which` input selects: 1 $finish, 2 $stop, 3 $fatal (0: none).
module stopper (
  input clk,
  input rst,
  input bump,
  input [1:0] which,
  output reg [15:0] n
);
  always @(posedge clk) begin
    if (rst) n <= 16'd0;
    else n <= n + 16'd1;
    if (!rst && n == 16'd5499) begin
      if (which == 2'd1) $finish;
      if (which == 2'd2) $stop;
      if (which == 2'd3) $fatal(1, "stopper: fatal at n = %0d", n);
    end
  end
endmodule
