"""A design of one's own on the robot's ULX3S, wired as ``ulx3s_top`` wires FollowTarget.

The design's ports meet the board where the simulation's connectors meet them:

- the camera's framed pixel stream ``pixels`` (OV7670, SCCB, capture and clock crossing as in
  ``robot_core``), ``color_sel`` from the DIP switches SW1..SW3; a pan camera's
  ``turret_pixels`` from a second OV7670 (``pins.TURRET_CAMERA_PINS``), ``turret_color_sel``
  from the same switches;
- the GoPiGo3 wheels, ``motor_left``/``motor_right``, sent over SPI ``update_delay`` cycles
  after every ``frame_done`` of a camera design (when the simulation reads them), else every
  ``update_s`` (50 Hz by default), and with them a servo's
  angle (the port ``servo`` names) as SET_SERVO to the GoPiGo3's servo port 1;
- the 8 user LEDs show ``centroid_leds`` when the design has it;
- every other connector pin (an ultrasound's ``trig``/``echo``, a bumper's ``pressed``, ...)
  on a free pin of GPIO header J1, in the order ``HEADER_SITES`` lists them.

Which ports are which is decided on the host (``fpga_robotics.flow.board``); this module only
wires what it is given.
"""

from amaranth.build import Attrs, Pins, Resource
from amaranth.hdl import Cat, ClockDomain, ClockSignal, Elaboratable, Module, Signal
from amaranth.lib import io
from amaranth.lib.cdc import ResetSynchronizer

from ..params import FollowTargetParams
from .clocking import BoardClocking
from .color_select import SwitchColorSelect
from .gopigo3_spi import GoPiGo3Motors
from .ov7670_capture import OV7670Capture
from .pins import TURRET_CAMERA_PINS, turret_camera_resources
from .robot_core import RobotTiming, gopigo3_dps_limit
from .sccb import OV7670_INIT, SCCBInit
from .ulx3s_top import OSC_FREQ, SYS_CLK_FREQ, ulx3s_platform

__all__ = [
    "HEADER_SITES",
    "ULX3SUserDesign",
    "delayed_strobe",
    "header_resources",
    "header_sites",
    "ulx3s_user_platform",
]

#: GPIO header J1 pins the camera and the GoPiGo3 leave free (``gpio`` pairs 7-12, 14-19,
#: 22-27 of the ULX3S), as (connector pin, ECP5 site).
HEADER_SITES = tuple(
    (f"gpio {pair}{side}", site)
    for pair, sites in (
        (7, ("A6", "B6")),
        (8, ("A4", "A5")),
        (9, ("A2", "B1")),
        (10, ("C4", "B4")),
        (11, ("F4", "E3")),
        (12, ("G3", "F3")),
        (14, ("U18", "U17")),
        (15, ("N17", "P16")),
        (16, ("N16", "M17")),
        (17, ("L16", "L17")),
        (18, ("H18", "H17")),
        (19, ("F17", "G18")),
        (22, ("B15", "C15")),
        (23, ("B17", "C17")),
        (24, ("C16", "D16")),
        (25, ("D14", "E14")),
        (26, ("B13", "C13")),
        (27, ("D13", "E13")),
    )
    for side, site in zip("+-", sites)
)


def header_sites(turret_camera=False):
    """``HEADER_SITES`` without the pan camera's pins when the design has one."""
    if not turret_camera:
        return HEADER_SITES
    taken = {s for v in TURRET_CAMERA_PINS.values() for s in ((v,) if isinstance(v, str) else v)}
    return tuple((pin, site) for pin, site in HEADER_SITES if site not in taken)


def header_resources(ports, turret_camera=False):
    """One resource ``fr_header`` per header port (``[(name, direction)]``), numbered in
    order, on ``header_sites(turret_camera)``."""
    sites = header_sites(turret_camera)
    return [
        Resource("fr_header", k, Pins(site, dir=direction), Attrs(IO_TYPE="LVCMOS33"))
        for k, ((_name, direction), (_pin, site)) in enumerate(zip(ports, sites))
    ]


class ULX3SUserDesign(Elaboratable):
    """Board top around ``design`` (an Amaranth component already checked on the host).

    ``header``: ``[(port, "i"|"o")]`` the design's 1-bit connector ports (``"line[2]"``: a
    bit of a wider one), on the header pins in order; ``camera``: whether ``pixels`` is a stream input; ``servo``: the output port of
    the servo's angle, or None; ``update_s``: the wheel update period of a design without
    ``frame_done``; ``update_delay``: the cycles after ``frame_done`` when its wheels are
    valid.
    """

    def __init__(
        self,
        design,
        *,
        header=(),
        camera=False,
        turret_camera=False,
        servo=None,
        update_s=0.02,
        update_delay=0,
        params=None,
    ):
        self.design = design
        self.turret_camera = turret_camera
        self.servo = servo
        self.header = list(header)
        self.camera = camera
        self.update_s = update_s
        self.update_delay = update_delay
        self.params = FollowTargetParams() if params is None else params
        self.timing = RobotTiming(SYS_CLK_FREQ)

    def _port(self, name):
        return getattr(self.design, name, None)

    def _camera(self, m, platform, fire1, number, stream, xclk):
        """OV7670 ``number`` (its SCCB set-up, capture in its own pclk domain) onto the
        design's ``stream``."""
        t = self.timing
        cam = platform.request("ov7670", number, dir="-")
        tag = "" if number == 0 else f"_{number}"

        def sub(subsignal, direction):
            buf = io.Buffer(direction, getattr(cam, subsignal))
            m.submodules[f"{subsignal}{tag}_buffer"] = buf
            return buf

        domain = f"pclk{tag}"
        pclk = sub("pclk", "i")
        m.domains += ClockDomain(domain, local=True)
        m.d.comb += ClockSignal(domain).eq(pclk.i)
        m.submodules[f"{domain}_reset"] = ResetSynchronizer(fire1.i, domain=domain)
        sccb = SCCBInit(
            OV7670_INIT,
            quarter_period=t.sccb_quarter,
            reset_wait=t.reset_wait,
            startup_wait=t.camera_wait,
        )
        m.submodules[f"sccb{tag}"] = sccb
        siod = sub("siod", "io")
        capture = OV7670Capture(pclk_domain=domain)
        m.submodules[f"capture{tag}"] = capture
        m.d.comb += [
            capture.data.eq(sub("data", "i").i),
            capture.href.eq(sub("href", "i").i),
            capture.vsync.eq(sub("vsync", "i").i),
            sub("xclk", "o").o.eq(xclk),
            sub("sioc", "o").o.eq(sccb.sioc),
            siod.o.eq(sccb.siod_o),
            siod.oe.eq(sccb.siod_oe),
            # Only RGB444 frames reach the design: nothing before the registers are set.
            stream.valid.eq(capture.pixels.valid & sccb.done),
            stream.payload.eq(capture.pixels.payload),
        ]
        if hasattr(cam, "reset"):
            m.d.comb += sub("reset", "o").o.eq(0)

    def elaborate(self, platform):
        m = Module()
        t = self.timing

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
            clk25.i, fire1.i, in_freq=OSC_FREQ, sys_clk_freq=SYS_CLK_FREQ
        )
        m.submodules.design = design = self.design

        switch_color = None
        if self.camera or self.turret_camera:
            xclk, count = Signal(), Signal(range(t.xclk_half))  # both cameras' master clock
            with m.If(count == t.xclk_half - 1):
                m.d.sync += [count.eq(0), xclk.eq(~xclk)]
            with m.Else():
                m.d.sync += count.eq(count + 1)
            if any(self._port(n) is not None for n in ("color_sel", "turret_color_sel")):
                m.submodules.color_select = color = SwitchColorSelect()
                m.d.comb += color.switches.eq(Cat(pin("switch", i, "i").i for i in range(3)))
                switch_color = color.color_sel
        for number, prefix, wanted in ((0, "", self.camera), (1, "turret_", self.turret_camera)):
            if not wanted:
                continue
            stream = getattr(design, f"{prefix}pixels")
            self._camera(m, platform, fire1, number, stream, xclk)
            color_port = self._port(f"{prefix}color_sel")
            if color_port is not None:  # the switches' colour, for each camera
                m.d.comb += color_port.eq(switch_color)

        leds = self._port("centroid_leds")
        for i in range(8):
            m.d.comb += pin("led", i, "o").o.eq(
                leds[i] if leds is not None and i < len(leds) else 0
            )

        # The wheels: update_delay cycles after each frame_done, else at a steady rate.
        done = self._port("frame_done")
        if done is not None:
            update = delayed_strobe(m, done, self.update_delay)
        else:
            period = max(1, round(SYS_CLK_FREQ * self.update_s))
            tick, update = Signal(range(period)), Signal()
            m.d.sync += [tick.eq(0 if period == 1 else (tick + 1) % period), update.eq(tick == 0)]
        m.submodules.motors = motors = GoPiGo3Motors(
            half_period=t.spi_half,
            startup_wait=t.motor_wait,
            dps_limit=gopigo3_dps_limit(self.params),
            servo=self.servo is not None,
        )
        if self.servo is not None:
            m.d.comb += motors.servo_angle.eq(getattr(design, self.servo))
        spi = platform.request("gopigo3_spi", 0, dir="-")
        m.d.comb += [
            motors.update.eq(update),
            motors.left.eq(design.motor_left),
            motors.right.eq(design.motor_right),
            sub(spi, "clk", "o").o.eq(motors.sclk),
            sub(spi, "copi", "o").o.eq(motors.copi),
            sub(spi, "cs", "o").o.eq(motors.cs),
        ]
        sub(spi, "cipo", "i")

        for k, (name, direction) in enumerate(self.header):
            buf = pin("fr_header", k, direction)
            name, _, bit = name.partition("[")  # "line[2]": bit 2 of a wider port
            value = getattr(design, name)
            if bit:
                value = value[int(bit.rstrip("]"))]
            if direction == "i":
                m.d.comb += value.eq(buf.i)
            else:
                m.d.comb += buf.o.eq(value)
        return m


def delayed_strobe(m, strobe, cycles):
    """A one-cycle pulse ``cycles`` cycles after each pulse of ``strobe`` (``strobe`` itself
    for 0), from a down-counter: a later strobe before the pulse restarts the count."""
    if cycles == 0:
        return strobe
    wait = Signal(range(cycles + 1))
    with m.If(strobe):
        m.d.sync += wait.eq(cycles)
    with m.Elif(wait != 0):
        m.d.sync += wait.eq(wait - 1)
    return wait == 1


def ulx3s_user_platform(header, turret_camera=False):
    """``ulx3s_platform()`` with the header pins of ``header`` (``[(port, direction)]``) and
    the pan camera if asked for."""
    platform = ulx3s_platform()
    platform.add_resources(header_resources(header, turret_camera))
    if turret_camera:
        platform.add_resources(turret_camera_resources())
    return platform
