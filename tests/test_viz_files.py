"""Recording files: checked before the run, never replacing an earlier recording silently, and
kept under their real name (never as a hidden partial file) when a run is interrupted."""

import faulthandler
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from terminal_signals import FROM_A_TERMINAL

from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.records import FrameRecord
from fpga_robotics.viz import ViewerError, open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import read_rrd

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture(autouse=True)
def watchdog():
    # A hang (the bug class under test) ends the test session with tracebacks, not forever.
    faulthandler.dump_traceback_later(300, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def frame(i, w=32, h=24):
    result = FrameResult(
        filtered=np.zeros((h, w), np.uint16), found=False, proximity=0, centroid_x=0,
        centroid_leds=0, motor_left=10 * i, motor_right=-10 * i, cycles=1,
    )  # fmt: skip
    return FrameRecord(
        frame=i, sim_time=0.1 * i, camera_rgb=np.full((h, w, 3), i % 256, np.uint8), color_sel=4,
        result=result, robot_x=0.0, robot_y=0.0, robot_heading=0.0, robot_v=0.0, robot_w=0.0,
        cmd_v=0.0, cmd_w=0.0, camera_hfov=1.0,
    )  # fmt: skip


def record(mode, default_path, frames):
    rec = open_recorder(mode, default_path=str(default_path))
    for i in range(frames):
        rec.log_frame(frame(i))
    return rec, rec.close()


def frames_in(path):
    return read_rrd(str(path)).entities[P.MOTORS_DPS].frames


def hidden(folder):
    return sorted(n for n in os.listdir(folder) if n.startswith("."))


# Paths checked before the run ------------------------------------------------------------------


def unwritable_folder(tmp_path):
    """A folder this process cannot create files in (root ignores permission bits: /sys)."""
    if os.geteuid() == 0:
        return "/sys"
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    return str(folder)


@pytest.mark.parametrize("case", ["folder", "fifo", "device link", "below a file", "unwritable"])
def test_bad_save_paths_are_viewer_errors_before_any_frame(tmp_path, case):
    if case == "folder":
        path = tmp_path / "dir.rrd"
        path.mkdir()
        hint = "is a folder"
    elif case == "fifo":
        path = tmp_path / "pipe.rrd"
        os.mkfifo(path)
        hint = "not a regular file"
    elif case == "device link":
        path = tmp_path / "null.rrd"
        path.symlink_to("/dev/null")
        hint = "not a regular file"
    elif case == "below a file":
        (tmp_path / "file").write_text("x")
        path = tmp_path / "file" / "run.rrd"
        hint = "is not a folder"
    else:
        path = os.path.join(unwritable_folder(tmp_path), "run.rrd")
        hint = "cannot write in"
    before = sorted(os.listdir(tmp_path))
    with pytest.raises(ViewerError, match=hint):
        open_recorder(f"save:{path}", default_path=str(tmp_path / "default.rrd"))
    assert sorted(os.listdir(tmp_path)) == before  # nothing created


def test_an_unusable_default_path_is_an_error_for_live_modes_too(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ViewerError, match="is not a folder"):
        open_recorder("connect", default_path=str(tmp_path / "file" / "run.rrd"))


# Never replacing an earlier recording silently ------------------------------------------------


def test_the_default_path_gets_a_new_name_when_taken(tmp_path):
    default = tmp_path / "runs" / "follow_person.rrd"
    names = []
    for n in (3, 4, 5):
        rec, msg = record("save", default, n)
        names.append(os.path.basename(rec.path))
        assert f"saved {n} frames" in msg and rec.path in msg and "replacing" not in msg
    assert names == ["follow_person.rrd", "follow_person-2.rrd", "follow_person-3.rrd"]
    for name, n in zip(names, (3, 4, 5), strict=True):
        assert frames_in(default.parent / name) == list(range(n))  # each run kept whole


def test_runs_open_together_get_different_names(tmp_path):
    default = tmp_path / "run.rrd"
    a = open_recorder("save", default_path=str(default))
    b = open_recorder("save", default_path=str(default))
    assert a.path != b.path
    a.log_frame(frame(0))
    for i in range(2):
        b.log_frame(frame(i))
    b.close()
    a.close()
    assert frames_in(a.path) == [0] and frames_in(b.path) == [0, 1]
    assert hidden(tmp_path) == []


def test_an_explicit_path_is_replaced_and_the_notice_says_so(tmp_path):
    path = tmp_path / "mine.rrd"
    rec, first = record(f"save:{path}", tmp_path / "d.rrd", 2)
    assert "replacing" not in first
    rec, second = record(f"save:{path}", tmp_path / "d.rrd", 3)
    assert rec.path == str(path) and "replacing an earlier recording" in second
    assert frames_in(path) == [0, 1, 2]
    assert sorted(os.listdir(tmp_path)) == ["mine.rrd"]


def test_the_closing_line_names_a_folder_full_of_recordings(tmp_path, monkeypatch):
    from fpga_robotics.viz import outcome

    monkeypatch.setattr(outcome, "LARGE_FOLDER_BYTES", 3_000_000)
    runs = tmp_path / "runs"
    runs.mkdir()
    (runs / "old.rrd").write_bytes(bytes(2_000_000))
    (runs / "notes.txt").write_bytes(bytes(5_000_000))  # not a recording: not counted
    (runs / "sub").mkdir()
    (runs / "sub" / "deep.rrd").write_bytes(bytes(5_000_000))  # below the folder: not counted
    rec, msg = record("save", runs / "run.rrd", 3)
    size = os.path.getsize(rec.path)
    assert f"({size / 1e6:.1f} MB, " in msg  # the recording's own size
    assert "holds" not in msg and "--rerun off" not in msg  # 2 MB and a little: not large
    (runs / ".old.1a2b3c4d.partial.rrd").write_bytes(bytes(1_500_000))  # a killed run's
    rec, msg = record("save", runs / "run.rrd", 3)
    assert os.path.basename(rec.path) == "run-2.rrd"
    held = 2_000_000 + 1_500_000 + size + os.path.getsize(rec.path)
    assert msg.endswith(
        f"open it with: rerun {rec.path} "
        f"({runs.as_posix()}/ holds {held / 1e6:.0f} MB; "
        "--rerun off skips the recording)"
    ), msg


def test_a_fallback_file_does_not_replace_either(tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    default = tmp_path / "run.rrd"
    record(f"save:{default}", tmp_path / "x.rrd", 1)
    from fpga_robotics.viz import sinks

    monkeypatch.setattr(sinks, "port_is_listening", lambda *a, **k: False)
    rec, msg = record("spawn", default, 2)
    assert rec.path == str(tmp_path / "run-2.rrd") and "no display" in msg
    assert frames_in(default) == [0]


# Interrupts ------------------------------------------------------------------------------------


def wait_for_frames(folder, proc, timeout=120):
    """Wait until the run's hidden temporary file holds frames; the process must still run."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        if os.path.isdir(folder):
            partial = [n for n in os.listdir(folder) if n.endswith(".partial.rrd")]
            # Frames are written in batches of a few; one batch is well over 100 kB.
            if partial and os.path.getsize(os.path.join(folder, partial[0])) > 100_000:
                return
        time.sleep(0.1)
    raise AssertionError("the run never started writing frames")


def finish(proc, timeout=90):
    try:
        return proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def test_ctrl_c_keeps_the_recording_under_its_real_name(tmp_path):
    # The command line as a user runs it; paced to the clock so that it is still running.
    rrd = tmp_path / "out" / "run.rrd"
    proc = subprocess.Popen(
        [sys.executable, "-m", "fpga_robotics.run", "--backend", "model", "--duration", "120",
         "--realtime", "--quiet", "--rerun", f"save:{rrd}"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **FROM_A_TERMINAL
    )  # fmt: skip
    wait_for_frames(rrd.parent, proc)
    proc.send_signal(signal.SIGINT)
    _out, err = finish(proc)
    assert proc.returncode == 130, err
    assert os.listdir(rrd.parent) == ["run.rrd"]  # no hidden partial file left
    assert len(frames_in(rrd)) > 0


SCRIPT = textwrap.dedent(
    """
    import signal, sys, time
    sys.path.insert(0, {tests!r})
    from test_viz_files import frame
    from fpga_robotics.viz import open_recorder

    def interrupted(signum, _frame):  # what the CLI does with SIGTERM
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, interrupted)
    rec = open_recorder({mode!r}, default_path={default!r})
    try:
        i = 0
        while True:
            rec.log_frame(frame(i, 160, 120))
            i += 1
            time.sleep(0.005)
    except KeyboardInterrupt:
        print("interrupted")
    finally:
        rec.close()
        print("\\n".join(rec.notices))
    """
)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_mid_run_keeps_the_recording(tmp_path, signum):
    default = tmp_path / "runs" / "run.rrd"
    script = SCRIPT.format(tests=os.path.join(ROOT, "tests"), mode="save", default=str(default))
    proc = subprocess.Popen(
        [sys.executable, "-c", script], cwd=tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **FROM_A_TERMINAL
    )  # fmt: skip
    wait_for_frames(default.parent, proc)
    proc.send_signal(signum)
    out, err = finish(proc)
    assert proc.returncode == 0, err
    assert "interrupted" in out and f"rerun {default}" in out
    assert os.listdir(default.parent) == ["run.rrd"]
    frames = frames_in(default)
    assert frames == list(range(len(frames))) and frames


def test_an_interrupt_while_opening_leaves_no_file(tmp_path, monkeypatch):
    from fpga_robotics.viz.recorder import Recorder

    def interrupted(self):
        raise KeyboardInterrupt

    monkeypatch.setattr(Recorder, "_log_static_styles", interrupted)
    for mode in ("save", f"save:{tmp_path / 'mine.rrd'}"):
        with pytest.raises(KeyboardInterrupt):
            open_recorder(mode, default_path=str(tmp_path / "run.rrd"))
    assert os.listdir(tmp_path) == []


def test_a_run_that_ends_before_its_first_frame_writes_no_file(tmp_path):
    # An error before the first frame (or Ctrl-C) leaves no empty recording, and an earlier
    # recording at the same path is left as it was.
    path = tmp_path / "mine.rrd"
    rec, line = record(f"save:{path}", tmp_path / "d.rrd", 0)
    assert "no frame was recorded" in line and rec.path is None
    assert os.listdir(tmp_path) == []
    record(f"save:{path}", tmp_path / "d.rrd", 2)
    rec, line = record(f"save:{path}", tmp_path / "d.rrd", 0)
    assert "no file was written" in line
    assert os.listdir(tmp_path) == ["mine.rrd"] and frames_in(path) == [0, 1]


def test_a_recorder_never_closed_still_leaves_its_file_under_the_real_name(tmp_path):
    import gc

    path = tmp_path / "forgotten.rrd"
    rec = open_recorder(f"save:{path}", default_path=str(path))
    for i in range(3):
        rec.log_frame(frame(i))
    del rec
    gc.collect()
    assert os.listdir(tmp_path) == ["forgotten.rrd"] and frames_in(path) == [0, 1, 2]


def test_a_process_that_exits_without_closing_leaves_no_partial_file(tmp_path):
    script = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {os.path.join(ROOT, "tests")!r})
        from test_viz_files import frame
        from fpga_robotics.viz import open_recorder

        rec = open_recorder("save", default_path={str(tmp_path / "run.rrd")!r})
        for i in range(40):
            rec.log_frame(frame(i))
        """
    )
    proc = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert os.listdir(tmp_path) == ["run.rrd"]
    assert frames_in(tmp_path / "run.rrd") == list(range(40))
