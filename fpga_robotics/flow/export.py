"""Export a design as one self-contained Verilog file: ``generate_verilog(params)`` for
``follow_target``, ``generate_top_verilog(component, name)`` for the sensor designs
(``fpga-robotics export`` is the command, ``fpga_robotics.cli.export``)."""

from amaranth.back import verilog

from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.verilog import TOP_NAME, directed_ports, generate_verilog

__all__ = ["TOPS", "check_port_names", "generate_top_verilog", "generate_verilog"]

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


def check_port_names(ports, name):
    """``UserError`` if a port of design ``name`` is named ``clk`` or ``rst``: those are the
    clock domain's own ports, and Amaranth would rename the design's (``clk$3``)."""
    taken = [port for port in ("clk", "rst") if port in ports]
    if taken:
        raise UserError(
            f"design {name!r} has a port named {taken[0]!r}, the name of the clock domain's "
            f"own {'clock' if taken[0] == 'clk' else 'reset'}; rename the port"
        )
