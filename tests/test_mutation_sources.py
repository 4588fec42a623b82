"""Where a mutant of a design of one's own says it acts: a line of the design's file, never
one of Python's own library (the state of ``with m.FSM()`` is made as the block ends, inside
contextlib)."""

import contextlib
from pathlib import Path

import pytest

from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.sim import mutation

DESIGN = Path(__file__).parent / "data" / "user_designs" / "phases.py"

try:
    mutation.find_yosys()
    NO_YOSYS = None
except mutation.MutationError as exc:  # pragma: no cover - depends on the machine
    NO_YOSYS = str(exc)


def _line_of(text):
    return next(n for n, line in enumerate(DESIGN.read_text().splitlines(), 1) if text in line)


def test_the_fsm_state_is_located_at_its_with_line():
    rtlil_text = mutation.component_rtlil(resolve_design(f"{DESIGN}:Phases").build())
    assert "contextlib" not in rtlil_text
    state = rtlil_text.index("wire width 2 \\fsm_state")
    src = rtlil_text[:state].rpartition('attribute \\src "')[2].partition('"')[0]
    assert src == f"{DESIGN.resolve()}:{_line_of('with m.FSM()')}"


@pytest.mark.skipif(NO_YOSYS is not None, reason=str(NO_YOSYS))
def test_mutants_of_the_fsm_state_name_the_with_line():
    rtlil_text = mutation.component_rtlil(resolve_design(f"{DESIGN}:Phases").build())
    mutants = mutation.list_mutants(None, 20, 1, rtlil_text=rtlil_text)
    on_state = [m for m in mutants if m.signal == "fsm_state"]
    assert on_state
    # (relative to the project's folder where the file lies in it, as here)
    where = f"user_designs/phases.py:{_line_of('with m.FSM()')}"
    for m in on_state:
        assert len(m.sources) == 1 and m.sources[0].endswith(where), m.describe()


def test_a_place_in_python_s_library_is_left_out_of_a_listed_mutant():
    stdlib = f"{contextlib.__file__}:144"
    line = (
        "mutate -mode inv -module follow_target -cell $68 -port Q -portbit 1 "
        f"-wire fsm_state -wirebit 1 -src {stdlib} -src {stdlib}|/x/mine.py:12"
    )
    assert mutation._parse(8, line).sources == ("/x/mine.py:12",)
