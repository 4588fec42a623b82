// A ranger in plain Verilog: it measures the way ahead with an HC-SR04 every 20 ms and drives
// towards the wall, slowing down as it comes near, until it stands STOP_MM from it.
// No reset: the registers start at their initial values, as on an FPGA after configuration.
// range_mm, the last measurement, is read by no connector: the port map records it.
// The clock is 1 MHz (a scenario's sim.clock_hz = 1000000.0).
module ranger #(
  parameter STOP_MM = 300,
  parameter TOP_DPS = 300
) (
  input clk,
  output trig_o,
  input echo_i,
  output signed [15:0] left_dps,
  output signed [15:0] right_dps,
  output reg [15:0] range_mm = 16'd0
);
  localparam PERIOD = 20000;                // a measurement every 20 ms
  localparam TRIG = 10;                     // a 10 us TRIG pulse

  reg [31:0] tick = 0;
  always @(posedge clk) tick <= (tick == PERIOD - 1) ? 0 : tick + 1;
  assign trig_o = tick < TRIG;

  // ECHO is high for the sound's round trip: 0.1717 mm of range per microsecond (343 m/s
  // at 20 C), cycles * 11 / 64 in integers (0.1% off). Counts saturate: no echo within the
  // module's 38 ms timeout reads as about 6.5 m, far away.
  reg [15:0] echo_cycles = 0;
  reg echo_last = 0;
  wire [19:0] echo_mm = (echo_cycles * 20'd11) >> 6;
  always @(posedge clk) begin
    echo_last <= echo_i;
    if (echo_i && echo_cycles != 16'hffff) echo_cycles <= echo_cycles + 1;
    if (echo_last && !echo_i) begin
      range_mm <= echo_mm[15:0];
      echo_cycles <= 0;
    end
  end

  // Full speed far away, then the remaining distance in mm as DPS, 0 at STOP_MM.
  wire [15:0] left_over = range_mm > STOP_MM ? range_mm - STOP_MM : 16'd0;
  wire [15:0] speed = left_over > TOP_DPS ? TOP_DPS : left_over;
  assign left_dps = speed;
  assign right_dps = speed;
endmodule
