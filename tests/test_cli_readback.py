"""``fpga-robotics readback``: the frames of any design's recording (whatever entities it
logs), ``--help``, and a file that is not a recording, or not a whole one, as one line with
exit code 2."""

import subprocess
import sys
import warnings

import pytest
import rerun as rr
import rerun.blueprint as rrb

from fpga_robotics import cli


def _recording(path, entities):
    """An .rrd where each ``entities[name]`` lists the frames that entity is logged at."""
    stream = rr.RecordingStream("readback-test")
    stream.save(str(path))
    stream.log("world/room", rr.Scalars(1.0), static=True)
    for name, frames in entities.items():
        for f in frames:
            stream.set_time("frame", sequence=f)
            stream.log(name, rr.Scalars(float(f)))
    stream.flush()
    stream.disconnect()
    return path


def _readback(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["readback", *argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.mark.parametrize(
    "entities, frames",
    [
        # a line follower: no design/ entity of FollowTarget's at all
        ({"sensors/line/left": range(7), "robot/wheels": range(7)}, 7),
        # entities logged at different frames: the frames are their union
        ({"design/found": range(0, 10, 2), "sensors/ultrasound": range(1, 10, 2)}, 10),
    ],
)
def test_readback_counts_the_frames_of_any_recording(entities, frames, tmp_path, capsys):
    path = _recording(tmp_path / "r.rrd", entities)
    code, out, err = _readback([str(path)], capsys)
    assert code == 0, err
    head = out.splitlines()[0]
    assert f", {frames} frames, " in head, out
    for name, logged in entities.items():
        assert f"  {name:22s} {len(logged):6d} rows" in out


def test_readback_answers_help(capsys):
    code, out, _ = _readback(["--help"], capsys)
    assert code == 0 and out.startswith("usage: fpga-robotics readback")


def test_a_file_that_is_not_a_recording_is_one_line(tmp_path, capsys):
    junk = tmp_path / "junk.rrd"
    junk.write_text("not a recording\n")
    code, _, err = _readback([str(junk)], capsys)
    assert code == 2
    assert err.count("\n") == 1 and "is not a rerun recording" in err


def test_a_cut_off_recording_is_one_line(tmp_path, capsys):
    # Cut in its last message, as a copy of a recording still being written: rerun warns of
    # the missing footer before it fails; only the error is said.
    path = _recording(tmp_path / "r.rrd", {"design/found": range(50)})
    data = path.read_bytes()
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(data[: len(data) // 2])
    with warnings.catch_warnings(record=True) as said:  # on stderr outside pytest
        warnings.simplefilter("always")
        code, out, err = _readback([str(cut)], capsys)
    assert (code, out) == (2, "") and [str(w.message) for w in said] == []
    # It is a recording, only not whole: said so, and how to get a whole one.
    assert err.count("\n") == 1 and "is a cut-off or damaged rerun recording" in err, err
    assert "is not a rerun recording" not in err and "'saved ...'" in err


@pytest.mark.parametrize("keep", [8, 40])  # inside the file's header; inside its first message
def test_a_recording_cut_near_its_start_is_still_called_cut_off(keep, tmp_path, capsys):
    path = _recording(tmp_path / "r.rrd", {"design/found": range(50)})
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(path.read_bytes()[:keep])
    code, out, err = _readback([str(cut)], capsys)
    assert (code, out) == (2, "")
    assert err.count("\n") == 1 and "is a cut-off or damaged rerun recording" in err, err


def test_an_empty_file_is_called_empty(tmp_path, capsys):
    empty = tmp_path / "empty.rrd"
    empty.write_bytes(b"")
    code, out, err = _readback([str(empty)], capsys)
    assert (code, out) == (2, "")
    assert err == f"fpga-robotics readback: error: {empty} is empty, not a rerun recording (.rrd)\n"


def test_the_library_module_run_as_a_command_points_at_the_command(tmp_path):
    # `python -m fpga_robotics.viz.readback FILE` ran nothing, printed nothing and exited 0.
    path = _recording(tmp_path / "r.rrd", {"design/found": range(3)})
    done = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.viz.readback", str(path)],
        check=False,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr.count("\n") == 1 and "fpga-robotics readback FILE.rrd" in done.stderr


def test_a_file_of_only_a_viewer_layout_is_one_line(tmp_path, capsys):
    # A saved blueprint (.rbl) holds no recording store: rerun raised ValueError, a traceback.
    layout = tmp_path / "layout.rrd"
    rrb.Blueprint(rrb.Spatial2DView()).save("app", str(layout))
    code, out, err = _readback([str(layout)], capsys)
    assert (code, out) == (2, "")
    assert err.count("\n") == 1 and "layout.rrd holds no recording" in err


def test_a_folder_is_named_as_a_folder(tmp_path, capsys):
    # It said "no recording at 'runs.rrd'", as of a path with nothing there.
    (tmp_path / "runs.rrd").mkdir()
    code, out, err = _readback([str(tmp_path / "runs.rrd")], capsys)
    assert (code, out) == (2, "")
    assert err.count("\n") == 1 and "runs.rrd is a folder, not a recording (.rrd)" in err
