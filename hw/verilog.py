"""Verilog and CXXRTL text of a component, without any command-line code.

``generate_verilog(params)`` is what ``fpga-robotics export`` writes and what the Verilator
backend compiles; ``port_values`` is the port list every back-end conversion uses.
"""

import re

from amaranth.back import cxxrtl, rtlil, verilog
from amaranth.hdl import Const, Value, ValueCastable
from amaranth.hdl._ir import PortDirection  # no public name in Amaranth 0.5; its back-ends use it
from amaranth.lib import wiring

from .params import FollowTargetParams
from .top import FollowTarget

__all__ = [
    "TOP_NAME",
    "directed_ports",
    "generate_cxxrtl",
    "generate_verilog",
    "port_values",
    "verilog_ports",
]

#: Module name of the top in the generated Verilog and C++.
TOP_NAME = "follow_target"


def _port_items(component):
    for path, member, value in component.signature.flatten(component):
        if isinstance(value, ValueCastable):
            value = value.as_value()
        value = Value.cast(value)
        # Constant members (``ready`` of a stream that cannot be stalled) are no ports:
        # the back-ends reject them.
        if not isinstance(value, Const):
            yield path, member, value


def port_values(component):
    """``[Value]`` of a component's ports in signature order."""
    return [value for _path, _member, value in _port_items(component)]


def verilog_ports(component):
    """``{name: (value, "i"|"o")}``: the ports of a component, named ``member__sub`` as
    Amaranth names them."""
    return {
        "__".join(map(str, path)): (value, "i" if member.flow == wiring.In else "o")
        for path, member, value in _port_items(component)
    }


def directed_ports(component):
    """``{name: (value, PortDirection)}``: the ports ``verilog_ports`` names, each with its
    declared direction, as Amaranth's own conversion gives them. An output the design never
    drives stays an output (constant 0); with direction None Amaranth would infer an input."""
    directions = {"i": PortDirection.Input, "o": PortDirection.Output}
    return {
        name: (value, directions[direction])
        for name, (value, direction) in verilog_ports(component).items()
    }


def generate_verilog(params=None, component=None):
    """Verilog text of ``FollowTarget(params)`` (or of ``component``), top module
    ``follow_target``. Ports: ``clk rst pixels__valid pixels__payload color_sel
    filtered__valid filtered__payload frame_done found proximity centroid_x centroid_leds
    motor_left motor_right``. Without the design's ``Assert``/``Assume``/``Cover``: only
    pysim checks those in a run (``fpga-robotics formal`` proves them)."""
    if component is None:
        component = FollowTarget(FollowTargetParams() if params is None else params)
        # Direction None: Amaranth infers it (driven inside the design = output).
        ports = {name: (value, None) for name, (value, _) in verilog_ports(component).items()}
    else:
        ports = port_values(component)
    # The private conversion step of verilog.convert: no public one takes RTLIL text.
    return verilog._convert_rtlil_text(_rtlil_without_checks(component, ports))


def generate_cxxrtl(component):
    """CXXRTL C++ text of ``component``, top class ``p_follow__target``, without its
    ``Assert``/``Assume``/``Cover`` (as ``generate_verilog``)."""
    text = _rtlil_without_checks(component, port_values(component))
    return cxxrtl._convert_rtlil_text(text, None)


#: An RTLIL ``$check`` cell (an Assert, Assume or Cover): its block up to its own ``end``.
_CHECK_CELL = re.compile(r"^( *)cell \$check \S+\n.*?^\1end\n", re.MULTILINE | re.DOTALL)


def _rtlil_without_checks(component, ports):
    """RTLIL text of ``component`` without its formal checks: the compiled simulators would
    print a failing ``Assert`` (Verilator on every clock, CXXRTL once) and run on; only
    pysim stops at one. ``$check`` cells drive nothing, so nothing else changes."""
    text = rtlil.convert(component, name=TOP_NAME, ports=ports, emit_src=False)
    return _CHECK_CELL.sub("", text)
