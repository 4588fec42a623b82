# amaranth: UnusedElaboratable=no
"""SequentialDivider against Python's integer division: results, latency, done strobe."""

import random

import pytest
from hwsim import WatchdogTimeout, run_testbench

from fpga_robotics.hw.divider import SequentialDivider


def divide_all(cases, dividend_bits, divisor_bits, quotient_bits, *, change_inputs=False):
    """Run every (dividend, divisor) through one divider; return the quotients and the
    number of edges from each start to the edge after which done was high."""
    dut = SequentialDivider(dividend_bits, divisor_bits, quotient_bits)
    out = []
    limit = (quotient_bits + 3) * (len(cases) + 1) + 50

    async def bench(ctx):
        for dividend, divisor in cases:
            ctx.set(dut.dividend, dividend)
            ctx.set(dut.divisor, divisor)
            ctx.set(dut.start, 1)
            await ctx.tick()
            ctx.set(dut.start, 0)
            if change_inputs:  # the divider must hold what it sampled at start
                ctx.set(dut.dividend, (1 << dividend_bits) - 1)
                ctx.set(dut.divisor, 1)
            edges = 1
            strobes = []
            while not ctx.get(dut.done):
                assert ctx.get(dut.busy)
                await ctx.tick()
                edges += 1
                if edges > quotient_bits + 5:
                    raise WatchdogTimeout("divider never finished")
            quotient = ctx.get(dut.quotient)
            await ctx.tick()
            strobes.append(ctx.get(dut.done))
            assert strobes == [0], "done is a one-cycle strobe"
            assert ctx.get(dut.quotient) == quotient, "the quotient holds"
            out.append((quotient, edges - 1))

    run_testbench(dut, bench, watchdog=limit)
    return out


def valid_cases(rng, n, divisor_bits, quotient_bits, dividend_bits):
    cases = []
    while len(cases) < n:
        divisor = rng.randint(1, (1 << divisor_bits) - 1)
        quotient = rng.randint(0, (1 << quotient_bits) - 1)
        dividend = divisor * quotient + rng.randint(0, divisor - 1)
        if dividend < 1 << dividend_bits:
            cases.append((dividend, divisor))
    return cases


@pytest.mark.parametrize("bits", [(22, 14, 8), (15, 9, 6), (4, 1, 4), (30, 19, 12)])
def test_quotients_and_latency(bits):
    dividend_bits, divisor_bits, quotient_bits = bits
    rng = random.Random(sum(bits))
    cases = valid_cases(rng, 150, divisor_bits, quotient_bits, dividend_bits)
    # Edge cases: largest quotient, quotient 0, divisor 1, exact multiples.
    top = (1 << quotient_bits) - 1
    cases += [(0, 1), (top, 1), (1, 1)]
    if divisor_bits >= 2:
        cases += [(3 * top, 3), (3 * top + 2, 3)]
    d_max = (1 << divisor_bits) - 1
    if d_max * top + d_max - 1 < 1 << dividend_bits:
        cases.append((d_max * top + d_max - 1, d_max))
    results = divide_all(cases, dividend_bits, divisor_bits, quotient_bits)
    assert [q for q, _ in results] == [a // b for a, b in cases]
    # start sampled at edge S, done shows right after edge S + quotient_bits.
    assert {lat for _, lat in results} == {quotient_bits}


def test_inputs_may_change_after_start():
    rng = random.Random(5)
    cases = valid_cases(rng, 40, 14, 8, 22)
    results = divide_all(cases, 22, 14, 8, change_inputs=True)
    assert [q for q, _ in results] == [a // b for a, b in cases]


def test_zero_divisor_still_finishes_on_time():
    results = divide_all([(1234, 0)], 22, 14, 8)
    assert results[0][1] == 8


@pytest.mark.parametrize(
    "bad,error", [(0, ValueError), (-1, ValueError), (1.5, TypeError), (True, TypeError)]
)
def test_widths_are_validated(bad, error):
    with pytest.raises(error, match="quotient_bits"):
        SequentialDivider(8, 8, bad)


def test_tag_travels_with_the_division_and_holds_until_the_next_start():
    dut = SequentialDivider(22, 14, 9, tag_bits=12)
    seen = []

    async def bench(ctx):
        for dividend, divisor, tag in [(1000, 7, 0xABC), (90, 9, 0x123), (5, 1, 0)]:
            ctx.set(dut.dividend, dividend)
            ctx.set(dut.divisor, divisor)
            ctx.set(dut.tag_in, tag)
            ctx.set(dut.start, 1)
            await ctx.tick()
            ctx.set(dut.start, 0)
            ctx.set(dut.tag_in, 0xFFF)  # sampled at start only
            tags = [ctx.get(dut.tag)]
            while not ctx.get(dut.done):
                await ctx.tick()
                tags.append(ctx.get(dut.tag))
            await ctx.tick()
            tags.append(ctx.get(dut.tag))
            seen.append((ctx.get(dut.quotient), set(tags)))

    run_testbench(dut, bench, watchdog=100)
    assert seen == [(1000 // 7, {0xABC}), (90 // 9, {0x123}), (5, {0})]


def test_tag_width_is_validated():
    with pytest.raises(ValueError, match="tag_bits"):
        SequentialDivider(8, 8, 4, tag_bits=-1)
    assert "tag" not in SequentialDivider(8, 8, 4).signature.members
