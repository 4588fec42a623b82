"""The GoPiGo3 robot's board: ``FollowTarget`` on a ULX3S (ECP5 LFE5U-85F) with an OV7670.

This file only connects pins and clocks; the logic is ``robot_core.RobotCore``, whose
``FollowTarget`` is the very component the simulations run, unchanged.

- Clock: 25 MHz oscillator -> PLL -> 50 MHz ``sync`` domain (``clocking.BoardClocking``).
  Reset: power-on, PLL not locked, or the FIRE1 button (held = reset).
- ``pclk`` domain: the camera's PCLK pin; reset by FIRE1 too (and at power-on).
- Camera: XCLK = 50 MHz / 4 = 12.5 MHz, reset pin inactive (high), SCCB at 100 kHz.
- ``color_sel`` from DIP switches SW1..SW3 (red when all are off).
- The 8 user LEDs show ``centroid_leds`` (LED 0 = leftmost bin).
- GoPiGo3 over SPI at 500 kHz on the pins of ``pins.py``.
"""

from amaranth.hdl import Cat, ClockDomain, ClockSignal, Elaboratable, Module
from amaranth.lib import io
from amaranth.lib.cdc import ResetSynchronizer
from amaranth_boards.ulx3s import ULX3S_85F_Platform

from ..params import FollowTargetParams
from ..validate import CheckedArguments
from .clocking import BoardClocking
from .pins import camera_resources, gopigo3_spi_resources
from .robot_core import RobotCore, RobotTiming

__all__ = ["OSC_FREQ", "SYS_CLK_FREQ", "ULX3SFollowTarget", "ulx3s_platform"]

OSC_FREQ = 25e6
SYS_CLK_FREQ = 50e6


def ulx3s_platform():
    """``ULX3S_85F_Platform`` with the camera and GoPiGo3 SPI resources of ``pins.py``."""
    platform = ULX3S_85F_Platform()
    platform.add_resources(camera_resources() + gopigo3_spi_resources())
    return platform


class ULX3SFollowTarget(CheckedArguments, Elaboratable):
    """Board top: ``RobotCore`` (with ``FollowTarget``) wired to the ULX3S.

    Parameters
    ----------
    params : FollowTargetParams, optional
        Design parameters; the camera's register table produces 160x120, so the geometry
        must be that.
    sys_clk_freq : float
        Design clock in Hz (an even multiple of the 12.5 MHz XCLK).
    """

    @staticmethod
    def check_arguments(params=None, *, sys_clk_freq=SYS_CLK_FREQ):
        """Raise ``TypeError``/``ValueError`` unless ``ULX3SFollowTarget`` accepts the
        arguments (``RobotCore``'s included)."""
        params = FollowTargetParams() if params is None else params
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        if (params.width, params.height) != (160, 120):
            raise ValueError(
                f"the OV7670 is set up for QQVGA (160x120) but the design is "
                f"{params.width}x{params.height}; build the board with the default geometry"
            )
        RobotCore.check_arguments(params, RobotTiming(sys_clk_freq))

    def __init__(self, params=None, *, sys_clk_freq=SYS_CLK_FREQ):
        params = FollowTargetParams() if params is None else params
        self.params = params
        self.sys_clk_freq = sys_clk_freq
        self.core = RobotCore(params, RobotTiming(sys_clk_freq))

    def elaborate(self, platform):
        m = Module()

        def pin(name, number, direction):
            buf = io.Buffer(direction, platform.request(name, number, dir="-"))
            m.submodules[f"{name}_{number}_buffer"] = buf
            return buf

        def sub(resource, subsignal, direction):
            buf = io.Buffer(direction, getattr(resource, subsignal))
            m.submodules[f"{subsignal}_buffer"] = buf
            return buf

        m.domains.sync = ClockDomain("sync")
        clk25 = pin("clk25", 0, "i")
        fire1 = pin("button_fire", 0, "i")
        m.submodules.clocking = BoardClocking(
            clk25.i, fire1.i, in_freq=OSC_FREQ, sys_clk_freq=self.sys_clk_freq
        )

        cam = platform.request("ov7670", 0, dir="-")
        pclk = sub(cam, "pclk", "i")
        m.domains.pclk = ClockDomain("pclk", local=True)
        m.d.comb += ClockSignal("pclk").eq(pclk.i)
        m.submodules.pclk_reset = ResetSynchronizer(fire1.i, domain="pclk")

        m.submodules.core = core = self.core
        siod = sub(cam, "siod", "io")
        m.d.comb += [
            core.cam_data.eq(sub(cam, "data", "i").i),
            core.cam_href.eq(sub(cam, "href", "i").i),
            core.cam_vsync.eq(sub(cam, "vsync", "i").i),
            sub(cam, "xclk", "o").o.eq(core.xclk),
            sub(cam, "reset", "o").o.eq(core.cam_reset),
            sub(cam, "sioc", "o").o.eq(core.sioc),
            siod.o.eq(core.siod_o),
            siod.oe.eq(core.siod_oe),
            core.switches.eq(Cat(pin("switch", i, "i").i for i in range(3))),
        ]
        for i in range(8):
            m.d.comb += pin("led", i, "o").o.eq(core.leds[i])

        spi = platform.request("gopigo3_spi", 0, dir="-")
        m.d.comb += [
            sub(spi, "clk", "o").o.eq(core.spi_sclk),
            sub(spi, "copi", "o").o.eq(core.spi_copi),
            sub(spi, "cs", "o").o.eq(core.spi_cs),
        ]
        sub(spi, "cipo", "i")  # unused (write-only link) but claimed, so the pin is constrained
        return m
