"""GoPiGo3 SPI master: a simulated SPI peripheral (mode 0) decodes the bytes on the wire and
they must be the GoPiGo3 protocol's messages for the commanded speeds."""

import pytest
from amaranth.sim import Simulator

from fpga_robotics.hw.board.gopigo3_spi import GoPiGo3Motors, dps_to_ticks, servo_pulse_us

HALF = 3
STARTUP = 20


def limits_message(port, dps=512, power=0):
    ticks = dps * 2
    return [0x08, 0x0F, port, power, (ticks >> 8) & 0xFF, ticks & 0xFF]


def dps_message(port, dps):
    ticks = max(-32768, min(32767, 2 * dps)) & 0xFFFF  # two's complement, big-endian
    return [0x08, 0x0E, port, ticks >> 8, ticks & 0xFF]


def run_spi(updates, *, max_cycles=20000, **kwargs):
    """Drive ``updates`` [(cycle, left, right[, servo_angle])], return the decoded messages and bus checks."""
    dut = GoPiGo3Motors(half_period=HALF, startup_wait=STARTUP, **kwargs)
    sim = Simulator(dut)
    sim.add_clock(1e-6)
    messages, high_times, low_times = [], set(), set()
    state = {"idle": False}

    async def peripheral(ctx):
        prev_sclk, prev_copi, prev_cs = 0, 0, 0
        current, shift, nbits = None, 0, 0
        last_edge, quiet = 0, 0
        pending = list(updates)
        for cycle in range(max_cycles):  # watchdog
            if pending and pending[0][0] == cycle:
                _, left, right, *servo = pending.pop(0)
                ctx.set(dut.left, left)
                ctx.set(dut.right, right)
                if servo:
                    ctx.set(dut.servo_angle, servo[0])
                ctx.set(dut.update, 1)
            else:
                ctx.set(dut.update, 0)
            await ctx.tick()
            sclk, copi, cs = ctx.get(dut.sclk), ctx.get(dut.copi), ctx.get(dut.cs)
            if not cs:
                assert sclk == 0, "mode 0: SCLK idles low while deselected"
            if cs and not prev_cs:
                assert sclk == 0
                current, shift, nbits, last_edge = [], 0, 0, cycle
            if sclk != prev_sclk:
                assert cs, "SCLK toggled while deselected"
                (low_times if sclk else high_times).add(cycle - last_edge)
                last_edge = cycle
            if sclk and not prev_sclk:
                # Mode 0: data was set up before the rising edge and is sampled on it.
                assert copi == prev_copi, "COPI changed on the rising edge"
                shift, nbits = (shift << 1) | copi, nbits + 1
                if nbits == 8:
                    current.append(shift)
                    shift, nbits = 0, 0
            if not cs and prev_cs:
                assert nbits == 0, "chip select released in the middle of a byte"
                messages.append(current)
            prev_sclk, prev_copi, prev_cs = sclk, copi, cs
            quiet = quiet + 1 if not (cs or ctx.get(dut.busy)) else 0
            if not pending and messages and quiet > 50:
                state["idle"] = True
                return

    sim.add_testbench(peripheral)
    sim.run()
    assert state["idle"], "the SPI master did not finish within the cycle budget"
    return messages, high_times, low_times


def test_limits_then_speeds_including_negative_and_x2():
    updates = [(1500, 300, -300), (3000, -512, 512), (4500, 0, -1)]
    messages, high_times, low_times = run_spi(updates)
    expected = [limits_message(0x01), limits_message(0x02)]
    for _, left, right in updates:
        expected += [dps_message(0x01, left), dps_message(0x02, right)]
    assert messages == expected
    # Spot-check the encoding by hand: -300 DPS = -600 ticks = 0xFDA8.
    assert messages[3] == [0x08, 0x0E, 0x02, 0xFD, 0xA8]
    # SCLK high for half_period cycles, low for half_period (one more between two bytes).
    assert high_times == {HALF} and low_times == {HALF, HALF + 1}


def test_latest_update_wins_while_busy():
    # Three updates in quick succession: the first is being sent when the next two arrive;
    # the second is overwritten by the third, which is sent after the first.
    updates = [(1500, 10, 20), (1520, 30, 40), (1540, 50, 60)]
    messages, _, _ = run_spi(updates)
    assert messages[2:] == [
        dps_message(1, 10),
        dps_message(2, 20),
        dps_message(1, 50),
        dps_message(2, 60),
    ]


def test_saturation_beyond_int16_ticks():
    updates = [(1500, 20000, -20000)]
    messages, _, _ = run_spi(updates)
    assert messages[2:] == [[0x08, 0x0E, 0x01, 0x7F, 0xFF], [0x08, 0x0E, 0x02, 0x80, 0x00]]
    assert dps_to_ticks(20000) == 32767 and dps_to_ticks(-20000) == -32768


def test_custom_limits():
    messages, _, _ = run_spi([], dps_limit=300, power_limit=50)
    assert messages == [limits_message(1, 300, 50), limits_message(2, 300, 50)]


def test_servo_message_after_the_wheels():
    # SET_SERVO (type 9, set_servo(SERVO_1, us)): 1500 us + the command, clamped to +-500.
    # By hand: 0 -> 1500 = 0x05DC; 250 -> 1750 = 0x06D6; -500 -> 1000 = 0x03E8;
    # 511 (beyond the end stop) -> 2000 = 0x07D0; -512 -> 1000 = 0x03E8.
    angles = [(0, 0x05, 0xDC), (250, 0x06, 0xD6), (-500, 0x03, 0xE8), (511, 0x07, 0xD0)]
    angles.append((-512, 0x03, 0xE8))
    updates = [(1500 + 1500 * k, 10 * k, -10 * k, a) for k, (a, _, _) in enumerate(angles)]
    messages, _, _ = run_spi(updates, servo=True)
    expected = [limits_message(0x01), limits_message(0x02)]
    for (_, left, right, _), (_, hi, lo) in zip(updates, angles):
        expected += [dps_message(0x01, left), dps_message(0x02, right), [8, 9, 1, hi, lo]]
    assert messages == expected
    assert [servo_pulse_us(a) for a, _, _ in angles] == [1500, 1750, 1000, 2000, 1000]


def test_latest_servo_command_wins_while_busy():
    updates = [(1500, 1, 2, 100), (1520, 3, 4, 200), (1540, 5, 6, -300)]
    messages, _, _ = run_spi(updates, servo=True)
    assert messages[2:] == [
        dps_message(1, 1),
        dps_message(2, 2),
        [8, 9, 1, 1600 >> 8, 1600 & 0xFF],
        dps_message(1, 5),
        dps_message(2, 6),
        [8, 9, 1, 1200 >> 8, 1200 & 0xFF],
    ]


@pytest.mark.parametrize(
    "kwargs,error",
    [
        ({"dps_limit": -1}, ValueError),
        ({"power_limit": 101}, ValueError),
        ({"startup_wait": 1.5}, TypeError),
        ({"servo": 1}, TypeError),
    ],
)
def test_bad_arguments(kwargs, error):
    with pytest.raises(error):
        GoPiGo3Motors(half_period=HALF, **kwargs)
