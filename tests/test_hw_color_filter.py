"""ColorFilter against the golden model's colour table (and the plain scalar formulas):
every colour select over every RGB444 value, thresholds, flags, latency, blanking."""

import numpy as np
import pytest
from hwsim import (
    FIRST_BIT,
    LAST_BIT,
    Step,
    edges_where,
    match_flag_offset,
    pack_transfer,
    run_schedule,
    run_testbench,
    small_params,
    stream_get,
    stream_put,
)
from scalar_reference import scalar_match

from fpga_robotics.hw.color_filter import ColorFilter
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import COLOR_SELECT, TargetColor, color_select_value
from fpga_robotics.hw.top import FollowTarget
from fpga_robotics.sim.models.follow_target import match_table

ALL_PIXELS = np.arange(4096, dtype=np.uint16)

#: docs/contract.md: bit 2 red, bit 1 green, bit 0 blue; a colour is the primaries it mixes.
PRIMARIES = {
    "none": "",
    "blue": "b",
    "green": "g",
    "cyan": "gb",
    "red": "r",
    "magenta": "rb",
    "yellow": "rg",
    "white": "rgb",
}


def test_target_color_codes_are_the_contract_bits():
    expected = {
        name: 4 * ("r" in mix) + 2 * ("g" in mix) + ("b" in mix) for name, mix in PRIMARIES.items()
    }
    assert {c.name.lower(): c.value for c in TargetColor} == expected
    assert dict(COLOR_SELECT) == expected
    assert color_select_value("Yellow") == color_select_value(TargetColor.YELLOW) == 0b110
    with pytest.raises(ValueError, match="unknown colour 'teal'"):
        color_select_value("teal")


def test_numpy_integers_are_colour_codes_and_bools_are_not():
    # A run's recorded color_sel column is int64: replaying it takes its values as they are.
    for value in (np.int64(4), np.uint8(4)):
        code = color_select_value(value)
        assert code == 4 and type(code) is int
    for value in (True, np.bool_(True), np.int64(8), 4.0):
        with pytest.raises(ValueError, match="an int 0..7"):
            color_select_value(value)


def test_color_sel_port_is_the_enum_on_three_bits():
    for dut in (ColorFilter(FollowTargetParams()), FollowTarget()):
        assert dut.color_sel.shape() is TargetColor
        assert len(dut.color_sel.as_value()) == 3


def run_filter(params, schedule, color_sel):
    dut = ColorFilter(params)
    assert dut.latency == params.filter_latency
    probes = {
        "valid": dut.filtered.valid,
        "payload": dut.filtered.payload,
        "m_valid": dut.matches.valid,
        "m_payload": dut.matches.payload,
    }
    return run_schedule(
        dut, dut.pixels, schedule, probes, static=[(dut.color_sel, color_sel)], tail=4
    )


def filtered_transfers(trace):
    valid = trace["valid"].astype(bool)
    return trace["payload"][valid], trace["m_payload"][trace["m_valid"].astype(bool)]


@pytest.mark.parametrize("color", list(COLOR_SELECT))
def test_every_pixel_value_for_every_colour(color):
    p = FollowTargetParams()
    sel = COLOR_SELECT[color]
    schedule = [pack_transfer(v) for v in ALL_PIXELS]
    payload, matches = filtered_transfers(run_filter(p, schedule, sel))
    expected_match = match_table(sel, p)
    assert len(payload) == 4096
    assert np.array_equal(payload & 0xFFF, np.where(expected_match, ALL_PIXELS, 0))
    assert np.array_equal((matches >> match_flag_offset("match")) & 1, expected_match)
    # The numpy model and the plain formulas agree too (spot check of the reference itself).
    assert [scalar_match(int(v), sel) for v in ALL_PIXELS[::97]] == list(expected_match[::97])


@pytest.mark.parametrize("diff_min,similar_max,white_min", [(0, 0, 0), (5, 1, 10), (15, 15, 15)])
def test_thresholds_are_parameters(diff_min, similar_max, white_min):
    p = FollowTargetParams(diff_min=diff_min, similar_max=similar_max, white_min=white_min)
    rng = np.random.default_rng(diff_min)
    pixels = rng.integers(0, 4096, 1500).astype(np.uint16)
    for sel in (0b100, 0b110, 0b111, 0b011):
        schedule = [pack_transfer(v) for v in pixels]
        payload, _ = filtered_transfers(run_filter(p, schedule, sel))
        expected = [scalar_match(int(v), sel, diff_min, similar_max, white_min) for v in pixels]
        assert np.array_equal(payload & 0xFFF, np.where(expected, pixels, 0))


def test_red_brown_wood_is_red_only_with_a_loose_diff_min():
    wood = (9 << 8) | (4 << 4) | 2  # the published false target: r - max(g, b) = 5
    for diff_min, is_red in ((6, False), (5, True)):
        p = FollowTargetParams(diff_min=diff_min)
        payload, _ = filtered_transfers(run_filter(p, [pack_transfer(wood)], COLOR_SELECT["red"]))
        assert list(payload & 0xFFF) == [wood if is_red else 0]


def test_latency_flags_and_blanking_pass_through():
    p = small_params()
    rng = np.random.default_rng(2)
    schedule = []
    for i in range(300):
        if rng.random() < 0.3:
            schedule.append(None)
        else:
            schedule.append(
                pack_transfer(
                    int(rng.integers(0, 4096)), first=rng.random() < 0.1, last=rng.random() < 0.2
                )
            )
    trace = run_filter(p, schedule, COLOR_SELECT["none"])
    # With colour "none" every pixel passes unchanged: the output is the input, delayed.
    inputs = [i for i, e in enumerate(schedule) if e is not None]
    outputs = edges_where(trace, "valid")
    latency = p.filter_latency
    # Sampled at edge k+1 on the input, sampled at edge k+1+latency on the output
    # (visible at trace index k + latency - 1).
    assert outputs == [i + latency - 1 for i in inputs]
    assert list(trace["payload"][outputs]) == [schedule[i] for i in inputs]
    m = trace["m_payload"][edges_where(trace, "m_valid")]
    first_at, last_at = match_flag_offset("first"), match_flag_offset("last")
    assert list((m >> first_at) & 1) == [(schedule[i] >> FIRST_BIT) & 1 for i in inputs]
    assert list((m >> last_at) & 1) == [(schedule[i] >> LAST_BIT) & 1 for i in inputs]


def test_non_matching_pixels_keep_their_flags():
    p = small_params()
    schedule = [pack_transfer(0x123, first=True), pack_transfer(0x0F0, last=True)]
    payload, _ = filtered_transfers(run_filter(p, schedule, COLOR_SELECT["red"]))
    assert list(payload) == [pack_transfer(0, first=True), pack_transfer(0, last=True)]


def test_color_select_is_sampled_with_each_pixel():
    p = small_params()
    red, green = 0xF22, 0x2F2
    dut = ColorFilter(p)
    schedule = [
        Step(pack_transfer(red), [(dut.color_sel, COLOR_SELECT["red"])]),
        Step(pack_transfer(green), [(dut.color_sel, COLOR_SELECT["green"])]),
        Step(pack_transfer(red), [(dut.color_sel, COLOR_SELECT["green"])]),
    ]
    trace = run_schedule(
        dut,
        dut.pixels,
        schedule,
        {"valid": dut.filtered.valid, "payload": dut.filtered.payload},
        tail=3,
    )
    assert list(trace["payload"][edges_where(trace, "valid")]) == [red, green, 0]


def test_single_transfers_with_stream_helpers():
    # One pixel at a time through the shared put/get helpers; the get's timeout is the
    # latency: the filtered pixel is there right after the edge that took the input.
    p = small_params()
    dut = ColorFilter(p)
    pixels = [0xF11, 0x1F1, 0xE22, 0x000]
    got = []

    async def bench(ctx):
        ctx.set(dut.color_sel, COLOR_SELECT["red"])
        for value in pixels:
            await stream_put(ctx, dut.pixels, pack_transfer(value, last=True))
            got.append(await stream_get(ctx, dut.filtered, timeout=p.filter_latency - 1))

    run_testbench(dut, bench, watchdog=50)
    expected = [v if scalar_match(v, COLOR_SELECT["red"]) else 0 for v in pixels]
    assert got == [pack_transfer(v, last=True) for v in expected]
