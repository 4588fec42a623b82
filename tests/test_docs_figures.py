"""The speed ratios the documentation quotes, re-measured.

Absolute speeds do not travel between machines; a ratio of two times measured in one run
does. The pages write such a figure as ``N.NNx (ratio ±S)``: the ratio and how far a run may
stray from it. ``FIGURES`` has one entry per quoted ratio: the page, the ratio, its spread,
the benchmark command that measures it (as the page names it) and what to take from the
figures that command writes with ``--json``. The fast tests check that every quoted ratio has
its entry and every entry its quote; the slow one runs the commands and fails when a
measurement is off by more than the stated spread. It times things, so it runs only when asked
(``FPGA_ROBOTICS_FIGURES=1 python -m pytest tests/test_docs_figures.py``, on a machine doing
nothing else): a timed test in the default run would fail for the machine's load, not the code.

``python tests/test_docs_figures.py`` measures every entry and prints the figures.
"""

import json
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = ["README.md", *sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").glob("*.md"))]

#: A quoted ratio: ``1.8x (ratio ±0.4)`` (it may wrap at its spaces).
QUOTE = re.compile(r"(\d+(?:\.\d+)?)x\s+\(ratio\s+±(\d+(?:\.\d+)?)\)")
#: Anything that looks like the start of a quote, to catch a malformed one.
LOOSE = re.compile(r"\(ratio\b")
CODE = re.compile(r"``.+?``|`[^`]*`", re.DOTALL)  # a double-backtick span may hold a backtick
FENCE = re.compile(r"^ {0,3}(```|~~~)")


def prose(text):
    """``text`` without its code blocks and code spans (program output and the pattern
    shown as code quote nothing), line breaks kept so that line numbers stay."""
    lines, fenced = [], False
    for line in text.split("\n"):
        if FENCE.match(line):
            fenced = not fenced
            line = ""
        lines.append("" if fenced else line)
    return CODE.sub(lambda m: "\n" * m.group().count("\n"), "\n".join(lines))


@dataclass(frozen=True)
class Figure:
    page: str
    ratio: str  # as the page writes it
    spread: str
    command: str  # the benchmark command (after ``fpga-robotics bench``)
    take: object  # figures dict of the command's --json -> the measured ratio
    what: str


def _rows(figures, key):
    return {(r.get("backend"), r.get("design"), r["width"], r["height"]): r for r in figures[key]}


def _verilator_over_cxxrtl(data):
    rows = _rows(data["figures"], "results")
    return (
        rows[("verilator", "follow_target", 160, 120)]["cpu_ms_per_frame"]
        / rows[("cxxrtl", "follow_target", 160, 120)]["cpu_ms_per_frame"]
    )


def _vga_over_qqvga(data):
    rows = _rows(data["figures"], "results")
    return (
        rows[("cxxrtl", "follow_target", 640, 480)]["cpu_ms_per_frame"]
        / rows[("cxxrtl", "follow_target", 160, 120)]["cpu_ms_per_frame"]
    )


def _paired_fraction(data):
    return data["figures"]["paired"][0]["fraction"]


def _pins_over_frames(data):
    return data["figures"]["backends"][0]["pins_over_frame"]


def _loop_over_design(data):
    run = data["figures"]["runs"][0]
    return run["plain_cpu_ms"] / run["design_alone_cpu_ms"]


def _foreign_over_builtin(data):
    return data["figures"]["foreign_over_builtin"]


def _camera_in_calibrations(data):
    row = data["figures"]["renderer"][0]
    return row["cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _camera_vga_over_qqvga(data):
    small, large = data["figures"]["renderer"]
    return large["cpu_ms"] / small["cpu_ms"]


def _shadow_extra_over_own(data):
    return data["figures"]["extra_over_own"]


def _viewer_in_calibrations(data):
    row = data["figures"]["sizes"][0]
    return row["caller_cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _viewer_vga_over_qqvga(data):
    small, large = data["figures"]["sizes"]
    return large["caller_cpu_ms"] / small["caller_cpu_ms"]


def _model_in_calibrations(data):
    row = data["figures"]["results"][0]
    return row["cpu_ms_per_frame"] / data["calibration"]["cpu_ms"]["median"]


def _pysim_in_calibrations(data):
    return data["figures"]["cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _terrain_in_calibrations(data):
    return data["figures"]["worlds"][-1]["cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _physics_in_calibrations(data):
    return data["figures"]["worlds"][0]["cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _bag_in_calibrations(data):
    return data["figures"]["bag"]["cpu_ms"] / data["calibration"]["cpu_ms"]["median"]


def _revolution_over_frame(data):
    return data["figures"]["revolution_over_frame"]


def _stream_over_uart(data):
    f = data["figures"]
    return (
        f["lidar_stream_mcycles_per_cpu_s"]["median"] / f["lidar_uart_mcycles_per_cpu_s"]["median"]
    )


FIGURES = (
    Figure(
        "docs/lidar.md",
        "75",
        "35",
        "lidar",
        _revolution_over_frame,
        "a LIDAR revolution's CPU time (stream binding, 50 MHz) over a 160x120 FollowTarget frame's",
    ),
    Figure(
        "docs/lidar.md",
        "2.1",
        "0.6",
        "lidar",
        _stream_over_uart,
        "the stream binding's design cycles per CPU second over the UART binding's",
    ),
    Figure(
        "docs/backends.md",
        "2.7",
        "0.6",
        "design --backends cxxrtl,verilator --resolutions 160x120 --no-trivial "
        "--frames 30 --min-seconds 2",
        _verilator_over_cxxrtl,
        "Verilator's CPU time a 160x120 frame over CXXRTL's",
    ),
    Figure(
        "docs/backends.md",
        "17",
        "8",
        "design --backends cxxrtl --resolutions 160x120,640x480 --no-trivial "
        "--frames 30 --min-seconds 2",
        _vga_over_qqvga,
        "CXXRTL's CPU time a 640x480 frame over a 160x120 one",
    ),
    Figure(
        "docs/hardware.md",
        "0.53",
        "0.1",
        "design --backends cxxrtl --resolutions 160x120 --frames 30 --min-seconds 2",
        _paired_fraction,
        "FollowTarget's cycle rate over the trivial design's, CXXRTL",
    ),
    Figure(
        "docs/pins.md",
        "0.9",
        "0.35",
        "pins --backends cxxrtl --seconds 0.25 --repeats 3",
        _pins_over_frames,
        "CXXRTL: the pin path's cycle rate over the frame path's",
    ),
    Figure(
        "docs/backends.md",
        "2.2",
        "0.8",
        "loop --backend cxxrtl --resolutions 160x120 --duration 3 --repeats 3",
        _loop_over_design,
        "the closed loop's CPU time a frame over the design's alone",
    ),
    Figure(
        "README.md",
        "2.2",
        "0.8",
        "loop --backend cxxrtl --resolutions 160x120 --duration 3 --repeats 3",
        _loop_over_design,
        "the closed loop's CPU time a frame over the design's alone",
    ),
    Figure(
        "docs/foreign.md",
        "1.35",
        "0.3",
        "foreign --frames 20 --repeats 3",
        _foreign_over_builtin,
        "the exported design as a foreign design over built-in",
    ),
    Figure(
        "docs/camera.md",
        "0.24",
        "0.12",
        "camera --sizes 160x120 --noise 0 --frames 60 --repeats 3 --calibrate",
        _camera_in_calibrations,
        "the renderer's CPU time a 160x120 frame, in calibrations",
    ),
    Figure(
        "docs/camera.md",
        "3.8",
        "1.5",
        "camera --sizes 160x120,640x480 --noise 0 --frames 60 --repeats 3",
        _camera_vga_over_qqvga,
        "the renderer's CPU time a 640x480 frame over a 160x120 one",
    ),
    Figure(
        "docs/running.md",
        "2.2",
        "0.8",
        "loop --backend cxxrtl --resolutions 160x120 --duration 3 --repeats 3",
        _loop_over_design,
        "the closed loop's CPU time a frame over the design's alone",
    ),
    Figure(
        "docs/running.md",
        "1.35",
        "0.4",
        "loop --backend cxxrtl --resolutions 640x480 --duration 3 --repeats 3",
        _loop_over_design,
        "the same at 640x480",
    ),
    Figure(
        "docs/running.md",
        "1.25",
        "0.35",
        "shadow --backend cxxrtl --duration 3 --repeats 3",
        _shadow_extra_over_own,
        "what a shadow design adds to a frame over its own time",
    ),
    Figure(
        "docs/viewer.md",
        "4.4",
        "1.5",
        "viewer --frames 100 --repeats 3 --calibrate",
        _viewer_in_calibrations,
        "log_frame's CPU time at 160x120 (PNG), in calibrations",
    ),
    Figure(
        "docs/viewer.md",
        "2.5",
        "0.8",
        "viewer --frames 100 --repeats 3 --calibrate",
        _viewer_vga_over_qqvga,
        "log_frame's CPU time at 640x480 over 160x120",
    ),
    Figure(
        "docs/ros.md",
        "1.4",
        "0.7",
        "ros --only bag --repeats 3 --calibrate",
        _bag_in_calibrations,
        "a bag's CPU time a frame, in calibrations",
    ),
    Figure(
        "docs/model.md",
        "0.35",
        "0.2",
        "design --backends model --resolutions 160x120 --no-trivial --frames 30 "
        "--min-seconds 1 --calibrate",
        _model_in_calibrations,
        "the model backend's CPU time a 160x120 frame, in calibrations",
    ),
    Figure(
        "docs/scenarios.md",
        "0.038",
        "0.015",
        "world --frames 300 --repeats 3 --calibrate",
        _terrain_in_calibrations,
        "terrain lookups and drive noise a frame (CPU time), in calibrations",
    ),
    Figure(
        "docs/scenarios.md",
        "0.25",
        "0.08",
        "world --frames 300 --repeats 3 --calibrate",
        _physics_in_calibrations,
        "the default world's physics a frame (CPU time), in calibrations",
    ),
    Figure(
        "docs/hardware.md",
        "2300",
        "700",
        "pysim --frames 3 --calibrate",
        _pysim_in_calibrations,
        "a pysim frame's CPU time, in calibrations",
    ),
    Figure(
        "docs/turret.md",
        "1.75",
        "0.2",
        "cameras --repeats 5",
        lambda data: data["figures"]["cpu_ratio"],
        "turret: the two-camera loop's CPU time a frame over the one-camera loop's",
    ),
)


def quoted(pages=PAGES, root=ROOT):
    """``(page, line, ratio, spread)`` of every quoted ratio; a malformed quote raises."""
    found = []
    for page in pages:
        text = prose((root / page).read_text())
        quotes = list(QUOTE.finditer(text))
        starts = {m.start() for m in quotes}
        for m in LOOSE.finditer(text):
            if not any(start < m.start() < start + 12 for start in starts):
                n = text.count("\n", 0, m.start()) + 1
                raise AssertionError(f"{page}:{n}: a '(ratio' that is not 'N.Nx (ratio ±S)'")
        found += [
            (page, text.count("\n", 0, m.start()) + 1, m.group(1), m.group(2)) for m in quotes
        ]
    return found


def test_every_quoted_ratio_has_an_entry_and_every_entry_a_quote():
    quotes = quoted()
    assert quotes, "no quoted ratio in the documentation"
    in_docs = sorted((page, ratio, spread) for page, _, ratio, spread in quotes)
    in_table = sorted((f.page, f.ratio, f.spread) for f in FIGURES)
    missing = [q for q in quotes if (q[0], q[2], q[3]) not in in_table]
    assert not missing, f"quoted ratios without an entry in FIGURES: {missing}"
    assert in_docs == in_table, "FIGURES has entries that no page quotes (or quotes twice)"


def test_the_quote_pattern(tmp_path):
    (tmp_path / "a.md").write_text(
        "runs at 1.8x (ratio ±0.4) real time; 0.51x (ratio ±0.1).\n"
        "took 3 ms; written `N.Nx (ratio ±S)`; then 2.5x\n"
        "(ratio ±1) over a line break.\n"
        "```\noutput 9.9x (ratio ±1)\n```\n"
    )
    assert quoted(["a.md"], tmp_path) == [
        ("a.md", 1, "1.8", "0.4"),
        ("a.md", 1, "0.51", "0.1"),
        ("a.md", 2, "2.5", "1"),
    ]
    (tmp_path / "b.md").write_text("runs at 1.8 times (ratio 0.4) real time\n")
    with pytest.raises(AssertionError, match="b.md:1"):
        quoted(["b.md"], tmp_path)


def test_every_command_is_a_benchmark_with_its_options():
    from fpga_robotics.cli import BENCHMARKS

    for f in FIGURES:
        assert f.command.split()[0] in BENCHMARKS, f.command


#: Command -> its JSON, so that two quotes of one command share its run.
_RUNS = {}


def measure(figure, folder):
    """Run ``fpga-robotics bench COMMAND --json`` in this process (once per command); the
    ratio it gives."""
    from fpga_robotics.cli import BENCHMARKS, _call

    if figure.command not in _RUNS:
        what, *argv = figure.command.split()
        path = Path(folder) / f"{what}.json"
        with pytest.raises(SystemExit) as exit_:
            _call(BENCHMARKS[what][0], [*argv, "--json", str(path)], f"fpga-robotics bench {what}")
        assert exit_.value.code == 0, figure.command
        _RUNS[figure.command] = json.loads(path.read_text())
    return figure.take(_RUNS[figure.command])


@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.skipif(
    os.environ.get("FPGA_ROBOTICS_FIGURES") != "1",
    reason="times benchmarks: FPGA_ROBOTICS_FIGURES=1 on a quiet machine",
)
@pytest.mark.parametrize("figure", FIGURES, ids=lambda f: f"{f.page}:{f.ratio}x")
def test_quoted_ratio_measures_within_its_spread(figure, tmp_path):
    measured = measure(figure, tmp_path)
    assert abs(measured - float(figure.ratio)) <= float(figure.spread), (
        f"{figure.page}: {figure.what}: quoted {figure.ratio}x ±{figure.spread}, "
        f"measured {measured:.3f}x (fpga-robotics bench {figure.command})"
    )


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        for f in FIGURES:
            if len(sys.argv) > 1 and not any(a in f.command or a in f.page for a in sys.argv[1:]):
                continue
            value = measure(f, tmp)
            print(
                f"RESULT {f.page}: {f.what}: quoted {f.ratio} ±{f.spread}, measured {value:.3f}",
                file=sys.stderr,
                flush=True,
            )
