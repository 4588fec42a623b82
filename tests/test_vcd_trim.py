"""``vcd_trim.trim_vcd`` on hand-written VCDs: the header kept, the values at the window's start
as the initial dump, only the changes inside the window, read no further than needed."""

import io

import pytest
from vcd.reader import TokenKind, tokenize

from fpga_robotics.sim.backends.vcd_trim import VCDTrimError, trim_vcd

HEADER = """\
$comment Hand-written $end
$timescale 1 ns $end
$scope module top $end
$var wire 1 ! clk $end
$var wire 4 " count $end
$var wire 1 # late $end
$var real 1 $ level $end
$scope module sub $end
$var wire 4 " count_alias $end
$upscope $end
$upscope $end
$enddefinitions $end
"""

BODY = """\
#0
$dumpvars
0!
b0 "
r0.5 $
$end
#5
1!
b1 "
#10
0!
$comment a comment
in the middle $end
#15
1!
b10 "
1#
#20
0!
r1.25 $
#25
1!
b11 "
#30
0!
"""


def trim(text, start, end, **kwargs):
    out = io.StringIO()
    trim_vcd(io.StringIO(text), out, start, end, **kwargs)
    return out.getvalue()


def after_header(text):
    return text.split("$enddefinitions $end\n", 1)[1]


def test_header_kept_values_at_start_dumped_and_only_the_window_copied():
    out = trim(HEADER + BODY, 10, 25)
    assert out.startswith(HEADER)
    # At 10: clk fell at 10 itself (at or before the start counts), count is 1 from 5, the
    # alias is not repeated, `late` has no value yet (x), level 0.5 since 0.
    assert (
        after_header(out)
        == """\
#0
$dumpvars
0!
b1 "
x#
r0.5 $
$end
#15
1!
b10 "
1#
#20
0!
r1.25 $
#25
"""
    )


def test_a_window_from_time_0_folds_the_changes_at_0_into_the_dump():
    out = trim(HEADER + BODY + "#40\n", 0, 12)
    assert (
        after_header(out)
        == """\
#0
$dumpvars
0!
b0 "
x#
r0.5 $
$end
#5
1!
b1 "
#10
0!
#12
"""
    )


def test_a_window_past_the_last_change_is_the_dump_and_the_end():
    out = trim(HEADER + BODY, 100, 200)
    assert after_header(out) == '#0\n$dumpvars\n0!\nb11 "\n1#\nr1.25 $\n$end\n#200\n'


def test_vectors_without_a_value_are_x_and_tokens_may_share_or_split_lines():
    header = (
        "$timescale 1ps $end $scope module m $end $var wire 8 % bus $end "
        "$var reg 1 & bit $end $var wire 3 ' nib $end $upscope $end "
        "$enddefinitions $end #0 1&\n"
    )
    body = "#3 b1010\n%\n#7 0& b1111 % #9 1&\n"
    out = trim(header + body, 4, 9)
    assert out.startswith(header[: header.index("#0")].rstrip() + "\n")
    assert after_header(out) == ("#0\n$dumpvars\nb1010 %\n1&\nbx '\n$end\n#7\n0&\nb1111 %\n#9\n")


def test_the_input_is_read_only_up_to_the_window_end():
    def lines():
        yield from io.StringIO(HEADER + BODY).readlines()[:-4]  # up to "#25"
        raise AssertionError("read past the window")

    out = io.StringIO()
    trim_vcd(lines(), out, 10, 25)
    assert after_header(out.getvalue()).endswith("r1.25 $\n#25\n")


def test_the_output_is_a_valid_vcd_with_every_variable():
    out = trim(HEADER + BODY, 7, 22)
    kinds, times, ids = [], [], set()
    for token in tokenize(io.BytesIO(out.encode())):
        kinds.append(token.kind)
        if token.kind is TokenKind.CHANGE_TIME:
            times.append(token.time_change)
        elif token.kind is TokenKind.VAR:
            ids.add(token.var.reference)
    assert ids == {"clk", "count", "late", "level", "count_alias"}
    assert times == [0, 10, 15, 20, 22]
    assert TokenKind.DUMPVARS in kinds


def test_timescale_is_checked_when_given():
    assert trim(HEADER + BODY, 10, 25, timescale="1ns") == trim(HEADER + BODY, 10, 25)
    with pytest.raises(VCDTrimError, match="timescale is '1 ns', expected '1 fs'"):
        trim(HEADER + BODY, 10, 25, timescale="1 fs")


@pytest.mark.parametrize(
    "text,message",
    [
        ("hello world\n", "unexpected token 'hello'"),
        (HEADER.replace("$enddefinitions $end\n", ""), "no \\$enddefinitions"),
        (HEADER + "#5\nb101\n", "ends inside the value change"),
        (HEADER + "#5\n?!\n", "unexpected token '\\?!'"),
        (HEADER + "#five\n", "bad time"),
    ],
)
def test_malformed_input_is_a_clear_error(text, message):
    with pytest.raises(VCDTrimError, match=message):
        trim(text, 1, 100)


@pytest.mark.parametrize("start,end", [(5, 5), (6, 5), (-1, 5)])
def test_the_window_must_not_be_empty(start, end):
    with pytest.raises(ValueError, match="0 <= start < end"):
        trim(HEADER + BODY, start, end)
