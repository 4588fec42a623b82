"""Export a design as one self-contained Verilog file: ``generate_verilog(params)`` for
``follow_target``, ``generate_top_verilog(component, name)`` for the sensor designs
(``fpga-robotics export`` is the command, ``fpga_robotics.cli.export``)."""

from amaranth.back import verilog

from fpga_robotics.hw.verilog import TOP_NAME, directed_ports, generate_verilog

__all__ = ["TOPS", "generate_top_verilog", "generate_verilog"]

#: The designs ``--top`` exports; each is also its Verilog module's name.
TOPS = (
    TOP_NAME,
    "follow_target_safe",
    "follow_line",
    "corridor_follow",
    "corridor_follow_uart",
    "turret_tracker",
)


def generate_top_verilog(component, name):
    """Verilog text of a sensor design's ``component`` (``FollowTargetSafe``, ``FollowLine``),
    top module ``name``, its ports named as Amaranth names them (``pixels__valid``).

    Each port keeps its declared direction: an output the design never drives is still an
    output (constant 0), as Amaranth's own conversion makes it."""
    return verilog.convert(component, name=name, ports=directed_ports(component), emit_src=False)
