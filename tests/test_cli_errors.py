"""One base for the errors the user can fix: every library error class derives from
``UserError``, and ``run_cli`` turns exactly those (and a missing input file) into one line and
exit code 2, while any other exception keeps its traceback."""

import ast
import importlib

import pytest
from test_layering import source_modules

from fpga_robotics.cli.errors import USAGE_EXIT, UsageError, run_cli
from fpga_robotics.hw.errors import UserError

#: Exception classes that are not the user's to fix, and why.
NOT_USER_ERRORS = {
    # a backend that hangs or fails to compile is the caller's to word (run.py adds context)
    "fpga_robotics.sim.backends.base.BackendError",
    "fpga_robotics.sweep.runner.RunTimeout",  # a run over its time budget: a result, not an error
    "fpga_robotics.viz.outfile._Discard",  # private control flow
}


def _exception_classes():
    """``module.Class`` of every class in the packages whose name says it is an error."""
    found = []
    for module, path in source_modules().items():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if (
                isinstance(node, ast.ClassDef)
                and node.bases
                and (
                    node.name.endswith(("Error", "Unavailable", "Timeout"))
                    or any(isinstance(b, ast.Name) and b.id == "Exception" for b in node.bases)
                )
            ):
                found.append(f"{module}.{node.name}")
    return found


CLASSES = _exception_classes()


def test_the_scan_finds_the_known_error_classes():
    # The scan itself must see the classes (a scan that finds nothing passes everything).
    for name in (
        "fpga_robotics.sim.camera.frames.FrameError",
        "fpga_robotics.sim.backends.port_map.PortMapError",
        "fpga_robotics.scenario.errors.ScenarioError",
        "fpga_robotics.viz.errors.ViewerError",
        "fpga_robotics.hw.errors.UsageError",
    ):
        assert name in CLASSES
    assert len(CLASSES) >= 17


@pytest.mark.parametrize("name", [c for c in CLASSES if c not in NOT_USER_ERRORS])
def test_every_library_error_derives_from_user_error(name):
    module, _, cls = name.rpartition(".")
    assert issubclass(getattr(importlib.import_module(module), cls), UserError), name


def test_a_design_parameter_out_of_range_is_a_user_error():
    from fpga_robotics.hw.errors import ParamError
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.hw.sensor_params import InterlockParams

    # diff_min is a 4-bit channel difference (0..15); resume must not be below stop.
    with pytest.raises(ParamError, match="diff_min"):
        FollowTargetParams(diff_min=16)
    with pytest.raises(ParamError, match="resume_mm"):
        InterlockParams(stop_mm=300, resume_mm=200)
    with pytest.raises(ParamError, match="unknown design preset"):
        FollowTargetParams.preset("nope")
    assert issubclass(ParamError, UserError) and issubclass(ParamError, ValueError)


def test_bases_callers_catch_are_kept():
    from fpga_robotics.sim.backends.base import BackendError
    from fpga_robotics.sim.backends.port_map import PortMapError
    from fpga_robotics.sim.files import OutputPathError
    from fpga_robotics.sim.pins.base import PinError

    assert issubclass(PortMapError, BackendError)
    assert issubclass(OutputPathError, ValueError)
    assert issubclass(PinError, RuntimeError)


def _run(exc, capsys):
    def main(argv):
        raise exc

    with pytest.raises(SystemExit) as info:
        run_cli(main, [], prog="fpga-robotics demo")
    return info.value.code, capsys.readouterr().err


@pytest.mark.parametrize(
    "exc",
    [
        UsageError("--x must be > 0"),
        importlib.import_module("fpga_robotics.sim.camera.frames").FrameError("bad frame"),
        importlib.import_module("fpga_robotics.sim.files").OutputPathError("cannot write x"),
        FileNotFoundError("no such file: x"),
    ],
)
def test_a_user_error_is_one_line_and_exit_2(exc, capsys):
    code, err = _run(exc, capsys)
    assert code == USAGE_EXIT
    assert err == f"fpga-robotics demo: error: {exc}\n"


def test_any_other_error_keeps_its_traceback(capsys):
    with pytest.raises(ValueError, match="a bug"):
        _run(ValueError("a bug"), capsys)


def test_a_reader_that_goes_away_stops_the_command_quietly():
    """`fpga-robotics readback x.rrd | head`: the closed pipe ends the command with SIGPIPE's
    exit code and no traceback."""
    import subprocess
    import sys

    code = (
        "from fpga_robotics.cli.errors import run_cli\n"
        "def main(argv):\n"
        "    for i in range(100000):\n"
        "        print('line', i)\n"
        "run_cli(main)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    proc.stdout.readline()
    proc.stdout.close()
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141
    assert "Traceback" not in stderr and "BrokenPipe" not in stderr, stderr


def _into_a_closed_pipe(args):
    """Run ``python args`` with stdout a pipe whose reader has gone (``| head`` after its
    lines), stdout buffered as in a user's shell: (exit code, stderr)."""
    import os
    import subprocess
    import sys

    read_end, write_end = os.pipe()
    os.close(read_end)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    try:
        proc = subprocess.run(
            [sys.executable, *args],
            check=False,
            stdout=write_end,
            stderr=subprocess.PIPE,
            env=env,
            timeout=120,
            text=True,
        )
    finally:
        os.close(write_end)
    return proc.returncode, proc.stderr


_RUN_CLI = "from fpga_robotics.cli.errors import run_cli\nimport argparse\n"


@pytest.mark.parametrize(
    "args",
    [
        # a command's short output, held in the buffer until exit, and argparse's --help
        ["-c", _RUN_CLI + "run_cli(lambda a: print('x'))"],
        ["-c", _RUN_CLI + "run_cli(lambda a: argparse.ArgumentParser().parse_args(['-h']))"],
        # the top level's own listings
        ["-m", "fpga_robotics", "--version"],
        ["-m", "fpga_robotics", "--help"],
        ["-m", "fpga_robotics", "bench", "--list"],
        ["-m", "fpga_robotics", "bench", "--help"],
    ],
)
def test_a_reader_gone_before_the_output_is_written_stops_it_quietly(args):
    code, stderr = _into_a_closed_pipe(args)
    assert code == 141, stderr
    assert "Traceback" not in stderr and "BrokenPipe" not in stderr, stderr
