"""A foreign design for the tests: the exported ``follow_target`` behind other port names, an
active-low reset, separate first/last flags and a 2-bit colour code of its own, with only the
LED code and the wheels as outputs (``RENAMED``, to be formatted with ``xmsb``, the centroid's
top bit), and its port map (``RENAMED_MAP``, formatted with the result ``latency``)."""

RENAMED = """\
module robot_top (
  input clock, input reset_n,
  input px_valid, input [11:0] px_rgb, input px_sof, input px_eol,
  input [1:0] colour,
  output result_ready, output [7:0] leds,
  output signed [15:0] left_dps, output signed [15:0] right_dps
);
  wire [2:0] sel = colour == 2'd0 ? 3'b100 : colour == 2'd1 ? 3'b010 : 3'b001;
  wire fv; wire [13:0] fp; wire found; wire [2:0] prox; wire [%(xmsb)d:0] cx;
  follow_target core (
    .clk(clock), .rst(~reset_n), .pixels__valid(px_valid),
    .pixels__payload({px_eol, px_sof, px_rgb}), .color_sel(sel),
    .filtered__valid(fv), .filtered__payload(fp), .frame_done(result_ready),
    .found(found), .proximity(prox), .centroid_x(cx), .centroid_leds(leds),
    .motor_left(left_dps), .motor_right(right_dps)
  );
endmodule
"""

RENAMED_MAP = """\
style = "stream"
top = "robot_top"
clock = { port = "clock" }
reset = { port = "reset_n", active_low = true }
pixels = { valid = "px_valid", data = "px_rgb", first = "px_sof", last = "px_eol" }
color = { port = "colour", codes = { red = 0, green = 1, blue = 2 } }
result = { strobe = "result_ready", latency = %(latency)d }

[outputs]
centroid_leds = "leds"
motor_left = { port = "left_dps", width = 16, signed = true }
motor_right = { port = "right_dps", width = 16, signed = true }
"""
