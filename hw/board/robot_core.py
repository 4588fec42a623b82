"""Everything on the robot's FPGA except pins and clock generation, so it can be simulated.

``RobotCore`` = camera control (XCLK divider, SCCB initialisation) + pixel capture with its
clock crossing + ``FollowTarget`` (unchanged) + colour selection + the GoPiGo3 SPI link. Pixels reach
``FollowTarget`` only once the camera's registers are written (``camera_ready``); the design
itself ignores everything until the next ``first``.
It runs in ``sync`` (the design clock) and ``pclk`` (the camera's byte clock), both supplied
by the board top, which also connects the members below to pins.
"""

from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..params import FollowTargetParams
from ..top import FollowTarget
from ..validate import CheckedArguments, check_int
from .color_select import SwitchColorSelect
from .gopigo3_spi import GOPIGO3_MAX_DPS_LIMIT, GoPiGo3Motors
from .ov7670_capture import OV7670Capture
from .sccb import OV7670_INIT, SCCBInit

__all__ = ["RobotCore", "RobotTiming"]


class RobotTiming:
    """Clock-derived cycle counts, computed once from the design clock (never in elaborate).

    Parameters
    ----------
    sys_clk_freq : float
        Design clock in Hz.
    xclk_freq, sccb_freq, spi_freq : float
        Camera clock, SCCB clock and SPI clock in Hz.
    camera_wait, reset_wait, motor_wait : float
        Seconds before the first SCCB write, after the camera's software reset, and before
        the first GoPiGo3 message.
    """

    def __init__(
        self,
        sys_clk_freq=50e6,
        *,
        xclk_freq=12.5e6,
        sccb_freq=100e3,
        spi_freq=500e3,
        camera_wait=10e-3,
        reset_wait=10e-3,
        motor_wait=100e-3,
    ):
        ratio = sys_clk_freq / xclk_freq
        if ratio != int(ratio) or int(ratio) % 2:
            raise ValueError(
                f"the design clock ({sys_clk_freq / 1e6:g} MHz) must be an even multiple of "
                f"XCLK ({xclk_freq / 1e6:g} MHz)"
            )
        self.sys_clk_freq = sys_clk_freq
        self.xclk_half = int(ratio) // 2
        self.sccb_quarter = max(1, round(sys_clk_freq / sccb_freq / 4))
        self.spi_half = max(1, round(sys_clk_freq / spi_freq / 2))
        self.camera_wait = round(sys_clk_freq * camera_wait)
        self.reset_wait = round(sys_clk_freq * reset_wait)
        self.motor_wait = round(sys_clk_freq * motor_wait)

    @classmethod
    def from_cycles(cls, *, xclk_half, sccb_quarter, spi_half, camera_wait, reset_wait, motor_wait):
        """Explicit cycle counts (fast simulations use small ones)."""
        t = cls.__new__(cls)
        t.sys_clk_freq = None
        t.xclk_half, t.sccb_quarter, t.spi_half = xclk_half, sccb_quarter, spi_half
        t.camera_wait, t.reset_wait, t.motor_wait = camera_wait, reset_wait, motor_wait
        return t


def gopigo3_dps_limit(params):
    """The speed limit sent to the GoPiGo3: the design's ``max_dps``, capped at the largest
    SET_MOTOR_LIMITS carries (16383 DPS). A design without saturation (the published preset,
    ``max_dps = 32767``) so leaves the limit to the motor controller's own maximum."""
    return min(params.max_dps, GOPIGO3_MAX_DPS_LIMIT)


class RobotCore(CheckedArguments, wiring.Component):
    """The robot's logic between the board pins (see module docstring).

    Parameters
    ----------
    params : FollowTargetParams
        Design parameters of ``FollowTarget``.
    timing : RobotTiming
        Clock-derived cycle counts.
    sccb_table : sequence of RegisterWrite
        Camera register table (default ``OV7670_INIT``).

    Members
    -------
    cam_data, cam_href, cam_vsync : In
        Camera outputs, in the ``pclk`` domain.
    xclk, cam_reset : Out(1)
        Camera clock (``sync`` / (2 * xclk_half)) and camera reset (held inactive, 0).
    sioc, siod_o, siod_oe : Out(1)
        SCCB bus.
    switches : In(3)
        DIP switches SW1..SW3 (colour selection).
    leds : Out(8)
        ``centroid_leds``.
    spi_sclk, spi_copi, spi_cs : Out(1)
        GoPiGo3 SPI (``spi_cs`` active high).
    camera_ready, overflow : Out(1)
        SCCB table written; a pixel was lost in the clock crossing (sticky).
    """

    @staticmethod
    def check_arguments(params=None, timing=None, *, sccb_table=OV7670_INIT):
        """Raise ``TypeError``/``ValueError`` unless ``RobotCore`` accepts the arguments,
        its parts' included (so that none of them is built when one would be rejected)."""
        params = FollowTargetParams() if params is None else params
        t = RobotTiming() if timing is None else timing
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        for name in ("xclk_half", "sccb_quarter", "spi_half"):
            check_int(name, getattr(t, name), 1)
        SCCBInit.check_arguments(
            sccb_table,
            quarter_period=t.sccb_quarter,
            reset_wait=t.reset_wait,
            startup_wait=t.camera_wait,
        )
        GoPiGo3Motors.check_arguments(
            half_period=t.spi_half, startup_wait=t.motor_wait, dps_limit=gopigo3_dps_limit(params)
        )

    def __init__(self, params=None, timing=None, *, sccb_table=OV7670_INIT):
        self.params = FollowTargetParams() if params is None else params
        self.timing = RobotTiming() if timing is None else timing
        t = self.timing
        self.design = FollowTarget(self.params)
        self.sccb = SCCBInit(
            sccb_table,
            quarter_period=t.sccb_quarter,
            reset_wait=t.reset_wait,
            startup_wait=t.camera_wait,
        )
        self.motors = GoPiGo3Motors(
            half_period=t.spi_half,
            startup_wait=t.motor_wait,
            dps_limit=gopigo3_dps_limit(self.params),
        )
        super().__init__(
            {
                "cam_data": In(8),
                "cam_href": In(1),
                "cam_vsync": In(1),
                "xclk": Out(1),
                "cam_reset": Out(1),
                "sioc": Out(1, init=1),
                "siod_o": Out(1, init=1),
                "siod_oe": Out(1, init=1),
                "switches": In(3),
                "leds": Out(8),
                "spi_sclk": Out(1),
                "spi_copi": Out(1),
                "spi_cs": Out(1),
                "camera_ready": Out(1),
                "overflow": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        t = self.timing

        # XCLK: the design clock divided by 2 * xclk_half.
        count = Signal(range(t.xclk_half))
        with m.If(count == t.xclk_half - 1):
            m.d.sync += [count.eq(0), self.xclk.eq(~self.xclk)]
        with m.Else():
            m.d.sync += count.eq(count + 1)
        m.d.comb += self.cam_reset.eq(0)

        m.submodules.sccb = sccb = self.sccb
        m.d.comb += [
            self.sioc.eq(sccb.sioc),
            self.siod_o.eq(sccb.siod_o),
            self.siod_oe.eq(sccb.siod_oe),
            self.camera_ready.eq(sccb.done),
        ]

        # Pixels: camera bytes (pclk) -> framed stream (sync) -> FollowTarget, unchanged.
        m.submodules.capture = capture = OV7670Capture(pclk_domain="pclk")
        m.d.comb += [
            capture.data.eq(self.cam_data),
            capture.href.eq(self.cam_href),
            capture.vsync.eq(self.cam_vsync),
            self.overflow.eq(capture.overflow),
        ]
        # Until the register table is written the camera sends its power-on format (YUV,
        # VGA): drop those bytes, so that only RGB444 frames ever reach the design.
        m.submodules.design = design = self.design
        m.d.comb += [
            design.pixels.valid.eq(capture.pixels.valid & sccb.done),
            design.pixels.payload.eq(capture.pixels.payload),
        ]

        m.submodules.color_select = color = SwitchColorSelect()
        m.d.comb += [color.switches.eq(self.switches), design.color_sel.eq(color.color_sel)]
        m.d.comb += self.leds.eq(design.centroid_leds)

        # The wheel speeds are valid motor_latency cycles after frame_done: send them then.
        update = design.frame_done
        for i in range(self.params.motor_latency):
            delayed = Signal(name=f"update_delay_{i}")
            m.d.sync += delayed.eq(update)
            update = delayed
        m.submodules.motors = motors = self.motors
        m.d.comb += [
            motors.update.eq(update),
            motors.left.eq(design.motor_left),
            motors.right.eq(design.motor_right),
            self.spi_sclk.eq(motors.sclk),
            self.spi_copi.eq(motors.copi),
            self.spi_cs.eq(motors.cs),
        ]
        return m
