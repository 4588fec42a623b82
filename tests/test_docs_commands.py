"""Every command in the documentation's code blocks runs, and does what the page says.

The commands are read from the fenced code blocks of README.md and docs/*.md: in shell blocks
(```` ```sh ````, ```` ```bash ````, or no language), the lines that start with
``python -m fpga_robotics``, ``python3 -m``, ``fpga-robotics``, ``rerun``, ``openFPGALoader``
or ``python -m pytest`` (with ``\\`` continuations joined and a trailing ``# comment`` split
off); and every ```` ```python ```` block. A shell block holds runnable commands only: a usage
synopsis (an optional ``[...]`` part, a ``...``) belongs in a ```` ```text ```` block, and
``test_shell_blocks_hold_no_synopsis`` fails on one.

Each command has an entry in ``PLANS`` (keyed by its text as the page writes it): how it is
run, and what is checked besides its exit code; or why it is not run here. A command that
is not in the table fails ``test_every_documented_command_is_classified``, so a page cannot
gain a command that nobody runs or excuses. The exit code expected is the page's: 0, or 1
where the command's comment says ``FAIL``.

The commands of one code block run in order, each as a subprocess of ``bash -c`` with a
timeout, in one fresh temporary folder (so ``--save-video clip.mp4`` and then
``--source clip.mp4`` work), with no display in the environment (so the viewer's ``auto``
mode saves a file, as on CI). They are made short: ``run`` gets ``--duration 1`` unless the
plan says why the page's run needs longer, and ``--rerun off --quiet`` unless it is about the
viewer; ``bench`` gets ``--frames 2 --min-seconds 0``; the other benchmarks their own small
counts. pytest commands are collected
(``--collect-only``), not run: running the tests is CI's own ``python -m pytest``. A server
that runs until Ctrl-C (``rerun --serve-web``) is started on free loopback ports, must answer
HTTP 200 within a bounded time, and is stopped with SIGINT. Place and route (``--bitstream``)
runs only under ``-m slow``. ``python tests/test_docs_commands.py`` prints what is not run
and why, and which runs keep the page's duration and why.

Python blocks are executed with ``exec`` in a namespace holding the names they assume (a
real frame, a world, frame records), and what they show is asserted. A bare expression of a
snippet (``result.found, ...``) is captured so that the test can check its value.
"""

import ast
import json
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import textwrap
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from terminal_signals import FROM_A_TERMINAL

ROOT = Path(__file__).resolve().parent.parent

#: The pages whose code blocks are checked.
PAGES = ["README.md", *sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").glob("*.md"))]

#: What starts a command line in a shell block.
COMMAND_PREFIXES = (
    "python -m fpga_robotics",
    "python3 -m",
    "fpga-robotics",
    "rerun",
    "openFPGALoader",
    "python -m pytest",
)

#: A line of a shell block that looks like a command (a program name first). In a block
#: marked as shell every line is a command or a comment; in a block without a language (which
#: may hold output) only such lines are taken for commands. Either way, one that is not a
#: documented command (``pip install ...``, ``python -m something_else``) fails the
#: classification test instead of being skipped silently.
LOOKS_LIKE_COMMAND = re.compile(
    r"^(\$\s+)?(sudo\s+)?(python[\d.]*|pip[\d.]*|pytest|fpga-robotics|fpga_robotics|rerun|"
    r"openFPGALoader|apt-get|apt|ssh|yowasp-[\w-]+|verilator|make|git|curl|cd|source|\.)(\s|$)"
)

SHELL_LANGS = {"", "sh", "bash", "shell", "console"}

#: Seconds one command may take (a cold compiled-model build included) before it counts as hung.
TIMEOUT = 300

FAIL_MARK = re.compile(r"\bFAIL\b")


# --- Extraction -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Block:
    page: str
    line: int  # the opening fence's line
    lang: str
    lines: tuple  # (line number, text) of the block's content


@dataclass(frozen=True)
class DocCommand:
    page: str
    line: int
    text: str  # the command as written (continuations joined, whitespace collapsed)
    comment: str  # its trailing comment, without the '#'

    @property
    def expected_rc(self):
        """The exit code the page gives the command: 1 where its comment says FAIL."""
        return 1 if FAIL_MARK.search(self.comment) else 0


_FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})\s*([\w+-]*)")


def fenced_blocks(page, text):
    """The fenced code blocks of a Markdown text."""
    blocks, fence, start, lang, body = [], None, 0, "", []
    for n, line in enumerate(text.split("\n"), 1):
        m = _FENCE.match(line)
        if fence is None:
            if m:
                fence, start, lang, body = m.group(1), n, m.group(2).lower(), []
        elif line.strip().startswith(fence) and set(line.strip()) == {fence[0]}:
            blocks.append(Block(page, start, lang, tuple(body)))
            fence = None
        else:
            body.append((n, line))
    return blocks


def split_comment(line):
    """``(command, comment)``: a ``#`` after a blank, outside quotes, starts a comment."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip(), line[i + 1 :].strip()
    return line.rstrip(), ""


def logical_lines(block):
    """``(line number, code, comment)`` of a shell block, ``\\`` continuations joined."""
    out = []
    pending = None  # [line, code, comment] still open for a continuation
    for n, raw in block.lines:
        code, comment = split_comment(raw)
        if pending is not None and pending[1].endswith("\\"):
            pending[1] = pending[1][:-1].rstrip() + " " + code.strip()
            pending[2] = comment or pending[2]
            continue
        if pending is not None:
            out.append(tuple(pending))
        pending = [n, code, comment]
    if pending is not None:
        out.append(tuple(pending))
    return out


def collapse(text):
    return " ".join(text.split())


#: What marks a usage synopsis rather than a command: an optional ``[...]`` part after a blank
#: (not a quoted TOML list such as ``--set 'x=[1,2]'``, not ``".[dev]"``), or ``...``.
SYNOPSIS = re.compile(r"(?:^|\s)\[[^\]]*\]|(?:^|\s)\.\.\.(?:\s|\]|$)")


def is_synopsis(code, previous_is_synopsis):
    """Whether a logical line of a shell block is (part of) a usage synopsis: a command with an
    optional part, or an indented ``[...]`` line under one."""
    stripped = code.strip()
    if stripped.startswith("[") and code[:1].isspace():
        return previous_is_synopsis
    return stripped.startswith(COMMAND_PREFIXES) and bool(SYNOPSIS.search(stripped))


def synopsis_lines(page):
    """``page:line: text`` of every line of a shell block that is a usage synopsis."""
    text = (ROOT / page).read_text(encoding="utf-8")
    found = []
    for block in fenced_blocks(page, text):
        if block.lang not in SHELL_LANGS:
            continue
        previous = False
        for n, code, _ in logical_lines(block):
            previous = is_synopsis(code, previous)
            if previous:
                found.append(f"{page}:{n}: {code.strip()}")
    return found


def scan_page(page):
    """``(commands, python blocks, unclassified lines)`` of one page."""
    text = (ROOT / page).read_text(encoding="utf-8")
    commands, snippets, strays = [], [], []
    for block in fenced_blocks(page, text):
        if block.lang == "python":
            snippets.append(block)
            continue
        if block.lang not in SHELL_LANGS:
            continue
        synopsis = False
        for n, code, comment in logical_lines(block):
            stripped = code.strip()
            if stripped.startswith("$ "):
                stripped = stripped[2:].lstrip()
            if not stripped:
                continue
            synopsis = is_synopsis(code, synopsis)
            if synopsis:
                continue  # test_shell_blocks_hold_no_synopsis reports it
            if stripped.startswith(COMMAND_PREFIXES):
                commands.append(DocCommand(page, n, collapse(stripped), comment))
            elif block.lang or LOOKS_LIKE_COMMAND.match(stripped):
                strays.append(f"{page}:{n}: {stripped}")
    return commands, snippets, strays


def command_blocks():
    """Every shell block with commands, as ``(page, fence line, [DocCommand])``."""
    found = []
    for page in PAGES:
        text = (ROOT / page).read_text(encoding="utf-8")
        for block in fenced_blocks(page, text):
            if block.lang not in SHELL_LANGS:
                continue
            lines = {n for n, _ in block.lines}
            cmds = [c for c in scan_page(page)[0] if c.line in lines]
            if cmds:
                found.append((page, block.line, cmds))
    return found


def python_blocks():
    return [b for page in PAGES for b in scan_page(page)[1]]


def snippet_key(block):
    """``(page, first line)``: how ``SNIPPETS`` names a Python block."""
    first = next(text for _, text in block.lines if text.strip())
    return block.page, first.strip()


# --- How each command is run ----------------------------------------------------------------------


@dataclass(frozen=True)
class Plan:
    """How a documented command is run here, or why it is not."""

    #: Why it is not run at all (None: it is run).
    excused: str = None
    #: Only this part of a ``&&`` chain is run; ``part_why`` says why the rest is not.
    part: str = None
    part_why: str = None
    #: ``run``: keep the page's duration, or use this one, and say why (else ``--duration 1``).
    duration: str = None
    duration_why: str = None
    #: ``run``: about the viewer, so no ``--rerun off`` is added.
    viewer: bool = False
    #: ``(option, value)`` pairs set to keep it short (benchmarks other than ``bench``).
    shorter: tuple = ()
    #: Commands run first in the folder, to make what the command's placeholders name.
    setup: tuple = ()
    #: Files (relative to the folder) that must exist afterwards.
    files: tuple = ()
    #: Regular expressions that must match the output (stdout and stderr).
    out: tuple = ()
    #: Regular expressions that must not match the output.
    not_out: tuple = ()
    #: A regular expression the last line of stdout must match.
    last_line: str = None
    #: Items the ``--summary s.json`` file must hold (``...``: the key is there).
    summary: tuple = ()
    #: A pytest command: collected in the repository (``--collect-only``), not run.
    collect: bool = False
    #: A server that runs until Ctrl-C: started on free ports, asked for its page, stopped.
    serve: bool = False
    #: Marked slow (it builds Verilator models or runs place and route): run only by
    #: ``test_documented_slow_command``.
    slow: bool = False


#: A run whose recording is the placeholder ``runs/follow_person.rrd`` of a page.
MAKE_RECORDING = "python -m fpga_robotics.run --duration 1 --quiet"
#: A run whose camera frames are the placeholder ``clip.mp4`` of a page.
MAKE_CLIP = "python -m fpga_robotics.run --duration 1 --rerun off --quiet --save-video clip.mp4"

SCENARIO_NAMES = ("follow_person", "divider", "lighting", "heavy_robot", "lost_target")
PASS = r"(?m)^verdict: PASS$"
#: Why docs/camera.md's sensor-model runs keep their scenario's duration.
_SENSOR_WHY = (
    "the page gives the verdict of the whole scenario (the divider's mean-distance "
    "check fails in runs under 15 s; the dimming of lighting lasts from 8 s to 24 s)"
)
SAVED_DEFAULT = (
    r"saved \d+ frames .* to runs/follow_person\.rrd .*open it with: rerun runs/follow_person\.rrd"
)

_DIVIDER_WHY = (
    "the scenario's own 25 s (about 1 s of wall time): the loose filter's robot turns to the "
    "wood and loses the person from view between 10 and 15 s, which is the failure the page "
    "means; a run of 10 s or less fails only the mean-distance check, as the default design does"
)

_APPROACH_WHY = (
    "the scenario's own 30 s (about a second of wall time): with the early thresholds the "
    "robot reaches the standing person at 26.7 s; the page's default run must stop short over "
    "the same time"
)

_ERRATIC_WHY = (
    "the scenario's own 30 s (about a second of wall time): the robot tips at 3.17 s and the "
    "oscillation the page quotes is over the whole run; a 1 s run of the default design fails "
    "its mean-distance check"
)

PLANS = {
    # README: two commands on a fresh machine ------------------------------------------------
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e . && python -m fpga_robotics.run": Plan(
        part="python -m fpga_robotics.run",
        part_why="the virtual environment and the install are the ones this test runs in; "
        ".ci/run makes them in a fresh clone on every submission",
        viewer=True,
        files=("runs/follow_person.rrd",),
        out=(PASS, SAVED_DEFAULT),
        last_line=r"runs/follow_person\.rrd$",
    ),
    'python3 -m venv .venv && . .venv/bin/activate && pip install -e ".[dev,board]" && '
    "python -m pytest -q -n auto": Plan(
        part="python -m pytest -q -n auto",
        collect=True,
        part_why="the set-up and the whole test run are CI's own command (.ci/run, checked "
        "by test_ci_runs_the_readme_test_command); here the suite is collected",
        out=(r"\d{3,} tests collected",),
    ),
    # docs/formal.md ------------------------------------------------------------------------------
    "python -m fpga_robotics.formal": Plan(
        excused="every formal check, about a minute of wall time with two solver jobs; "
        "the same checks run as tests (`pytest -m formal`, "
        "tests/test_formal_checks.py), and the documented --only commands run here"
    ),
    "python -m fpga_robotics.formal --list": Plan(
        out=(
            r"(?m)^frame_done\.latency@16x2\s+bmc\s+60\s",
            r"(?m)^capture\.no_overflow@fifo_depth=16\s+bmc\s+40\s",
        )
    ),
    "python -m fpga_robotics.formal --only frame_done.strobe": Plan(
        out=(r"(?m)^frame_done\.strobe@16x2\s+prove\s+4\s+pass\s", r"(?m)^1 of 1 checks passed")
    ),
    "python -m fpga_robotics.formal --only motor --depth 4": Plan(
        out=(
            r"(?m)^motor\.limits_hold_search@defaults\s+prove\s+4\s+pass\s",
            r"(?m)^motor\.limits_hold_search@odd\s+prove\s+4\s+pass\s",
            r"(?m)^2 of 2 checks passed",
        )
    ),
    "fpga-robotics formal --design counters.py:Saturating": Plan(
        setup=(f"cp {ROOT / 'tests/data/user_designs/counters.py'} .",),
        out=(
            r"(?m)^Saturating\.properties\s+prove\s+3\s+pass\s",
            r"(?m)^Saturating\.covers\s+cover\s+12\s+pass\s",
            r"(?m)^2 of 2 checks passed",
        ),
    ),
    "fpga-robotics formal --design counters.py:OffByOne": Plan(
        setup=(f"cp {ROOT / 'tests/data/user_designs/counters.py'} .",),
        out=(
            r"(?m)^OffByOne\.properties\s+bmc\s+15\s+FAIL\s",
            r"failed assertion \S*counters\.py:40 step 11",
            r"counterexample: \S*OffByOne\.properties\.vcd",
        ),
    ),
    "python -m pytest -m formal": Plan(
        collect=True,
        out=(
            r"test_seeded_bug_fails\[tracker\.no_leak@16x2\]",
            r"test_check_passes\[cover\.sccb\]",
        ),
    ),
    # Viewing a recording ---------------------------------------------------------------------
    "rerun --serve-web --bind 127.0.0.1 runs/follow_person.rrd": Plan(
        serve=True, setup=(MAKE_RECORDING,)
    ),
    "rerun out/run.rrd": Plan(
        excused="opens rerun's native viewer window: needs a display (the web viewer of "
        "the same file is checked through `rerun --serve-web`)"
    ),
    # README: the first ten minutes -----------------------------------------------------------
    "python -m fpga_robotics.run --target-color green":
    # Found in every frame: the person is dressed in green and the design selects green.
    Plan(out=(PASS, r"target: first found at 0\.00 s, in view 100%, found 100%")),
    "python -m fpga_robotics.run --scenario divider --set design.diff_min=5 --rerun off": Plan(
        duration="keep",
        duration_why=_DIVIDER_WHY,
        out=(
            r"\[FAIL\] target_in_view_min_fraction",
            r"\[FAIL\] max_off_target_fraction: centroid away .* out of view, in 83%",
        ),
    ),
    "python -m fpga_robotics.run --scenario divider --shadow diff_min=5 --rerun off": Plan(
        duration="keep",
        duration_why="the page says the default design passes: over the whole scenario "
        "(25 s); a run under 15 s fails its mean-distance check",
        out=(PASS, r"shadow diff_min=5: first differs at frame \d+"),
    ),
    "python -m fpga_robotics.run --duration 5 --rerun off --save-video clip.mp4": Plan(
        files=("clip.mp4",), out=(PASS,)
    ),
    "python -m fpga_robotics.run --source clip.mp4 --rerun off": Plan(
        out=(r"source clip\.mp4 \(video\)", r"target found in 30 frames")
    ),
    # README and docs/running.md: the closed loop ---------------------------------------------
    "python -m fpga_robotics.run --list-scenarios": Plan(
        out=tuple(rf"(?m)^{name}\s" for name in SCENARIO_NAMES)
    ),
    "python -m fpga_robotics.run --scenario lost_target --rerun off --summary s.json": Plan(
        duration="keep",
        duration_why="lost_target's reacquired_within_s needs the person to leave the view "
        "and be found again (after about 4 s); a shorter run leaves it nothing to judge (15 s "
        "simulated, under a second of wall time)",
        files=("s.json",),
        out=(PASS,),
        summary=(("scenario", "lost_target"), ("verdict", "pass")),
    ),
    "python -m fpga_robotics.run --resolution 640x480 --backend verilator --duration 5 --rerun off": Plan(
        slow=True, out=(r"backend verilator\s+640x480", PASS)
    ),
    "python -m fpga_robotics.run":
    # The page's "typical ending", line by line.
    Plan(
        out=(
            r"(?m)^scenario follow_person\s+backend {fastest}\s+160x120\s+seed 0$",
            (
                r"(?m)^  30 frames, 1\.0 s simulated in [\d.]+ s \([\d.]+ ms/frame, "
                r"[\d.]+x real time\)$"
            ),
            (
                r"(?m)^  target: first found at [\d.]+ s, in view \d+%, found \d+%, "
                r"\d+ search\(es\)$"
            ),
            r"(?m)^  distance: min [\d.]+ m, mean [\d.]+ m; path [\d.]+ m$",
            r"(?m)^  collisions: person 0, wall 0, furniture 0$",
            r"(?m)^  \[ok\] acquired_within_s: ",
            PASS,
        )
    ),
    "python -m fpga_robotics.run --scenario lost_target --rerun off": Plan(
        duration="keep", duration_why="as for the same command with --summary", out=(PASS,)
    ),
    # docs/stories.md -------------------------------------------------------------------------
    "python -m pytest -q -m stories tests/test_story_*.py": Plan(
        collect=True,
        out=(
            r"test_story_b_early_thresholds_drive_into_the_person",
            r"test_story_c_an_unstable_gain_tips_the_gopigo3",
            r"test_story_d_a_too_narrow_sx_puts_the_centroid_off_centre",
            r"\(\d+ deselected\)",
        ),
        not_out=(r"test_the_check_reads_the_at_fault_count",),
    ),
    "python -m fpga_robotics.run --scenario approach --rerun off --set robot.heading_deg=20 "
    "--set checks.max_heading_overshoot_deg=5": Plan(
        duration="keep",
        duration_why="the page says the default gain never turns past the person: over the "
        "whole 30 s run (about a second of wall time); in 1 s the robot has "
        "not finished its turn, so 0 degrees there would prove nothing",
        out=(PASS, r"\[ok\] max_heading_overshoot_deg: turned 0\.0 deg"),
    ),
    "python -m fpga_robotics.run --scenario approach --rerun off --set robot.heading_deg=20 "
    "--set checks.max_heading_overshoot_deg=5 --set design.kp_num=16": Plan(
        out=(r"\[FAIL\] max_heading_overshoot_deg: turned 11\.0 deg past the target",)
    ),
    "python -m fpga_robotics.run --scenario divider --rerun off": Plan(
        duration="keep",
        duration_why="the page says the default design passes: over the whole scenario "
        "(25 s); a run under 15 s fails its mean-distance check",
        out=(PASS, r"\[ok\] max_off_target_fraction: centroid away .* out of view, in 0%"),
    ),
    "python -m fpga_robotics.run --scenario approach --rerun off": Plan(
        duration="keep",
        duration_why=_APPROACH_WHY,
        out=(PASS, r"\[ok\] max_robot_at_fault_collisions"),
    ),
    "python -m fpga_robotics.run --scenario approach --rerun off --set design.sx_bits=17": Plan(
        duration="keep",
        duration_why="the page quotes the whole 30 s run (about a second of wall time): its "
        "mean centroid error over the frames found, and the bump at 15.4 s",
        out=(
            r"\[FAIL\] mean_centroid_error_max_px: centroid 89\.09 px from the target",
            r"\[FAIL\] max_robot_at_fault_collisions",
        ),
    ),
    "python -m fpga_robotics.run --scenario approach --rerun off --set "
    '"design.proximity_thresholds=[128,256,512,1024,2048,19000,19100]"': Plan(
        duration="keep",
        duration_why=_APPROACH_WHY,
        out=(r"\[FAIL\] max_person_collisions", r"\[FAIL\] max_robot_at_fault_collisions"),
    ),
    "python -m fpga_robotics.run --scenario erratic --rerun off": Plan(
        duration="keep", duration_why=_ERRATIC_WHY, out=(PASS, r"\[ok\] max_tip_overs")
    ),
    "python -m fpga_robotics.run --scenario erratic --rerun off --set design.kp_num=32": Plan(
        duration="keep",
        duration_why=_ERRATIC_WHY,
        out=(r"\[FAIL\] max_tip_overs: the robot tipped over at 3\.17 s",),
    ),
    "python -m fpga_robotics.run --scenario erratic --rerun off --set design.preset=published": Plan(
        duration="keep",
        duration_why=_ERRATIC_WHY,
        out=(r"\[FAIL\] max_oscillation_hz: W changes sign 4\.87 times",),
    ),
    "python -m fpga_robotics.run --scenario divider --set design.diff_min=5": Plan(
        duration="keep", duration_why=_DIVIDER_WHY, out=(r"\[FAIL\] target_in_view_min_fraction",)
    ),
    "python -m fpga_robotics.run --resolution 320x240 --backend verilator --summary s.json": Plan(
        slow=True,
        files=("s.json",),
        out=(r"backend verilator\s+320x240", PASS),
        summary=(("backend", "verilator"), ("resolution", "320x240")),
    ),
    "python -m fpga_robotics.run --source clip.mp4 --color red": Plan(
        setup=(MAKE_CLIP,),
        out=(
            r"source clip\.mp4 \(video\)\s+backend \w+\s+160x120\s+colour red",
            r"target found in 30 frames",
        ),
    ),
    "python -m fpga_robotics.run --scenario follow_person --rerun off --summary s.json":
    # README quotes the summary's realtime_factor of this command.
    Plan(files=("s.json",), out=(PASS,), summary=(("realtime_factor", ...),)),
    "python -m fpga_robotics.run --scenario follow_person --rerun off --summary s.json "
    "--resolution 640x480 --duration 10": Plan(
        files=("s.json",),
        out=(PASS,),
        summary=(("resolution", "640x480"), ("realtime_factor", ...)),
    ),
    "python -m fpga_robotics.run --backend model --rerun off --quiet --duration 20 "
    "--scenario lost_target --shadow 'lost_frames=5'": Plan(
        duration="keep",
        duration_why="the page shows this run's last lines, frame numbers and counts "
        "'of 600' included (model backend: under a second of wall time)",
        out=(
            re.escape(
                "  shadow lost_frames=5: first differs at frame 119 (3.97 s): "
                "motor_left 208 vs -250, motor_right 512 vs 250"
            ),
            re.escape("  shadow frames that differ: motor_left 10, motor_right 10 (of 600)"),
        ),
    ),
    "python -m fpga_robotics.run --backend model --rerun off --quiet --duration 20 "
    "--scenario lost_target --shadow 'lost_frames=5' --shadow-continue": Plan(
        duration="keep",
        duration_why="the page shows the frame the shadow takes over at and its run's "
        "figures (model backend: seconds of wall time)",
        out=(
            re.escape("  shadow lost_frames=5 on its own (drives from frame 119):"),
            re.escape("  scenario lost_target  backend model  160x120  seed 0"),
            r"distance: min 0\.89 m, mean 1\.35 m; path 1\.0 m",
            r"(?m)^  verdict: PASS$",
        ),
    ),
    # docs/campaigns.md: verification campaigns on Dask -------------------------------------
    "python -m fpga_robotics.sweep regression --dry-run": Plan(
        out=(
            r"campaign regression: 180 runs",
            (
                r"(?m)^  python -m fpga_robotics\.run --scenario approach --backend \w+ "
                r"--seed 0$"
            ),
        )
    ),
    "python -m fpga_robotics.sweep regression":
    # Two short runs on the model backend: the whole campaign takes minutes (the page
    # gives its measured time); the next command reads the same folder. Two seconds cannot
    # bring approach's mean distance from its 2.0 m start under the scenario's 1.75 m (the
    # sweeps below start with approach too): the short runs lift that limit.
    Plan(
        shorter=(
            ("--max-runs", "2"),
            ("--backend", "model"),
            ("--duration", "2"),
            ("--set", "checks.mean_distance_max_m=3"),
        ),
        files=(
            "runs/sweeps/regression/results.parquet",
            "runs/sweeps/regression/results.csv",
            "runs/sweeps/regression/report.html",
        ),
        out=(r"2 runs: 2 pass", r"pass rate per scenario:"),
    ),
    # Two variants, 2 s: the page quotes the whole campaign's measured figures.
    "fpga-robotics sweep --scenarios lost_target --backend model --duration 10 --grid "
    '"design.lost_frames=[5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24]" --workers 2 --record none '
    "--out runs/sweeps/fork": Plan(
        shorter=(("--duration", "2"), ("--grid", "design.lost_frames=[5,24]")),
        files=("runs/sweeps/fork/report.html",),
        out=(r"2 runs: ",),
    ),
    "fpga-robotics sweep --scenarios lost_target --backend model --duration 10 --grid "
    '"design.lost_frames=[5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24]" --workers 2 --record none '
    "--out runs/sweeps/no-fork --no-fork": Plan(
        shorter=(("--duration", "2"), ("--grid", "design.lost_frames=[5,24]")),
        files=("runs/sweeps/no-fork/report.html",),
        out=(r"2 runs: ",),
    ),
    "python -m fpga_robotics.sweep report runs/sweeps/regression": Plan(
        files=("runs/sweeps/regression/report.html",),
        out=(r"2 runs: 2 pass",),
        last_line=r"report: runs/sweeps/regression/report\.html$",
    ),
    "python -m fpga_robotics.sweep filter_tuning":
    # Two short runs: the page quotes the whole campaign's measured figures.
    Plan(
        shorter=(("--max-runs", "2"), ("--backend", "model"), ("--duration", "2")),
        files=("runs/sweeps/filter_tuning/report.html",),
        out=(r"2 runs: ", r"pass rate per design\.diff_min:", r"pass rate per lighting\.ambient:"),
    ),
    "python -m fpga_robotics.sweep robot_variants": Plan(
        shorter=(("--max-runs", "2"), ("--backend", "model"), ("--duration", "2")),
        files=("runs/sweeps/robot_variants/report.html",),
        out=(r"2 runs: ", r"pass rate per robot\.mass:"),
    ),
    "python -m fpga_robotics.sweep sensor_designs":
    # Two one-second runs in real-clock timing (the campaign's first two: line_track, whose
    # lap a second cannot complete).
    Plan(
        shorter=(("--max-runs", "2"), ("--duration", "1"), ("--set", "checks.min_laps=0")),
        files=("runs/sweeps/sensor_designs/report.html",),
        out=(r"2 runs: ", r"pass rate per scenario:"),
    ),
    "python -m fpga_robotics.sweep robustness":
    # Two short runs: the page gives the whole campaign's results and known limits.
    Plan(
        shorter=(
            ("--max-runs", "2"),
            ("--duration", "2"),
            ("--set", "checks.mean_distance_max_m=3"),
        ),
        files=("runs/sweeps/robustness/report.html",),
        out=(r"2 runs: ", r"pass rate per robot\.model:"),
    ),
    "python -m fpga_robotics.sweep robustness_small": Plan(
        shorter=(("--max-runs", "2"), ("--duration", "2")),
        files=("runs/sweeps/robustness_small/report.html",),
        out=(r"2 runs: 2 pass",),
    ),
    "python -m fpga_robotics.sweep regression --scheduler tcp://HOST:8786": Plan(
        excused="needs a Dask cluster (HOST is the page's placeholder); "
        "tests/test_sweep_scheduler.py runs a campaign through a real `dask "
        "scheduler` and `dask worker` on 127.0.0.1"
    ),
    "python -m fpga_robotics.sweep --bench": Plan(
        shorter=(("--bench-runs", "2"), ("--bench-repeats", "1"), ("--duration", "1")),
        out=(
            r"1 worker\(s\): [\d.]+ runs/s",
            r"outside run_scenario with 1 worker: [\d.-]+ ms per run",
        ),
    ),
    # docs/viewer.md --------------------------------------------------------------------------
    "python -m fpga_robotics.run --scenario follow_person": Plan(
        viewer=True, files=("runs/follow_person.rrd",), out=(SAVED_DEFAULT,)
    ),
    "python -m fpga_robotics.run --scenario follow_person --rerun save:out/run.rrd": Plan(
        viewer=True, files=("out/run.rrd",), out=(r"saved \d+ frames .* to out/run\.rrd",)
    ),
    "fpga-robotics bench viewer": Plan(
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(r"160x120: wall median", r"640x480: wall median"),
    ),
    # docs/foreign.md: your own Verilog design -----------------------------------------------
    "python -m fpga_robotics.export -o follow_target.v": Plan(
        files=("follow_target.v",), out=(r"160x120, module follow_target",)
    ),
    "fpga-robotics ports --example ports.toml": Plan(
        files=("ports.toml",), out=(r"wrote ports\.toml",)
    ),
    "python -m fpga_robotics.run --design verilog:follow_target.v --ports ports.toml": Plan(
        slow=True,
        setup=(
            "python -m fpga_robotics.export -o follow_target.v",
            "fpga-robotics ports --example ports.toml",
        ),
        out=(PASS, r"(?m)^backend:? .*cxxrtl-foreign|cxxrtl-foreign"),
    ),
    (
        "python -m fpga_robotics.run --scenario bump_wall.toml --design verilog:bump_stop.v "
        "--ports bump_stop_ports.toml --rerun off"
    ): Plan(
        slow=True,
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data" / name)
                        for name in ("bump_stop.v", "bump_stop_ports.toml", "bump_wall.toml")
                    ),
                    ".",
                ]
            ),
        ),
        duration="keep",
        duration_why="the page quotes the whole run's 120 000 cycles "
        "(12 s at 10 kHz, a twentieth of a second's wall time)",
        out=(PASS, r"\[ok\] max_wall_collisions"),
    ),
    # docs/your_design.md: your own design, by reference ------------------------------------
    "fpga-robotics run --scenario wall_stop.toml --rerun off": Plan(
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data/user_designs" / name)
                        for name in ("wall_stop.py", "wall_stop.toml")
                    ),
                    ".",
                ]
            ),
        ),
        duration="keep",
        duration_why="the page quotes the whole run's stop at the wall "
        "(12 s; about a second of wall time on CXXRTL)",
        out=(
            PASS,
            r"design output distance_mm: last 227, min 218, max 1898",
            r"design output stopped: last 1, min 0, max 1",
        ),
    ),
    "fpga-robotics run --scenario wall_stop.toml --shadow wall_stop_v1.py:WallStop --rerun off": Plan(
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data/user_designs" / name)
                        for name in ("wall_stop.py", "wall_stop.toml")
                    ),
                    ".",
                ]
            ),
            "cp wall_stop.py wall_stop_v1.py",
        ),
        duration="keep",
        duration_why="the page quotes the whole run's 360 frames",
        out=(
            PASS,
            (
                r"shadow wall_stop_v1\.py:WallStop with speed=300, stop_mm=250: identical "
                r"outputs on all 360 frames"
            ),
        ),
    ),
    (
        "fpga-robotics run --scenario wall_stop.toml --shadow wall_stop_v2.py:WallStop "
        "--shadow-param stop_mm=100 --rerun off"
    ): Plan(
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data/user_designs" / name)
                        for name in ("wall_stop.py", "wall_stop.toml")
                    ),
                    ".",
                ]
            ),
            "sed 's/stop_mm: int = 250/stop_mm: int = 100/' wall_stop.py > wall_stop_v2.py",
        ),
        duration="keep",
        duration_why="the page quotes the frame (9.60 s) where the shadow drives on",
        out=(
            PASS,
            re.escape(
                "shadow wall_stop_v2.py:WallStop with speed=300, stop_mm=100: first differs "
                "at frame 288 (9.60 s): motor_left 0 vs 300, motor_right 0 vs 300, stopped 1 vs 0"
            ),
        ),
    ),
    (
        "fpga-robotics mutate --design wall_stop.py:WallStop --mutants 8 --cycles 20000 "
        "--campaign wall_stop_campaign.toml --workers 1"
    ): Plan(
        slow=True,
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data/user_designs" / name)
                        for name in ("wall_stop.py", "wall_stop.toml", "wall_stop_campaign.toml")
                    ),
                    ".",
                ]
            ),
        ),
        out=(
            (
                r"unit judge \(against the unmutated design\): 3 caught, 5 equivalent on "
                r"these inputs: score 37\.5%"
            ),
            (
                r"robot judge \(campaign wall_stop_campaign: 1 of 1 runs pass unmutated\): "
                r"2 of 3 unit-caught mutants caught: score 66\.7%"
            ),
            r"#2 top: stopped\[0\] inverted",
        ),
        files=(
            "runs/mutation/WallStop-n8-s1/mutants.json",
            "runs/mutation/WallStop-n8-s1/mutants_ports.toml",
        ),
    ),
    (
        "fpga-robotics mutate --design verilog:bump_stop.v --ports bump_stop_ports.toml "
        "--mutants 10 --cycles 2000"
    ): Plan(
        slow=True,
        setup=(
            " ".join(
                [
                    "cp",
                    *(
                        str(ROOT / "tests/data" / name)
                        for name in ("bump_stop.v", "bump_stop_ports.toml")
                    ),
                    ".",
                ]
            ),
        ),
        out=(
            (
                r"unit judge \(against the unmutated design\): 8 caught, 2 equivalent on "
                r"these inputs: score 80\.0%"
            ),
        ),
        files=("runs/mutation/bump_stop-n10-s1/mutants.json",),
    ),
    "fpga-robotics formal --design verilog:bump_stop_formal.v": Plan(
        slow=True,
        setup=(f"cp {ROOT / 'tests/data/user_designs/bump_stop_formal.v'} .",),
        out=(
            r"(?m)^bump_stop_formal\.asserts\s+prove\s+20\s+pass\s",
            r"(?m)^bump_stop_formal\.covers\s+cover\s+20\s+pass\s",
            r"(?m)^2 of 2 checks passed",
        ),
    ),
    (
        "fpga-robotics board --design wall_stop.py:WallStop --param clock_hz=50000000 "
        "-o build/wall_stop"
    ): Plan(
        setup=(f"cp {ROOT / 'tests/data/user_designs/wall_stop.py'} .",),
        out=(r"trig: header gpio 7\+ \(site A6\)", r"echo: header gpio 7- \(site B6\)"),
        files=("build/wall_stop/ulx3s_follow_target.v", "build/wall_stop/ulx3s_follow_target.lpf"),
    ),
    (
        "fpga-robotics board --design verilog:bump_stop.v --ports bump_stop_ports.toml "
        "-o build/bump_stop"
    ): Plan(
        setup=(
            f"cp {ROOT / 'tests/data/bump_stop.v'} .",
            f"cp {ROOT / 'tests/data/bump_stop_ports.toml'} .",
        ),
        out=(r"bump_i: header gpio 7\+ \(site A6\)",),
        files=(
            "build/bump_stop/ulx3s_follow_target.v",
            "build/bump_stop/ulx3s_follow_target.lpf",
            "build/bump_stop/fr_design/bump_stop.v",
        ),
    ),
    "fpga-robotics board --design turret_tracker -o build/turret": Plan(
        files=("build/turret/ulx3s_follow_target.v", "build/turret/ulx3s_follow_target.lpf"),
    ),
    "fpga-robotics bench user_verilog": Plan(
        slow=True,
        shorter=(("--seconds", "0.2"), ("--repeats", "1")),
        out=(
            r"(?m)^cxxrtl +[\d.]+ +[\d.]+ +1\.00$",
            r"(?m)^verilator +[\d.]+ +[\d.]+ +[\d.]+$",
        ),
    ),
    "fpga-robotics bench user_verilog --design wall_stop.py:WallStop": Plan(
        slow=True,
        setup=(f"cp {ROOT / 'tests/data/user_designs/wall_stop.py'} .",),
        shorter=(("--seconds", "0.2"), ("--repeats", "1")),
        out=(
            r"wall_stop.py:WallStop in real-clock timing",
            r"(?m)^cxxrtl +[\d.]+ +[\d.]+ +[\d.]+ +[\d.]+$",
        ),
    ),
    "fpga-robotics designs": Plan(
        out=(
            r"follow_target_safe  \(built-in\)",
            r"connectors: ultrasound \(trig=us_trig, echo=us_echo\)",
        )
    ),
    "fpga-robotics designs wall_stop.py:WallStop": Plan(
        setup=(f"cp {ROOT / 'tests/data/user_designs/wall_stop.py'} .",),
        out=(
            r"wall_stop\.py:WallStop  \(Amaranth\)",
            (
                r"connectors: wheels \(motor_left=motor_left, motor_right=motor_right\); "
                r"ultrasound \(trig=trig, echo=echo\)"
            ),
            r"recorded outputs: distance_mm, stopped",
        ),
    ),
    (
        "fpga-robotics run --scenario bump_wall.toml --design verilog:bump_stop_noreset.v --ports "
        "bump_stop_noreset_ports.toml --rerun off"
    ): Plan(
        setup=(
            " ".join(
                [
                    "cp",
                    str(ROOT / "tests/data/bump_wall.toml"),
                    *(
                        str(ROOT / "tests/data/user_designs" / name)
                        for name in ("bump_stop_noreset.v", "bump_stop_noreset_ports.toml")
                    ),
                    ".",
                ]
            ),
        ),
        duration="keep",
        duration_why="the bumper closes after about 8 s of the 12 s",
        out=(PASS, r"design output hit: last 1, min 0, max 1"),
    ),
    "fpga-robotics ports ports.toml": Plan(
        setup=("fpga-robotics ports --example ports.toml",),
        out=(r"ports\.toml: follow_target, outputs found, proximity",),
    ),
    "fpga-robotics ports ports.toml --design verilog:follow_target.v": Plan(
        setup=(
            "fpga-robotics ports --example ports.toml",
            "python -m fpga_robotics.export -o follow_target.v",
        ),
        out=(r"ports\.toml: matches verilog:follow_target\.v \(\d+ ports\)",),
    ),
    "python -m fpga_robotics.mutation --mutants 200": Plan(
        slow=True,
        shorter=(("--mutants", "12"), ("--width", "80"), ("--height", "60")),
        out=(r"unit judge: \d+ caught, \d+ equivalent on these frames: score",),
        files=("runs/mutation/n12-s1/mutants.json", "runs/mutation/n12-s1/mutants.v"),
    ),
    "fpga-robotics mutate --mutants 40 --width 80 --height 60 --out runs/mutation/small": Plan(
        slow=True,
        shorter=(("--mutants", "12"),),
        out=(r"12 mutants of follow_target 80x60",),
        files=("runs/mutation/small/mutants.json",),
    ),
    "fpga-robotics mutate --design wall_stop.py:WallStop --mutants 40 --param clock_hz=100000": Plan(
        slow=True,
        setup=(f"cp {ROOT / 'tests/data/user_designs/wall_stop.py'} .",),
        shorter=(("--mutants", "12"),),
        out=(
            r"12 mutants of WallStop \(seed 1\), 100000 cycles of random inputs",
            (
                r"unit judge \(against the unmutated design\): \d+ caught, \d+ equivalent "
                r"on these inputs: score"
            ),
        ),
        files=("runs/mutation/WallStop-n12-s1/mutants.json",),
    ),
    "python -m fpga_robotics.mutation --mutants 100 --campaign mutation":
    # Four mutants at 80x60 on one worker, the campaign's runs made short: the whole
    # command takes minutes (the page gives its measured time).
    Plan(
        slow=True,
        shorter=(
            ("--mutants", "4"),
            ("--width", "80"),
            ("--height", "60"),
            ("--workers", "1"),
            ("--recordings", "1"),
        ),
        out=(r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\)",),
        files=(
            "runs/mutation/n4-s1/report.html",
            "runs/mutation/n4-s1/robot.jsonl",
            "runs/mutation/n4-s1/mutants.json",
        ),
    ),
    # The robot judge's scaling with workers: the same four mutants at 80x60 as above.
    (
        "python -m fpga_robotics.mutation --mutants 30 --campaign mutation --workers 1 "
        "--recordings 0 --out runs/mutation/scale-w1"
    ): Plan(
        slow=True,
        shorter=(("--mutants", "4"), ("--width", "80"), ("--height", "60")),
        out=(
            (
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\).*"
                r"mutants/min"
            ),
        ),
        files=("runs/mutation/scale-w1/mutants.json",),
    ),
    (
        "python -m fpga_robotics.mutation --mutants 30 --campaign mutation --workers 2 "
        "--recordings 0 --out runs/mutation/scale-w2"
    ): Plan(
        slow=True,
        shorter=(("--mutants", "4"), ("--width", "80"), ("--height", "60")),
        out=(
            (
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\).*"
                r"mutants/min"
            ),
        ),
        files=("runs/mutation/scale-w2/mutants.json",),
    ),
    # Forked against full robot-judge runs: the same four mutants at 80x60 as above.
    (
        "python -m fpga_robotics.mutation --mutants 60 --seed 0 --campaign mutation --workers 2 "
        "--recordings 0 --out runs/mutation/fork"
    ): Plan(
        slow=True,
        shorter=(("--mutants", "4"), ("--width", "80"), ("--height", "60")),
        out=(
            (
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\).*"
                r"mutants/min"
            ),
        ),
        files=("runs/mutation/fork/mutants.json",),
    ),
    (
        "python -m fpga_robotics.mutation --mutants 60 --seed 0 --campaign mutation --workers 2 "
        "--recordings 0 --no-fork --out runs/mutation/no-fork"
    ): Plan(
        slow=True,
        shorter=(("--mutants", "4"), ("--width", "80"), ("--height", "60")),
        out=(
            (
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\).*"
                r"mutants/min"
            ),
        ),
        files=("runs/mutation/no-fork/mutants.json",),
    ),
    # The mutants settled by their fan-out cone, on more seeds and 200 mutants: four mutants
    # at 80x60 each (the page gives the measured counts and the cone step's time).
    **{
        f"python -m fpga_robotics.mutation --mutants {n} --seed {seed} --campaign mutation "
        f"--workers 2 --recordings 0 --out runs/mutation/{out}": Plan(
            slow=True,
            shorter=(("--mutants", "4"), ("--width", "80"), ("--height", "60")),
            out=(
                rf"4 mutants of follow_target 80x60 \(seed {seed}\).*fan-out cones [\d.]+ s",
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\)",
            ),
            files=(f"runs/mutation/{out}/robot.jsonl",),
        )
        for n, seed, out in ((60, 1, "cone-s1"), (60, 2, "cone-s2"), (200, 0, "cone-200"))
    },
    # The robot judge with the envelopes on three seeds: four mutants at 80x60 each (the page
    # gives the measured scores; the whole commands take tens of minutes).
    **{
        f"python -m fpga_robotics.mutation --mutants {n} --campaign mutation --seed {seed} "
        f"--workers {workers}": Plan(
            slow=True,
            shorter=(
                ("--mutants", "4"),
                ("--width", "80"),
                ("--height", "60"),
                ("--recordings", "0"),
            ),
            out=(
                rf"4 mutants of follow_target 80x60 \(seed {seed}\)",
                r"robot judge \(campaign mutation: \d+ of 10 runs pass unmutated\)",
            ),
        )
        for n, seed, workers in ((60, 1, 2), (60, 2, 1), (60, 3, 1))
    },
    # The mutation campaign with the unmutated design: two short runs on the model backend
    # (the page gives the whole campaign's results).
    "python -m fpga_robotics.sweep mutation": Plan(
        shorter=(
            ("--max-runs", "2"),
            ("--backend", "model"),
            ("--duration", "2"),
            ("--set", "checks.mean_distance_max_m=3"),
        ),
        out=(r"2 runs: 2 pass",),
    ),
    "python -m fpga_robotics.sweep mutation --seeds 0-4 --workers 1 --out runs/sweeps/mutation-5": Plan(
        shorter=(
            ("--max-runs", "2"),
            ("--backend", "model"),
            ("--duration", "2"),
            ("--set", "checks.mean_distance_max_m=3"),
        ),
        files=("runs/sweeps/mutation-5/report.html",),
        out=(r"2 runs: 2 pass",),
    ),
    "fpga-robotics bench foreign": Plan(
        slow=True,
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(
            r"verilator \(built-in\) +[\d.]+ ms/frame",
            r"foreign follow_target \(stream\) +[\d.]+ ms/frame +\([\d.]+x the built-in\)",
        ),
    ),
    # Verilog export and the board ------------------------------------------------------------
    "python -m fpga_robotics.export -o build/follow_target.v": Plan(
        files=("build/follow_target.v",), out=(r"160x120, module follow_target",)
    ),
    "python -m fpga_robotics.export -o build/ft320.v --width 320 --height 240 --diff-min 5 "
    "--kp-num 2 --base-dps 0,400,300,200,150,100,-100,-150 "
    "--proximity-thresholds 512,1024,2048,4096,8192,16384,24576": Plan(
        files=("build/ft320.v",), out=(r"320x240, module follow_target",)
    ),
    "python -m fpga_robotics.export --board ulx3s-85f -o build/ulx3s":
    # docs/board.md: the board top, its LPF and the rest of Amaranth's build plan.
    Plan(
        files=tuple(
            f"build/ulx3s/{name}"
            for name in (
                "ulx3s_follow_target.v",
                "ulx3s_follow_target.lpf",
                "ulx3s_follow_target.il",
                "ulx3s_follow_target.ys",
                "build_ulx3s_follow_target.sh",
            )
        )
    ),
    "python -m fpga_robotics.export --board ulx3s-85f -o build/ulx3s --bitstream": Plan(
        slow=True, files=("build/ulx3s/ulx3s_follow_target.bit",), out=(r"(?i)sync.*MHz",)
    ),
    (
        "python -m fpga_robotics.run --design verilog:design_top.v,centroid.v,color_proc.v,"
        "frame_buffer.v,motor_ctrl_spi.v --ports \"$(python -c 'import fpga_robotics, pathlib; "
        'print(pathlib.Path(fpga_robotics.__file__).parent / "designs/port_maps/published_design_top.toml'
        '")\')" --rerun off --shadow published --shadow-backend model'
    ): Plan(
        excused="runs the published RTL, which this project does not ship (third-party "
        "files); the shipped port map is read by test_foreign_verilog.py"
    ),
    "openFPGALoader -b ulx3s build/ulx3s/ulx3s_follow_target.bit": Plan(
        excused="programs a ULX3S over USB: needs the board (and openFPGALoader, which is "
        "not a Python package)"
    ),
    # "includes the slow full build", and without it:
    "python -m pytest -q tests/test_board_*.py": Plan(
        collect=True, out=(r"test_bitstream_build_meets_timing",)
    ),
    'python -m pytest -q tests/test_board_*.py -m "not slow"': Plan(
        collect=True, out=(r"\(\d+ deselected\)",), not_out=(r"test_bitstream_build_meets_timing",)
    ),
    "python -m pytest -q tests/test_hw_color_filter.py tests/test_hw_divider.py "
    "tests/test_hw_tracker.py tests/test_hw_motor.py tests/test_hw_top.py "
    "tests/test_hw_pysim_backend.py tests/test_export.py tests/test_published_frames.py": Plan(
        collect=True, out=(r"\d+ tests collected",)
    ),
    # docs/published.md: the published design as a preset -----------------------------------
    "python -m fpga_robotics.run --set design.preset=published --rerun off": Plan(out=(PASS,)),
    "python -m fpga_robotics.run --shadow published --rerun off": Plan(
        duration="keep",
        duration_why="the page shows this run's last lines, with counts 'of 900': the "
        "whole 30 s of follow_person (a second or two of wall time)",
        out=(
            PASS,
            re.escape(
                "  shadow published: first differs at frame 0 (0.00 s): proximity 4 "
                "vs 3, centroid_leds 24 vs 16, motor_left 147 vs 350, motor_right "
                "153 vs 225"
            ),
            re.escape(
                "  shadow frames that differ: proximity 750, centroid_leds 118, "
                "motor_left 900, motor_right 900 (of 900)"
            ),
        ),
    ),
    "python -m fpga_robotics.export --preset published -o build/published.v": Plan(
        files=("build/published.v",), out=(r"160x120, preset published, module follow_target",)
    ),
    # docs/sensor_designs.md: the sensor designs' exports -------------------------------------
    "python -m fpga_robotics.export --top follow_target_safe -o build/follow_target_safe.v": Plan(
        files=("build/follow_target_safe.v",),
        out=(r"160x120, 50000000 Hz, stop 300 mm, resume 400 mm, module follow_target_safe",),
    ),
    "python -m fpga_robotics.export --top follow_target_safe --stop-mm 250 --resume-mm 350 "
    "-o build/safe250.v": Plan(files=("build/safe250.v",), out=(r"stop 250 mm, resume 350 mm",)),
    "python -m fpga_robotics.export --top follow_line --line-n-sensors 2 -o build/follow_line2.v": Plan(
        files=("build/follow_line2.v",), out=(r"2 sensors, module follow_line",)
    ),
    "python -m fpga_robotics.export --top follow_line --variant line_inverted_polarity "
    "-o build/line_inverted.v": Plan(
        files=("build/line_inverted.v",),
        out=(r"3 sensors, variant line_inverted_polarity, module follow_line",),
    ),
    "python -m fpga_robotics.export --top follow_target_safe --variant us_echo_counter_narrow "
    "-o build/safe_narrow.v": Plan(
        files=("build/safe_narrow.v",),
        out=(r"variant us_echo_counter_narrow, module follow_target_safe",),
    ),
    "python -m pytest -q tests/test_hw_ultrasound.py tests/test_hw_safe_follow.py "
    "tests/test_hw_follow_line.py tests/test_hw_follow_line_track.py "
    "tests/test_export_sensor_designs.py": Plan(collect=True, out=(r"\d+ tests collected",)),
    "python -m fpga_robotics.run --set design.preset=published": Plan(
        viewer=True, files=("runs/follow_person.rrd",), out=(PASS, SAVED_DEFAULT)
    ),
    "python -m fpga_robotics.run --set design.preset=published --rerun off --summary "
    "published.json": Plan(files=("published.json",), out=(PASS,)),
    "python -m fpga_robotics.run --rerun off --summary ours.json": Plan(
        files=("ours.json",), out=(PASS,)
    ),
    "python -m fpga_robotics.run --shadow published --set robot.heading_deg=180 --duration 6 "
    "--rerun off": Plan(
        duration="keep",
        duration_why="the page shows this 6 s run's last lines",
        out=(
            re.escape(
                "  shadow published: first differs at frame 79 (2.63 s): proximity "
                "2 vs 3, motor_left 111 vs 75, motor_right 489 vs 350"
            ),
            re.escape(
                "  shadow frames that differ: proximity 96, centroid_leds 1, "
                "motor_left 101, motor_right 101 (of 180)"
            ),
        ),
    ),
    # Benchmarks ------------------------------------------------------------------------------
    "fpga-robotics bench": Plan(
        slow=True,
        out=tuple(
            rf"(?m)^{b}\s+{s}\s"
            for b in ("model", "cxxrtl", "verilator")
            for s in ("160x120", "320x240", "640x480")
        )
        + (
            r"(?m)^pysim\s+160x120\s",
            r"cxxrtl 160x120: FollowTarget at [\d.]+ of the trivial design's cycle rate",
        ),
    ),
    "fpga-robotics bench design --backends cxxrtl,verilator --resolutions 160x120,640x480 "
    "--frames 30 --min-seconds 2 --published /tmp/published": Plan(
        excused="needs the published FPGA-Robotics RTL in /tmp/published, which is not part "
        "of the project (docs/foreign.md says where it is); "
        "tests/test_backends_bench.py runs the option's checks"
    ),
    "fpga-robotics bench calibrate": Plan(
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(
            r"calibration: published preset, (cxxrtl|verilator|model), 160x120",
            r"(?m)^wall +[\d.]+ +[\d.]+ +[\d.]+$",
        ),
    ),
    "fpga-robotics bench loop --backend cxxrtl --duration 10 --repeats 3": Plan(
        shorter=(("--duration", "1"), ("--repeats", "1")),
        out=(
            r"closed loop 160x120: follow_person, cxxrtl",
            r"closed loop 640x480: follow_person, cxxrtl",
            r"the loop against the design alone, CPU time: whole [\d.]+x",
            r"target 640x480: [\d.]+x real time by CPU time",
        ),
    ),
    "fpga-robotics bench loop --backend cxxrtl --resolutions 160x120 --profile 12": Plan(
        shorter=(("--duration", "1"), ("--repeats", "1")),
        out=(r"cProfile of one run, 12 functions of largest own time", r"tottime"),
    ),
    "fpga-robotics bench fork": Plan(
        shorter=(("--duration", "3"), ("--values", "5,20")),
        out=(
            r"every forked result equals its full run",
            r"full runs / forked \(reference included\)\s+[\d.]+x",
        ),
    ),
    "fpga-robotics bench mutant_replay": Plan(
        slow=True,
        shorter=(("--duration", "1"), ("--mutants", "4"), ("--repeats", "1")),
        out=(
            r"the netlist alone on the recorded frames\s+[\d.]+ ms",
            r"the same with its watch output watched\s+[\d.]+ ms",
            r"forking gains at most [\d.]+x",
        ),
    ),
    "fpga-robotics bench camera": Plan(
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(r"(?m)^\s*160x120\s+[\d.]+", r"(?m)^\s*640x480\s+[\d.]+"),
    ),
    # docs/turret.md -----------------------------------------------------------------------------
    "fpga-robotics bench cameras --repeats 5": Plan(
        shorter=(("--seconds", "0.5"), ("--repeats", "1")),
        out=(
            r"(?m)^ +one camera: +[\d.]+ \([\d.]+-[\d.]+\) ms/frame, CPU [\d.]+",
            r"(?m)^ +two cameras: +[\d.]+ \([\d.]+-[\d.]+\) ms/frame, CPU [\d.]+",
            r"(?m)^two cameras / one camera: [\d.]+ \(CPU [\d.]+\)$",
        ),
    ),
    # docs/pins.md -------------------------------------------------------------------------------
    "fpga-robotics bench pins": Plan(
        slow=True,
        shorter=(("--seconds", "0.02"), ("--pysim-seconds", "0.0002"), ("--repeats", "1")),
        out=(
            (
                r"(?m)^cxxrtl +pins: +[\d.]+ Mcycles/s \(1,000,000 cycles, 1 frames, \d+ stops "
                r"a run\); frame path [\d.]+ Mcycles/s, pins/frame [\d.]+ \(median of the runs' "
                r"ratios\)$"
            ),
            r"(?m)^verilator +pins: +[\d.]+ Mcycles/s",
            r"(?m)^pysim +pins: +[\d.]+ Mcycles/s \(10,000 cycles",
        ),
    ),
    # docs/camera.md: the sensor model ---------------------------------------------------------
    "fpga-robotics bench camera --sensor --sizes 160x120,640x480": Plan(
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(r"(?m)^\s*160x120(\s+[\d.]+){9}$", r"(?m)^\s*640x480(\s+[\d.]+){9}$"),
    ),
    "fpga-robotics bench camera --stage-images docs/images": Plan(
        files=tuple(f"docs/images/sensor_stage_{i}.png" for i in range(7)),
        out=(r"sensor_stage_6\.png: RGB444",),
    ),
    "python -m fpga_robotics.run --scenario divider --backend cxxrtl --set camera.sensor=ov7670": Plan(
        duration="keep", duration_why=_SENSOR_WHY, out=(PASS,)
    ),
    "python -m fpga_robotics.run --scenario divider --backend cxxrtl --rerun off "
    "--set camera.sensor=ov7670": Plan(duration="keep", duration_why=_SENSOR_WHY, out=(PASS,)),
    "python -m fpga_robotics.run --scenario lighting --backend cxxrtl --rerun off "
    "--set camera.sensor=ov7670": Plan(duration="keep", duration_why=_SENSOR_WHY, out=(PASS,)),
    "python -m fpga_robotics.run --scenario divider --backend cxxrtl --rerun off "
    "--set design.diff_min=5 --set camera.sensor=ov7670": Plan(
        duration="keep",
        duration_why=_SENSOR_WHY,
        out=(PASS, r"target: first found at 0\.00 s, in view 100%, found 100%"),
    ),
    "python -m fpga_robotics.run --scenario lighting --backend cxxrtl --rerun off "
    "--set camera.sensor=ov7670 "
    "--set 'lighting.keyframes=[[0,0.6,0.4],[8,0.28,0.2],[18,0.28,0.2],[24,0.8,0.5]]'": Plan(
        duration="keep",
        duration_why=_SENSOR_WHY,
        out=(PASS, r"target: first found at 0\.00 s, in view 100%, found 100%"),
    ),
    # docs/ros.md: ROS 2 bags and Foxglove -------------------------------------------------------
    "python -m fpga_robotics.run --bag runs/follow_bag": Plan(
        files=("runs/follow_bag/metadata.yaml", "runs/follow_bag/follow_bag.mcap"),
        out=(PASS, r"ROS 2 bag \(30 frames\) written to runs/follow_bag"),
    ),
    "python -m fpga_robotics.run --live foxglove": Plan(
        out=(
            PASS,
            r"Foxglove live: open a WebSocket connection to ws://127\.0\.0\.1:8765",
            r"foxglove_layout\.json",
        )
    ),
    "python -m fpga_robotics.run --interactive": Plan(
        excused="reads keys from a terminal, and this test gives commands none; "
        "tests/test_ros_interactive.py drives it through a pseudo-terminal"
    ),
    "python -m fpga_robotics.run --interactive --summary steered.json": Plan(
        excused="reads keys from a terminal, and this test gives commands none; "
        "tests/test_ros_interactive.py drives it through a pseudo-terminal "
        "(the replay below gets its steered.json from a set-up)"
    ),
    "python -m fpga_robotics.run --replay-inputs steered.json --bag runs/replayed":
    # Inputs as a steered run records them: the target stopped for ten frames.
    Plan(
        setup=(
            (
                """echo '{"inputs": [{"frame": 12, "kind": "target_velocity", """
                """"value": [0, 0]}, {"frame": 22, "kind": "target_velocity", """
                """"value": null}]}' > steered.json"""
            ),
        ),
        files=("runs/replayed/metadata.yaml",),
        out=(PASS, r"ROS 2 bag \(30 frames\) written to runs/replayed"),
    ),
    "python -m fpga_robotics.run --source bag:robot_bag:/camera/image_raw --bag runs/robot_outputs":
    # A run's own bag stands in for a real robot's.
    Plan(
        setup=(("python -m fpga_robotics.run --duration 1 --rerun off --quiet --bag robot_bag"),),
        files=("runs/robot_outputs/metadata.yaml",),
        out=(
            r"source bag:robot_bag:/camera/image_raw \(bag\)",
            r"target found in 30 frames",
            r"ROS 2 bag \(30 frames\) written to runs/robot_outputs",
        ),
    ),
    "fpga-robotics bench ros": Plan(
        shorter=(("--frames", "2"), ("--repeats", "1")),
        out=(
            r"bag  \(--bag\): log_frame median [\d.]+ ms",
            (
                r"live \(--live foxglove, one client\): log_frame median [\d.]+ ms; "
                r"client received 26/26 messages"
            ),
        ),
    ),
    # docs/render3d.md: the 3D renderer ----------------------------------------------------
    "python -m fpga_robotics.run --scenario follow_person --set camera.renderer=mujoco --rerun off": Plan(
        out=(PASS,)
    ),
    "python -m pytest -q tests/test_render3d_agreement.py tests/test_render3d_people.py": Plan(
        collect=True, out=(r"\d+ tests collected",)
    ),
    "fpga-robotics bench render3d --figures docs/figures": Plan(
        files=("docs/figures/divider_3d.png", "docs/figures/lighting_3d.png"),
        out=(r"wrote docs/figures/divider_3d\.png",),
    ),
    "python -m fpga_robotics.run --scenario divider_3d --rerun off": Plan(
        duration="keep",
        duration_why="the page says the scenario passes: over its own 25 s; a run under "
        "15 s fails its mean-distance check, as divider's does",
        out=(PASS,),
    ),
    "python -m fpga_robotics.run --scenario divider_3d --set design.diff_min=6 --rerun off": Plan(
        duration="10",
        duration_why="the centroid is on the lit wood well within 10 s (the person leaves "
        "the view later, failing target_in_view_min_fraction over 25 s)",
        out=(r"\[FAIL\] max_off_target_fraction",),
    ),
    "python -m fpga_robotics.run --scenario lighting_3d --rerun off": Plan(
        duration="keep",
        duration_why="the page says the scenario passes, dusk and the light's return "
        "included (30 s)",
        out=(PASS,),
    ),
    "python -m fpga_robotics.run --scenario lighting_3d --set design.diff_min=6 --rerun off": Plan(
        duration="16",
        duration_why="dusk falls by 8 s; by 16 s the person has been lost long enough to "
        "fail found_min_fraction",
        out=(r"\[FAIL\] found_min_fraction",),
    ),
    "fpga-robotics bench render3d": Plan(
        shorter=(
            ("--frames", "2"),
            ("--repeats", "1"),
            ("--seconds", "0.5"),
            ("--backend", "model"),
        ),
        out=(
            r"(?m)^\s*raster\s+[\d.]+\s+[\d.]+\s+[\d.]+",
            r"(?m)^\s*3d, shadows 256\s+[\d.]+ ms/frame\s+[\d.]+x real time",
        ),
    ),
    "fpga-robotics bench pysim --frames 7": Plan(
        shorter=(("--frames", "2"),),
        out=(r"every frame equal to the golden model", r"median [\d.]+ s wall"),
    ),
    # docs/lidar.md: the LIDAR and the corridor follower -----------------------------------------
    "fpga-robotics export --design corridor_follow -o corridor_follow.v": Plan(
        files=("corridor_follow.v",), out=(r"keep 420 mm, stop 300 mm, module corridor_follow\)",)
    ),
    "fpga-robotics export --design corridor_follow_uart -o corridor_follow_uart.v": Plan(
        files=("corridor_follow_uart.v",),
        out=(r"115200 baud at 50000000 Hz, module corridor_follow_uart\)",),
    ),
    "fpga-robotics export --top corridor_follow --variant lidar_bearing_mirrored -o "
    "corridor_mirrored.v": Plan(
        files=("corridor_mirrored.v",),
        out=(r"variant lidar_bearing_mirrored, module corridor_follow",),
    ),
    "fpga-robotics run --scenario corridor": Plan(
        out=(PASS, r"design output nearest_mm: last \d+", r"collisions: person 0, wall 0")
    ),
    "fpga-robotics run --scenario corridor_uart": Plan(
        out=(PASS, r"design output framing_errors: last 0", r"design output resyncs: last 0")
    ),
    "fpga-robotics run --scenario corridor --duration 8 --set "
    "design.variant=lidar_bearing_mirrored": Plan(
        slow=True,
        duration="keep",
        duration_why="the page says the variant fails within these 8 s",
        out=(r"\[FAIL\] max_wall_collisions", r"(?m)^verdict: FAIL$"),
    ),
    "fpga-robotics run --scenario corridor --bag corridor_bag": Plan(
        files=("corridor_bag/metadata.yaml", "corridor_bag/corridor_bag.mcap"),
        out=(PASS, r"ROS 2 bag \(30 frames\) written to corridor_bag"),
    ),
    "fpga-robotics bench lidar": Plan(
        slow=True,
        shorter=(("--duration", "0.5"), ("--repeats", "1")),
        out=(
            r"revolution / frame: [\d.]+ \(median of the turns\)",
            r"(?m)^  UART   binding, real clock at 50 MHz: [\d.]+ \([\d.]+-[\d.]+\) Mcycles",
        ),
    ),
}


def _is_design_bench(cmd):
    """``bench`` of the design backends (the default benchmark), not another subject's."""
    words = cmd.split()
    subject = words[2] if words[0] == "fpga-robotics" and len(words) > 2 else ""
    return not subject or subject.startswith("-") or subject == "design"


def _is(cmd, module, sub):
    return cmd.startswith(
        (f"python -m fpga_robotics.{module} ", f"fpga-robotics {sub} ")
    ) or cmd in (f"python -m fpga_robotics.{module}", f"fpga-robotics {sub}")


def _set_option(args, name, value):
    """``args`` with ``name value`` replacing the option's value, or added."""
    args = list(args)
    for i, a in enumerate(args):
        if a == name:
            args[i + 1] = value
            return args
        if a.startswith(name + "="):
            args[i] = f"{name}={value}"
            return args
    return [*args, name, value]


def effective(doc_text, plan):
    """The command line this test runs for a documented command (a string for ``bash -c``)."""
    text = plan.part or doc_text
    text = collapse(text)
    args = shlex.split(text)
    if _is(text, "run", "run") and "--list-scenarios" not in args:
        if "--source" not in args:
            if plan.duration is None:
                args = _set_option(args, "--duration", "1")
            elif plan.duration != "keep":
                args = _set_option(args, "--duration", plan.duration)
        if not plan.viewer and not any(a == "--rerun" or a.startswith("--rerun=") for a in args):
            args += ["--rerun", "off"]
        if "--quiet" not in args:
            args.append("--quiet")
    elif _is(text, "bench", "bench") and _is_design_bench(text):
        args = _set_option(_set_option(args, "--frames", "2"), "--min-seconds", "0")
    if plan.collect:
        args += ["--collect-only", "-p", "no:cacheprovider"]
    for name, value in plan.shorter:
        args = _set_option(args, name, value)
    # Keep the page's glob (tests/test_board_*.py) for the shell to expand.
    return " ".join(a if re.fullmatch(r"[\w@%+=:,./*-]+", a) else shlex.quote(a) for a in args)


# --- Running ----------------------------------------------------------------------------------


def command_env():
    """The environment of a documented command: this interpreter's scripts first on PATH,
    and no display (so ``--rerun auto`` saves a file, as on CI)."""
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    for name in ("DISPLAY", "WAYLAND_DISPLAY"):
        env.pop(name, None)
    return env


@dataclass
class Ran:
    command: str
    returncode: int
    output: str
    stdout: str = ""


def run_shell(command, cwd, timeout=TIMEOUT):
    try:
        proc = subprocess.run(
            ["bash", "-c", command],
            check=False,
            cwd=cwd,
            env=command_env(),
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"{command!r} did not end within {timeout} s:\n{exc.stdout}\n{exc.stderr}")
    return Ran(command, proc.returncode, proc.stdout + proc.stderr, proc.stdout)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http_status(url, timeout=2.0):
    try:
        with urllib.request.urlopen(url, timeout=timeout) as response:
            return response.status
    except OSError:
        return None


def run_server(command, cwd, *, within=60.0):
    """Start a server that runs until Ctrl-C on free loopback ports, wait (bounded) until its
    web page answers HTTP 200 on 127.0.0.1, then stop it as Ctrl-C does (SIGINT to its
    process group). Returns a ``Ran`` whose output is what it printed and whose return code
    is 0 when it served the page."""
    web, grpc = free_port(), free_port()
    while grpc == web:
        grpc = free_port()
    command = f"{command} --web-viewer-port {web} --port {grpc}"
    log = Path(cwd) / "server.log"
    start = time.monotonic()
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            ["bash", "-c", command],
            cwd=cwd,
            env=command_env(),
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            **FROM_A_TERMINAL,
        )
    try:
        status = None
        while time.monotonic() - start < within and proc.poll() is None:
            status = http_status(f"http://127.0.0.1:{web}/")
            if status == 200:
                break
            time.sleep(0.5)
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C
        try:
            proc.wait(timeout=15)
            stopped = True
        except subprocess.TimeoutExpired:
            stopped = False
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
    printed = log.read_text(errors="replace")
    ran = Ran(command, 0 if status == 200 else 1, printed, printed)
    assert status == 200, (
        f"{command!r}: no HTTP 200 on 127.0.0.1:{web} within {within} s:\n{ran.output}"
    )
    assert stopped, f"{command!r} did not stop within 15 s of Ctrl-C"
    # The page says it prints the address to open, with the gRPC port in the URL.
    assert (
        f"http://127.0.0.1:{web}?url=rerun%2Bhttp%3A%2F%2Flocalhost%3A{grpc}%2Fproxy" in ran.output
    ), ran.output
    return ran


def check(doc, plan, ran, folder):
    where = f"{doc.page}:{doc.line}: {ran.command!r}"
    assert ran.returncode == doc.expected_rc, (
        f"{where}: exit code {ran.returncode}, the page says "
        f"{doc.expected_rc}{' (# FAIL)' if doc.expected_rc else ''}:\n{ran.output[-3000:]}"
    )
    for name in plan.files:
        assert (folder / name).is_file(), f"{where}: wrote no {name}:\n{ran.output[-2000:]}"
    for pattern in plan.out:
        pattern = pattern.replace("{fastest}", _fastest())
        assert re.search(pattern, ran.output), (
            f"{where}: no match for {pattern!r} in the output:\n{ran.output[-3000:]}"
        )
    for pattern in plan.not_out:
        assert not re.search(pattern, ran.output), f"{where}: {pattern!r} in the output"
    if plan.last_line:
        last = (ran.stdout.strip().splitlines() or [""])[-1]
        assert re.search(plan.last_line, last), f"{where}: last line {last!r}"
    if plan.summary:
        summary = json.loads((folder / "s.json").read_text())
        for key, value in plan.summary:
            assert key in summary, f"{where}: s.json has no {key!r}"
            if value is not ...:
                assert summary[key] == value, f"{where}: s.json {key} = {summary[key]!r}"


def _fastest():
    from fpga_robotics.sim.backends import fastest_backend_name

    return fastest_backend_name()


def run_documented(doc, plan, folder):
    """Run one documented command in ``folder`` as its plan says, and check it."""
    for setup in plan.setup:
        ran = run_shell(setup, folder)
        assert ran.returncode == 0, f"set-up {setup!r} failed:\n{ran.output[-3000:]}"
    command = effective(doc.text, plan)
    if plan.serve:
        ran = run_server(command, folder)
    else:
        ran = run_shell(command, ROOT if plan.collect else folder)
    check(doc, plan, ran, folder)
    return ran


# --- The extraction itself ------------------------------------------------------------------------

SAMPLE = """\
Text.

```sh
python -m fpga_robotics.run --scenario divider --rerun off   # FAIL
python -m fpga_robotics.export -o a.v \\
    --width 320 --height 240     # wide
fpga-robotics run --set 'x=a # b' --quiet
```

```
python -m fpga_robotics.bench [--frames 30]
                              [--json b.json]
python -m fpga_robotics.export -o a.v ...
pip install something
fpga-robotics run --set 'lighting.keyframes=[[0,0.6,0.4]]' --quiet
```

```text
python -m fpga_robotics.bench [--frames 30]
```

```python
print(1)
```

```toml
key = 1
```
"""


def test_extraction_of_a_sample_page(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "page.md").write_text(SAMPLE)
    commands, snippets, strays = scan_page("page.md")
    assert [(c.line, c.text, c.comment, c.expected_rc) for c in commands] == [
        (4, "python -m fpga_robotics.run --scenario divider --rerun off", "FAIL", 1),
        (5, "python -m fpga_robotics.export -o a.v --width 320 --height 240", "wide", 0),
        (7, "fpga-robotics run --set 'x=a # b' --quiet", "", 0),
        (15, "fpga-robotics run --set 'lighting.keyframes=[[0,0.6,0.4]]' --quiet", "", 0),
    ]
    assert strays == ["page.md:14: pip install something"]
    assert synopsis_lines("page.md") == [
        "page.md:11: python -m fpga_robotics.bench [--frames 30]",
        "page.md:12: [--json b.json]",
        "page.md:13: python -m fpga_robotics.export -o a.v ...",
    ]
    assert [snippet_key(b) for b in snippets] == [("page.md", "print(1)")]


def test_shortening_rules():
    plan = Plan()
    assert (
        effective("python -m fpga_robotics.run --duration 5 --save-video c.mp4", plan)
        == "python -m fpga_robotics.run --duration 1 --save-video c.mp4 --rerun off --quiet"
    )
    assert (
        effective("fpga-robotics run --source c.mp4", plan)
        == "fpga-robotics run --source c.mp4 --rerun off --quiet"
    )
    assert (
        effective("python -m fpga_robotics.run --scenario x", Plan(viewer=True))
        == "python -m fpga_robotics.run --scenario x --duration 1 --quiet"
    )
    assert (
        effective("python -m fpga_robotics.run --duration 20 --quiet", Plan(duration="keep"))
        == "python -m fpga_robotics.run --duration 20 --quiet --rerun off"
    )
    assert (
        effective("python -m fpga_robotics.bench --frames 30 --json b.json", plan)
        == "python -m fpga_robotics.bench --frames 2 --json b.json --min-seconds 0"
    )
    assert (
        effective("fpga-robotics bench design --json b.json", plan)
        == "fpga-robotics bench design --json b.json --frames 2 --min-seconds 0"
    )
    assert (
        effective("fpga-robotics bench loop --duration 10", plan)
        == "fpga-robotics bench loop --duration 10"
    )
    assert effective("python -m fpga_robotics.run --shadow 'a=1;b=2'", plan).startswith(
        "python -m fpga_robotics.run --shadow 'a=1;b=2' --duration 1"
    )
    assert (
        effective('python -m pytest -q tests/test_board_*.py -m "not slow"', Plan(collect=True))
        == "python -m pytest -q tests/test_board_*.py -m 'not slow' --collect-only -p no:cacheprovider"
    )


# --- Every command is run or excused --------------------------------------------------------------


def test_every_documented_command_is_classified():
    problems = []
    for page in PAGES:
        commands, _, strays = scan_page(page)
        problems += [
            f"{s}  (a command line the extractor does not take: make it one of "
            f"{COMMAND_PREFIXES} or move it out of the code block)"
            for s in strays
        ]
        problems += [
            f"{c.page}:{c.line}: {c.text}  (not in PLANS: run it or excuse it)"
            for c in commands
            if c.text not in PLANS
        ]
    used = {c.text for page in PAGES for c in scan_page(page)[0]}
    problems += [f"PLANS entry no page has any more: {key}" for key in PLANS if key not in used]
    problems += [
        f"PLANS[{key!r}].part is not a part of the command"
        for key, plan in PLANS.items()
        if plan.part and plan.part not in key.split(" && ")
    ]
    blocks = {snippet_key(b) for b in python_blocks()}
    problems += [
        f"{p}: python block starting {first!r} has no entry in SNIPPETS"
        for p, first in sorted(blocks - set(SNIPPETS))
    ]
    problems += [
        f"SNIPPETS entry no page has any more: {key}" for key in SNIPPETS if key not in blocks
    ]
    assert not problems, "\n".join(problems)


def test_shell_blocks_hold_no_synopsis():
    """A shell block is run line by line: a usage synopsis there is not a command."""
    found = [line for page in PAGES for line in synopsis_lines(page)]
    assert not found, "usage synopses in shell blocks (move them into a ```text block):\n" + (
        "\n".join(found)
    )


def test_ci_runs_the_readme_test_command():
    """README: ``.ci/run`` does exactly the README's test command in a fresh clone, and the
    linter's two checks."""
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    for step in (
        "python3 -m venv .venv",
        ". .venv/bin/activate",
        'python -m pip install -q -e ".[dev,board]"',
        "python -m pytest -q -n auto",
        "ruff check .",
        "ruff format --check .",
    ):
        assert step in ci, f".ci/run does not do {step!r}"


def _block_id(item):
    page, line, _ = item
    return f"{page}:{line}"


@pytest.mark.parametrize("block", command_blocks(), ids=_block_id)
def test_documented_commands(block, tmp_path):
    """The commands of one code block, in order, in one fresh folder."""
    _, _, commands = block
    ran_any = False
    for doc in commands:
        plan = PLANS.get(doc.text)
        if plan is None:
            pytest.fail(f"{doc.page}:{doc.line}: {doc.text}: not in PLANS")
        if plan.excused or plan.slow:
            continue
        run_documented(doc, plan, tmp_path)
        ran_any = True
    if not ran_any:
        pytest.skip(
            "every command of this block is excused or slow: "
            + "; ".join(PLANS[d.text].excused or "slow" for d in commands)
        )


def _slow_commands():
    """Each slow command once (the same build is documented on two pages)."""
    seen = {}
    for page in PAGES:
        for d in scan_page(page)[0]:
            if d.text in PLANS and PLANS[d.text].slow:
                seen.setdefault(d.text, d)
    return [pytest.param(d, id=f"{d.page}:{d.line}") for d in seen.values()]


@pytest.mark.slow
@pytest.mark.parametrize("doc", _slow_commands())
def test_documented_slow_command(doc, tmp_path):
    """Verilator builds or place and route (about 40 s, more on a cold YoWASP cache): the
    page's full command."""
    run_documented(doc, PLANS[doc.text], tmp_path)


# --- Python blocks ----------------------------------------------------------------------------


class _ShowExpressions(ast.NodeTransformer):
    """Every bare expression statement ``e`` becomes ``_shown.append(e)``, so that what a
    snippet shows (``result.found, result.proximity``) can be checked."""

    def visit_Expr(self, node):
        call = ast.Call(
            func=ast.Attribute(value=ast.Name("_shown", ast.Load()), attr="append", ctx=ast.Load()),
            args=[node.value],
            keywords=[],
        )
        return ast.copy_location(ast.Expr(call), node)


def exec_snippet(block, namespace):
    """Execute a Python block in ``namespace``; returns the values of its bare expressions."""
    # A block inside a list item is indented as a whole.
    source = textwrap.dedent("\n".join(text for _, text in block.lines))
    tree = _ShowExpressions().visit(ast.parse(source))
    ast.fix_missing_locations(tree)
    shown = []
    namespace["_shown"] = shown
    exec(compile(tree, f"{block.page}:{block.line}", "exec"), namespace)  # noqa: S102
    return shown


def _model_result(frame, params, **kwargs):
    from fpga_robotics.sim.backends import get_backend

    with get_backend("model", params, **kwargs) as model:
        return model.process_frame(frame, "red")


def snippet_readme_backends(tmp_path, capsys):
    """README: the frame API on Verilator; what it shows equals the golden model's result."""
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.camera.synthetic import blob_frame

    frame = blob_frame(160, 120, "red", rng=1)
    ns = {"rgb888_image": frame}
    shown = yield ns
    expected = _model_result(frame, FollowTargetParams(), line_blank=0, frame_blank=0)
    filtered, found, proximity, centroid_x, motor_left = shown[-1]
    assert found is True or found == 1
    assert filtered.shape == (120, 160) and filtered.dtype == np.uint16
    assert np.array_equal(filtered, expected.filtered)
    assert (found, proximity, centroid_x, motor_left) == (
        expected.found,
        expected.proximity,
        expected.centroid_x,
        expected.motor_left,
    )
    assert ns["result"] == expected  # cycles included


def snippet_backends_api(tmp_path, capsys):
    """docs/backends.md: the fastest backend at 320x240 with blanking equals the model."""
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.camera.synthetic import blob_frame

    frame = blob_frame(320, 240, "red", rng=2)
    ns = {"rgb_frame": frame}
    yield ns
    expected = _model_result(
        frame, FollowTargetParams(width=320, height=240), line_blank=4, frame_blank=100
    )
    assert ns["result"].found
    assert ns["result"] == expected


def snippet_backends_waveform(tmp_path, capsys):
    """docs/backends.md: a waveform of frames 10..12, renamed into place when frame 12 is done.
    The snippet continues the page's first block (its imports) and assumes ``params`` and an
    existing ``out/`` (a missing directory is an error, as the page says)."""
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.backends import WaveformRequest, get_backend
    from fpga_robotics.sim.camera.synthetic import blob_frame

    (tmp_path / "out").mkdir()
    ns = {
        "get_backend": get_backend,
        "WaveformRequest": WaveformRequest,
        "params": FollowTargetParams(),
    }
    shown = yield ns
    design = shown[-1]
    try:
        frame = blob_frame(160, 120, "red", rng=3)
        for _ in range(12):  # frames 0..11
            design.process_frame(frame, "red")
        assert not (tmp_path / "out" / "run.fst").exists()
        design.process_frame(frame, "red")  # frame 12, the last requested
        fst = tmp_path / "out" / "run.fst"
        assert fst.is_file() and fst.stat().st_size > 0
    finally:
        design.close()


def snippet_camera(tmp_path, capsys):
    """docs/camera.md: the renderer on a real scene and camera pose; the cached ``render`` gives
    the same image as the renderer without noise."""
    from fpga_robotics.scenario.load import load_scenario
    from fpga_robotics.sim.camera.raster import CameraRenderer
    from fpga_robotics.sim.world import World

    world = World.from_config(load_scenario("follow_person").world, 0)
    scene, pose = world.scene(), world.camera_pose()
    ns = {"np": np, "scene": scene, "pose": pose, "seed": 0}
    yield ns
    img = ns["img"]
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    plain = CameraRenderer(160, 120, hfov=1.047).render(scene, pose)
    assert np.array_equal(img, plain)
    assert np.array_equal(ns["renderer"].render(scene, pose), plain)


def snippet_running(tmp_path, capsys):
    """docs/running.md: a run from Python (model backend, the snippet's 10 s: 300 frames in
    about a second)."""
    ns = {}
    shown = yield ns
    (verdict, mean_distance), (x, found), events = shown
    assert verdict in ("pass", "fail") and ns["result"].passed == (verdict == "pass")
    assert isinstance(mean_distance, float) and mean_distance > 0
    assert isinstance(x, np.ndarray) and isinstance(found, np.ndarray)
    assert len(x) == len(found) == 300  # one value per frame: 10 s at 30 frames/s
    assert isinstance(events, list)
    for frame, time_s, text in events:
        assert isinstance(frame, int) and isinstance(time_s, float) and isinstance(text, str)


def snippet_viewer(tmp_path, capsys):
    """docs/viewer.md: a recorder fed a world's map and a run's frame records; the file gets
    its real name and the last notice says how to open it."""
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.scenario.load import load_scenario
    from fpga_robotics.sim.world import World

    scenario = load_scenario("follow_person", ["sim.duration=1"])
    records = []
    run_scenario(scenario, backend="model", on_frame=records.append)
    assert len(records) == 30
    ns = {"world": World.from_config(scenario.world, scenario.seed), "records": records}
    yield ns
    printed = capsys.readouterr().out
    assert (tmp_path / "run.rrd").is_file()
    assert not (tmp_path / "runs").exists()  # save:PATH writes exactly PATH
    assert re.search(r"saved 30 frames .*open it with: rerun run\.rrd", printed), printed

    from fpga_robotics.viz.readback import read_rrd

    assert read_rrd(str(tmp_path / "run.rrd"))  # a recording rerun can read


def snippet_published_scenarios(tmp_path, capsys):
    """docs/published.md: the preset passes every shipped scenario, five ways (25 runs)."""
    yield {}
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 25
    assert all(line.split()[-1] == "pass" for line in lines), lines


def snippet_published_driving(tmp_path, capsys):
    """docs/published.md: the table of how each design drives on follow_person."""
    yield {}
    out = capsys.readouterr().out
    assert re.search(
        r"(?m)^ours +mean 3\.05 m, min 1\.73 m, path 2\.8 m, steering reversals "
        r"10, turn-rate sign changes 1, rms turn rate 0\.06 rad/s, frames backing "
        r"0$",
        out,
    ), out
    assert re.search(
        r"(?m)^published mean 2\.09 m, min 1\.27 m, path 5\.0 m, steering "
        r"reversals 276, turn-rate sign changes 132, rms turn rate 0\.26 rad/s, "
        r"frames backing 80$",
        out,
    ), out


def snippet_published_lost(tmp_path, capsys):
    """docs/published.md: on losing the person the preset speeds up, ours holds."""
    yield {}
    out = capsys.readouterr().out
    # The page rounds the re-acquisition times to 1.87 s and 2.03 s.
    assert re.search(r"(?m)^ours lost at frame 115 found again after \[1\.866\d*\] s$", out), out
    assert re.search(r"(?m)^published lost at frame 113 found again after \[2\.033\d*\] s$", out), (
        out
    )
    assert re.search(r"(?m)^ +115 False 208 512$", out), out
    assert re.search(r"(?m)^ +113 False 325 600$", out), out


def snippet_published_first_frame(tmp_path, capsys):
    """docs/published.md: the first frame's counts, levels and LED codes in both designs."""
    yield {}
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "column 79: 71"
    ours, published = lines[1].split(), lines[2].split()
    assert ours[0] == published[0] == "1696"
    assert (ours[-2], ours[-1]) == ("4", "00011000")  # level 4, LEDs 3 and 4
    assert (published[-2], published[-1]) == ("3", "00010000")  # level 3, LED 4


def snippet_pins(tmp_path, capsys):
    """docs/pins.md: a frame streamed in real-clock time on a pin backend; frame_done comes
    result_latency edges after the last pixel, the outputs are the golden model's."""
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.camera.synthetic import blob_frame
    from fpga_robotics.sim.pins import Stop, real_clock_timing

    frame = blob_frame(160, 120, "red", rng=1)
    shown = yield {"rgb888_image": frame}
    stop, found, centroid_x = shown[-1]
    params = FollowTargetParams()
    last = real_clock_timing(160, 120, 30, 50e6, 1).last_edge(160, 120)
    assert (
        stop
        == Stop(last + params.result_latency, "frame_done", 1)
        == Stop(1559887, "frame_done", 1)
    )
    expected = _model_result(frame, params)
    assert (found, centroid_x) == (int(expected.found), expected.centroid_x)
    assert found == 1


#: Python blocks, by (page, first line): a generator that yields the namespace the snippet
#: assumes, is sent the values of its bare expressions, and checks them.
def snippet_connectors_own_design(tmp_path, capsys):
    """docs/connectors.md: a design of one's own with the bumper stops short of the wall."""
    from fpga_robotics.designs.builtin import TOPS

    shown = yield {}
    try:
        verdict, pressed, x = shown[-1]
        assert verdict == "pass" and pressed == 1
        # Pressed at 3 cm, minus the braking distance (300 DPS at 1500 DPS/s on 66.5 mm
        # wheels: v^2 / 2a = 17.4 mm): about 1.26 cm short of the wall's 1.89 m.
        v = 300 / 360 * np.pi * 0.0665
        braking = v * v / (2 * 1500 / 360 * np.pi * 0.0665)
        assert 2.0 - 0.11 - 0.03 <= x <= 2.0 - 0.11 - 0.03 + braking + 0.005
        assert str(x).startswith("1.87")
    finally:
        TOPS.pop("bump_stop", None)


def snippet_your_design(tmp_path, capsys):
    """docs/your_design.md: the design file, word for word the one the tests run
    (tests/data/user_designs/wall_stop.py); defining it builds nothing."""
    namespace = {"__name__": "wall_stop"}
    shown = yield namespace
    assert all(isinstance(text, str) for text in shown)  # only its docstrings
    from fpga_robotics.designs.reference import component_ports

    component = namespace["WallStop"](stop_mm=100)
    assert component_ports(component)["distance_mm"] == ("out", 16)


SNIPPETS = {
    (
        "docs/your_design.md",
        (
            '"""A design of one\'s own with pin sensors and no camera: drives '
            "straight on at ``speed`` DPS"
        ),
    ): snippet_your_design,
    (
        "docs/connectors.md",
        "from amaranth import Module, Mux, Signal, signed",
    ): snippet_connectors_own_design,
    (
        "docs/pins.md",
        (
            "from fpga_robotics.sim.pins import follow_target_source, get_pin_backend, "
            "real_clock_timing"
        ),
    ): snippet_pins,
    (
        "README.md",
        "from fpga_robotics.hw.params import FollowTargetParams",
    ): snippet_readme_backends,
    (
        "docs/backends.md",
        "from fpga_robotics.hw.params import FollowTargetParams",
    ): snippet_backends_api,
    (
        "docs/backends.md",
        (
            'get_backend("verilator", params, waveform=WaveformRequest('
            '"out/run.fst", first_frame=10,'
        ),
    ): snippet_backends_waveform,
    (
        "docs/camera.md",
        "from fpga_robotics.sim.camera import CameraRenderer, render",
    ): snippet_camera,
    ("docs/running.md", "from fpga_robotics.scenario import load_scenario"): snippet_running,
    ("docs/viewer.md", "from fpga_robotics.viz import ViewerError, open_recorder"): snippet_viewer,
    (
        "docs/published.md",
        "# Every shipped scenario with the preset, five ways (25 runs on the model backend)",
    ): snippet_published_scenarios,
    ("docs/published.md", "# How each design drives on follow_person"): snippet_published_driving,
    (
        "docs/published.md",
        "# What each design does when it loses the person (lost_target)",
    ): snippet_published_lost,
    (
        "docs/published.md",
        "# The first camera frame of follow_person through both designs' trackers",
    ): snippet_published_first_frame,
}


#: Python blocks that build a Verilator model: run only under ``-m slow``.
SLOW_SNIPPETS = {
    ("README.md", "from fpga_robotics.hw.params import FollowTargetParams"),
    (
        "docs/backends.md",
        (
            'get_backend("verilator", params, waveform=WaveformRequest('
            '"out/run.fst", first_frame=10,'
        ),
    ),
}


def _python_params():
    return [
        pytest.param(b, marks=pytest.mark.slow) if snippet_key(b) in SLOW_SNIPPETS else b
        for b in python_blocks()
    ]


@pytest.mark.parametrize("block", _python_params(), ids=lambda b: f"{b.page}:{b.line}")
def test_documented_python(block, tmp_path, monkeypatch, capsys):
    handler = SNIPPETS.get(snippet_key(block))
    if handler is None:
        pytest.fail(f"{block.page}:{block.line}: no entry in SNIPPETS")
    monkeypatch.chdir(tmp_path)
    steps = handler(tmp_path, capsys)
    namespace = next(steps)
    shown = exec_snippet(block, namespace)
    with pytest.raises(StopIteration):
        steps.send(shown)


# --- What is not run, for the report -------------------------------------------------------------


def excused_commands():
    """``(where, command, reason)`` of every documented command (or part) not run here."""
    rows = []
    for page in PAGES:
        for doc in scan_page(page)[0]:
            plan = PLANS.get(doc.text)
            if plan is None:
                continue
            where = f"{doc.page}:{doc.line}"
            if plan.excused:
                rows.append((where, doc.text, plan.excused))
            if plan.part_why:
                rows.append((where, doc.text.replace(plan.part, "").rstrip(" &"), plan.part_why))
            if plan.slow:
                rows.append((where, doc.text, "place and route: only under -m slow"))
    return rows


def test_every_excuse_gives_a_reason():
    rows = excused_commands()
    assert rows and all(reason.strip() for _, _, reason in rows)
    assert all(PLANS[k].duration_why for k in PLANS if PLANS[k].duration)


if __name__ == "__main__":  # python tests/test_docs_commands.py: the table of what is not run
    for where, command, reason in excused_commands():
        print(f"{where}\t{command}\t{reason}")
    for key, plan in PLANS.items():
        if plan.duration_why:
            print(f"duration kept\t{key}\t{plan.duration_why}")
