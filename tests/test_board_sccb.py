"""SCCB initialisation, decoded by a simulated SCCB target that watches SIOC/SIOD like the
camera does: START/STOP conditions, bits sampled on SIOC rising edges, ID 0x42, (reg, value)."""

import pytest
from amaranth.sim import Simulator

from fpga_robotics.hw.board.sccb import OV7670_INIT, OV7670_SCCB_ID, RegisterWrite, SCCBInit

QUARTER = 3
RESET_WAIT = 60
STARTUP_WAIT = 11


def decode_bus(dut, *, max_cycles):
    """Run the master and decode the bus. Returns (transactions, done_cycle, timing notes)."""
    sim = Simulator(dut)
    sim.add_clock(1e-6)
    result = {"tx": [], "done_cycle": None, "rise_periods": set(), "starts": [], "stops": []}

    async def target(ctx):
        prev_c, prev_d = 1, 1
        bits, released = [], []
        in_tx = False
        last_rise = None
        for cycle in range(max_cycles):  # watchdog: bounded number of cycles
            await ctx.tick()
            c = ctx.get(dut.sioc)
            oe = ctx.get(dut.siod_oe)
            d = ctx.get(dut.siod_o) if oe else 1  # pull-up when released
            if prev_c and c:
                if prev_d and not d:  # START
                    assert not in_tx, f"repeated START at cycle {cycle}"
                    in_tx, bits, released, last_rise = True, [], [], None
                    result["starts"].append(cycle)
                elif not prev_d and d:  # STOP
                    assert in_tx, f"STOP without START at cycle {cycle}"
                    in_tx = False
                    result["stops"].append(cycle)
                    # The SIOC rise that precedes STOP (with SIOD low) is not a data bit.
                    assert bits and bits[-1] == 0, "STOP must follow SIOC rising with SIOD low"
                    bits, released = bits[:-1], released[:-1]
                    result["tx"].append((bits, released))
            if not prev_c and c:  # SIOC rising: the target samples SIOD
                assert in_tx, f"SIOC pulse outside a transmission at cycle {cycle}"
                bits.append(d)
                released.append(not oe)
                if last_rise is not None:
                    result["rise_periods"].add(cycle - last_rise)
                last_rise = cycle
            prev_c, prev_d = c, d
            if ctx.get(dut.done) and result["done_cycle"] is None:
                result["done_cycle"] = cycle
                return

    sim.add_testbench(target)
    sim.run()
    return result


def byte_of(bits):
    return int("".join(str(b) for b in bits), 2)


def check_writes(result, table):
    assert result["done_cycle"] is not None, "the SCCB master never reported done"
    assert len(result["tx"]) == len(table)
    writes = []
    for bits, released in result["tx"]:
        assert len(bits) == 27, f"a 3-phase write has 27 bits, got {len(bits)}"
        # The ninth bit of every byte is the don't-care bit: the master must release SIOD.
        assert [released[i] for i in (8, 17, 26)] == [True, True, True]
        assert not any(released[i] for i in range(27) if i not in (8, 17, 26))
        assert byte_of(bits[0:8]) == OV7670_SCCB_ID
        writes.append((byte_of(bits[9:17]), byte_of(bits[18:26])))
    assert writes == [(w.reg, w.value) for w in table]


def test_ov7670_table_is_sent_in_order():
    dut = SCCBInit(
        OV7670_INIT, quarter_period=QUARTER, reset_wait=RESET_WAIT, startup_wait=STARTUP_WAIT
    )
    result = decode_bus(
        dut, max_cycles=len(OV7670_INIT) * 36 * 4 * QUARTER + RESET_WAIT + STARTUP_WAIT + 100
    )
    check_writes(result, OV7670_INIT)
    # SIOC period is four quarter periods.
    assert result["rise_periods"] == {4 * QUARTER}
    # Nothing happens on the bus before the startup wait.
    assert result["starts"][0] >= STARTUP_WAIT
    # After the software reset (entry 0) the camera gets at least reset_wait cycles.
    assert OV7670_INIT[0] == (0x12, 0x80, OV7670_INIT[0].comment, True)
    assert result["starts"][1] - result["stops"][0] >= RESET_WAIT
    # Other writes are separated by just the bus-free time, far less than the reset wait.
    gaps = [s - e for s, e in zip(result["starts"][2:], result["stops"][1:])]
    assert max(gaps) < RESET_WAIT


def test_published_register_values_are_in_the_table():
    table = {w.reg: w.value for w in OV7670_INIT[1:]}
    assert table[0x12] == 0x04  # COM7: RGB
    assert table[0x8C] == 0x02  # RGB444 enable, xR GB
    assert table[0x40] == 0xF0  # COM15
    assert table[0x72] == 0x22 and table[0x73] == 0xF2  # QQVGA downsampling, PCLK divider


def test_custom_table_and_device_id():
    table = [RegisterWrite(0xAB, 0x00, "a"), RegisterWrite(0x01, 0xFF, "b")]
    dut = SCCBInit(table, quarter_period=2, reset_wait=0)
    result = decode_bus(dut, max_cycles=2000)
    check_writes(result, table)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"table": [], "quarter_period": 2, "reset_wait": 0}, "empty"),
        ({"table": [RegisterWrite(0x100, 0, "")], "quarter_period": 2, "reset_wait": 0}, "a byte"),
        ({"table": OV7670_INIT, "quarter_period": 0, "reset_wait": 0}, "quarter_period"),
        ({"table": OV7670_INIT, "quarter_period": 2, "reset_wait": -1}, "reset_wait"),
    ],
)
def test_bad_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        SCCBInit(**kwargs)
