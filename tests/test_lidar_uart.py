"""The LIDAR's serial link in gateware: bytes of a known scan, put on the line 8N1 as the
connector does, come out of UartRx and RplidarDecoder as the samples they encode; a stray
byte is dropped by the resynchronisation; a low stop bit is a framing error. And the
corridor_uart scenario passes."""

import re

import pytest
from amaranth import Module
from amaranth.lib import wiring
from hwsim import run_testbench

from fpga_robotics.hw.lidar_params import UartParams
from fpga_robotics.hw.lidar_sample import unpack_sample
from fpga_robotics.hw.lidar_uart import RplidarDecoder, UartRx
from fpga_robotics.loop import run_scenario
from fpga_robotics.scenario import ScenarioError, load_scenario
from fpga_robotics.sim.world.lidar import DESCRIPTOR, LidarSample, packet_bytes, uart_levels

#: 8 cycles a bit.
PARAMS = UartParams(clock_hz=921_600, baud=115_200)


class Link(wiring.Component):
    def __init__(self):
        self.uart = UartRx(PARAMS)
        self.decoder = RplidarDecoder()
        super().__init__({})

    def elaborate(self, platform):
        m = Module()
        m.submodules.uart, m.submodules.decoder = self.uart, self.decoder
        wiring.connect(m, self.uart.bytes, self.decoder.bytes)
        return m


def run_line(levels, idle=3):
    """Drive ``levels`` a bit each (``bit_cycles`` cycles), ``idle`` bits of high first;
    returns the decoded samples, the framing errors and the resyncs."""
    dut = Link()
    samples, errors = [], 0
    n = PARAMS.bit_cycles
    bits = [1] * idle + list(levels) + [1] * 4

    async def bench(ctx):
        nonlocal errors
        for level in bits:
            ctx.set(dut.uart.rx, level)
            for _ in range(n):
                await ctx.tick()
                errors += ctx.get(dut.uart.framing_error)
                if ctx.get(dut.decoder.samples.valid):
                    samples.append(unpack_sample(ctx.get(dut.decoder.samples.payload.as_value())))
        assert ctx.get(dut.decoder.synced)
        samples.append(("resyncs", ctx.get(dut.decoder.resyncs)))

    run_testbench(dut, bench, watchdog=len(bits) * n + 100)
    *decoded, (_, resyncs) = samples
    return decoded, errors, resyncs


SCAN = [
    LidarSample(0, 0, 12000, 15, True),  # 3 m ahead, a new revolution
    LidarSample(1, 63, 4001, 15, False),  # 0.98 degrees, 1000.25 mm
    LidarSample(2, 126, 0, 0, False),  # a dropout
    LidarSample(3, 23039, 65535, 63, False),  # every field at its largest
    LidarSample(4, 5760, 1, 1, True),  # 90 degrees
]


def _fields(s):
    return {
        "angle_q6": s.angle_q6,
        "distance_q2": s.distance_q2,
        "quality": s.quality,
        "start": int(s.start),
    }


def test_a_known_scan_decodes_to_its_samples():
    data = DESCRIPTOR + b"".join(packet_bytes(s) for s in SCAN)
    decoded, errors, resyncs = run_line(uart_levels(data))
    assert decoded == [_fields(s) for s in SCAN]
    assert (errors, resyncs) == (0, 0)


def test_bytes_before_the_descriptor_are_skipped_and_a_stray_byte_resyncs():
    # Noise and a partial descriptor before the descriptor are skipped. Then a stray 0x00
    # (S = !S = 0) before the first packet is dropped; before the second, 0x3D (S = 1, !S = 0:
    # a first byte) then 0x00 (check bit C = 0): the packet begins again: two resyncs.
    data = (
        b"\x12\xa5\x5a\x05"
        + DESCRIPTOR
        + b"\x00"
        + packet_bytes(SCAN[0])
        + b"\x3d\x00"
        + packet_bytes(SCAN[1])
    )
    decoded, errors, resyncs = run_line(uart_levels(data))
    assert decoded == [_fields(SCAN[0]), _fields(SCAN[1])]
    assert errors == 0 and resyncs == 2


def test_a_low_stop_bit_is_a_framing_error():
    levels = uart_levels(DESCRIPTOR + packet_bytes(SCAN[0]))
    bad = [0] + [1, 0, 1, 0, 1, 0, 1, 0] + [0]  # 0x55 with a low stop bit
    decoded, errors, _ = run_line(bad + [1, 1] + levels)
    assert errors == 1 and decoded == [_fields(SCAN[0])]


@pytest.mark.slow
def test_the_corridor_passes_over_the_serial_link():
    s = load_scenario("corridor_uart", ["sim.clock_hz=1000000", "sim.duration=8"])
    r = run_scenario(s, backend="cxxrtl")
    assert r.passed, r.summary["checks"]
    assert r.trajectory["design.framing_errors"][-1] == 0
    assert r.trajectory["design.resyncs"][-1] == 0
    assert r.trajectory["design.found"][-1] == 1


def test_the_uart_takes_the_runs_clock_and_baud():
    """[design.uart] left out: the receiver runs on sim.clock_hz at the LIDAR's baud."""
    s = load_scenario("corridor_uart", ["sim.clock_hz=10000000", "robot.sensors.0.baud=230400"])
    assert s.design_tables["uart"] == UartParams(clock_hz=10_000_000, baud=230_400)
    # On a 1 MHz clock the design decodes every byte: a revolution found, no framing error.
    s = load_scenario("corridor_uart", ["sim.clock_hz=1000000", "sim.duration=0.5"])
    r = run_scenario(s, backend="cxxrtl")
    assert r.trajectory["design.found"][-1] == 1
    assert r.trajectory["design.framing_errors"][-1] == 0


@pytest.mark.parametrize(
    "sets, message",
    [
        (
            ["sim.clock_hz=10000000", "design.uart.clock_hz=50000000"],
            (
                "design.uart.clock_hz 50000000 does not match sim.clock_hz 10000000; leave "
                "design.uart.clock_hz out to take it"
            ),
        ),
        (
            ["design.uart.baud=57600"],
            (
                "design.uart.baud 57600 does not match robot.sensors[0].baud 115200; leave "
                "design.uart.baud out to take it"
            ),
        ),
        # Values the user did not write: the message says where they come from.
        (
            ["sim.clock_hz=200000"],
            (
                "design.uart: clock_hz=200000 is too slow for baud=115200: a bit must last at "
                "least 4 cycles, it lasts 1.74 (clock_hz is sim.clock_hz, baud is "
                "robot.sensors[0].baud)"
            ),
        ),
    ],
)
def test_a_uart_off_the_runs_clock_or_baud_is_refused(sets, message):
    with pytest.raises(ScenarioError, match=re.escape(message)):
        load_scenario("corridor_uart", sets)


@pytest.mark.parametrize(
    "clock_hz, accepted",
    [
        (250_000, False),  # 2.5 cycles a bit: the connector's one edge a bit, not the receiver's 4
        (383_000, False),  # rounded to 4, 4.4% off: the stop bit sampled 42% off its middle
        (384_000, True),
        (417_000, True),
        (418_000, False),
        (1_200_000, True),  # 12 cycles a bit
    ],
)
def test_the_receivers_cycles_a_bit_are_as_documented(clock_hz, accepted):
    """docs/lidar.md: at least 4 cycles a bit, within 4% of a whole number of cycles."""
    if accepted:
        assert UartParams(clock_hz=clock_hz, baud=100_000).bit_cycles == round(clock_hz / 100_000)
    else:
        with pytest.raises(ValueError):
            UartParams(clock_hz=clock_hz, baud=100_000)
