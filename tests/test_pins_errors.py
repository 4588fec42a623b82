"""Bad uses of the pin backends give a ``PinError`` with one line saying what to do, and
leave the backend usable; ``real_clock_timing`` gives the hand-computed OV7670-like spread."""

import numpy as np
import pytest
from amaranth import ClockDomain, ClockSignal, Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature
from fpga_robotics.sim.pins import (
    PIXEL_PORTS,
    PinDesignSource,
    PinError,
    PixelTiming,
    Stop,
    get_pin_backend,
    real_clock_timing,
)


class Probe(wiring.Component):
    """A 3-bit input ``x``, a signed 5-bit input ``s``, ``y = x`` registered, a pixel stream."""

    x: In(3)
    s: In(signed(5))
    pixels: In(pixel_stream_signature())
    y: Out(3)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.y.eq(self.x)
        return m


SOURCE = PinDesignSource(Probe, "test_pins_errors_probe", pixels=PIXEL_PORTS, frame_size=(3, 2))


@pytest.fixture(scope="module", params=["pysim", "cxxrtl"])
def pins(request):
    with get_pin_backend(request.param, SOURCE) as backend:
        yield backend


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda p: p.peek("z"),
            r"unknown port 'z'; the design's ports: x, s, pixels__payload, pixels__valid, y$",
        ),
        (lambda p: p.poke("z", 1), r"unknown port 'z'"),
        (lambda p: p.watch(["y", "z"]), r"unknown port 'z'"),
        (lambda p: p.watch(["x"]), r"port 'x' is an input; only outputs can be watched"),
        (
            lambda p: p.poke("y", 1),
            (
                r"port 'y' is an output of the design; only inputs can be "
                r"driven \(inputs: x, s, pixels__payload, pixels__valid\)"
            ),
        ),
        (lambda p: p.poke("pixels__valid", 1), r"driven by the pixel stream; use stream_frame"),
        (lambda p: p.poke("x", 8), r"8 does not fit port 'x' \(3-bit unsigned: 0\.\.7\)"),
        (lambda p: p.poke("x", -1), r"-1 does not fit port 'x'"),
        (lambda p: p.poke("x", 1.5), r"the value for 'x' must be an int"),
        (
            lambda p: p.schedule(p.cycle, "x", 1),
            (
                r"edge 5 is in the past \(cycle is 5\); schedule "
                r"changes for edge 6 or later"
            ),
        ),
        (lambda p: p.run(-1), r"run needs a number of cycles >= 0"),
        (
            lambda p: p.stream_frame(np.zeros((3, 2), np.uint16), PixelTiming(9, 4)),
            (
                r"a frame must be a \(2, 3\) uint16 array of RGB444 pixels \(or \(2, 3, 3\) uint8 "
                r"RGB888\), not uint16 \(3, 2\)"
            ),
        ),
        (
            lambda p: p.stream_frame(np.full((2, 3), 0x1000, np.uint16), PixelTiming(9, 4)),
            r"a packed RGB444 frame holds 12-bit values; found one above 0xFFF",
        ),
        (
            lambda p: p.stream_frame(np.zeros((2, 3), np.uint16), PixelTiming(5, 4)),
            r"the frame starts at edge 5, in the past \(cycle is 5\)",
        ),
        (
            lambda p: p.stream_frame(np.zeros((2, 3), np.uint16), PixelTiming(9, 2)),
            r"line_period >= \(width - 1\) \* pixel_period \+ 1 = 3",
        ),
    ],
)
def test_bad_calls(pins, call, message):
    pins.reset()
    pins.run(5)
    with pytest.raises(PinError, match=message):
        call(pins)
    # Nothing half-done: the backend still runs, the input keeps its value.
    pins.poke("x", 5)
    assert pins.run(1) == Stop(6) and pins.peek("y") == 5


def test_signed_inputs_take_their_range(pins):
    pins.reset()
    pins.poke("s", -16)
    assert pins.peek("s") == -16
    for bad in (-17, 16):
        with pytest.raises(
            PinError,
            match=rf"{bad} does not fit port 's' \(5-bit signed: "
            r"-16\.\.15\)",
        ):
            pins.poke("s", bad)


def test_a_frame_while_one_is_pending(pins):
    pins.reset()
    pins.stream_frame(np.ones((2, 3), np.uint16), PixelTiming(start=3, line_period=10))
    with pytest.raises(
        PinError,
        match=r"a frame is still streaming \(its last pixel is at "
        r"edge 15, cycle is 0\); run until frame_pending is",
    ):
        pins.stream_frame(np.ones((2, 3), np.uint16), PixelTiming(start=20, line_period=10))
    pins.run(15)
    assert not pins.frame_pending
    pins.stream_frame(np.ones((2, 3), np.uint16), PixelTiming(start=16, line_period=10))


def test_no_pixel_binding():
    source = PinDesignSource(Probe, "test_pins_errors_probe_unbound")
    with (
        get_pin_backend("pysim", source) as pins,
        pytest.raises(PinError, match="no pixel stream binding"),
    ):
        pins.stream_frame(np.zeros((2, 3), np.uint16), PixelTiming(1, 4))


def test_bad_bindings():
    with pytest.raises(
        PinError,
        match=r"the filtered binding needs a 1-bit output port "
        r"'filtered__valid'",
    ):
        PinDesignSource(
            Probe, "k", filtered=("filtered__valid", "filtered__payload"), frame_size=(3, 2)
        )
    with pytest.raises(PinError, match=r"needs frame_size=\(width, height\)"):
        PinDesignSource(Probe, "k", pixels=PIXEL_PORTS)


@pytest.mark.parametrize("name", ["cxxrtl", "verilator"])
def test_missing_compiler(monkeypatch, name):
    monkeypatch.setenv("CXX", "no-such-compiler-here")
    with pytest.raises(
        PinError,
        match=rf"^{name}: the C\+\+ compiler 'no-such-compiler-here' "
        r"named by the CXX environment variable was not found; "
        r"install a C\+\+ compiler",
    ):
        get_pin_backend(name, SOURCE)


def test_auto_without_a_compiler_says_it_once_and_names_the_way_out(monkeypatch):
    monkeypatch.setenv("CXX", "no-such-compiler-here")
    with pytest.raises(PinError) as info:
        get_pin_backend("auto", SOURCE)
    message = str(info.value)
    assert message.startswith(
        "no compiled pin backend works here (cxxrtl and verilator: the C++ compiler "
        "'no-such-compiler-here' named by the CXX environment variable was not found; "
    )
    assert message.count("no-such-compiler-here") == 1
    assert message.endswith("; --backend pysim (Amaranth's simulator, slower) needs none")
    with get_pin_backend("pysim", SOURCE) as pins:  # and it does
        assert pins.name == "pysim"


def test_unknown_backend():
    with pytest.raises(
        PinError,
        match=r"unknown pin backend 'fast'; choose one of: auto, "
        r"pysim, cxxrtl, verilator",
    ):
        get_pin_backend("fast", SOURCE)


class HalfClock(wiring.Component):
    """``ticks`` counts the edges of a clock domain the design drives itself: half the clock."""

    ticks: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.domains.half = ClockDomain()
        divider = Signal()
        m.d.sync += divider.eq(~divider)
        m.d.comb += ClockSignal("half").eq(divider)
        m.d.half += self.ticks.eq(self.ticks + 1)
        return m


HALF = PinDesignSource(HalfClock, "test_pins_errors_half_clock")


def test_a_clock_the_design_drives_is_refused_by_cxxrtl():
    # CXXRTL never saw its edges (Yosys issue #3549): ticks stayed 0 where pysim counts.
    with pytest.raises(
        PinError,
        match=r"^cxxrtl: test_pins_errors_half_clock clocks flip-flops from a signal of its "
        r"own \(p_divider in the CXXRTL model\), whose edges CXXRTL misses \(Yosys issue "
        r"#3549\): run it with --backend verilator or pysim$",
    ):
        get_pin_backend("cxxrtl", HALF)
    with get_pin_backend("pysim", HALF) as pins:
        pins.run(20)
        assert pins.peek("ticks") == 10


@pytest.mark.slow
def test_auto_runs_a_clock_the_design_drives_on_verilator():
    with get_pin_backend("auto", HALF) as pins:
        assert pins.name == "verilator"
        pins.run(20)
        assert pins.peek("ticks") == 10


def test_auto_is_a_compiled_backend():
    with get_pin_backend("auto", SOURCE) as pins:
        assert pins.name == "cxxrtl"


def test_real_clock_timing():
    # 50 MHz at 30 fps: 1666667 cycles a frame; 120 lines spread over round(127.5) = 128
    # line periods of 13020 cycles; 160 pixels in 13020 * 640 // 784 = 10628: every 66.
    assert real_clock_timing(160, 120, 30, 50e6, 7) == PixelTiming(7, 13020, 66)
    # VGA: 510 line periods of 3267 cycles; 640 pixels in 2666 cycles: every 4.
    assert real_clock_timing(640, 480, 30, 50e6, 1) == PixelTiming(1, 3267, 4)
    # A slow clock: 180 cycles a line, 146 of them active: one pixel per cycle is the floor.
    assert real_clock_timing(160, 120, 30, 691200, 1) == PixelTiming(1, 180, 1)
    with pytest.raises(PinError, match="3267 cycles per line at 30 fps, too few for 4000 pixels"):
        real_clock_timing(4000, 480, 30, 50e6, 1)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--backends", "cxxrtl,fast"], "unknown backend"),
        (["--resolution", "160"], "--resolution is WIDTHxHEIGHT"),
        (["--resolution", "16x12"], "--resolution: the window width"),
        (["--clock-hz", "1e5"], "too few for 160 pixels; lower the resolution or fps"),
        (["--repeats", "0"], "--repeats must be 1..1000"),
        (["--step", "0"], "--step must be more than 0"),
    ],
)
def test_pin_bench_bad_arguments(argv, message):
    from fpga_robotics.bench.pins import main
    from fpga_robotics.cli.errors import UsageError

    with pytest.raises(UsageError, match=message):
        main(argv)


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_compiled_pins_after_close(name):
    # Before, a call after close() handed the harness a freed model: a segmentation fault.
    backend = get_pin_backend(name, SOURCE)
    backend.poke("x", 5)
    backend.run(3)
    assert backend.peek("y") == 5
    backend.close()
    backend.close()  # twice is fine
    for call in (
        lambda p: p.peek("y"),
        lambda p: p.poke("x", 1),
        lambda p: p.run(1),
        lambda p: p.reset(),
    ):
        with pytest.raises(PinError, match=f"^{name}: the pins are closed; open new ones"):
            call(backend)
