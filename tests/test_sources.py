"""Frames from a video file or an image folder, resized and run through the design."""

import itertools
import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from rerun.chunk import RrdReader

from fpga_robotics.cli.errors import Terminated, UsageError, run_cli
from fpga_robotics.cli.run import main
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.sources import open_source, run_source
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.models.follow_target import FollowTargetModel
from fpga_robotics.sim.world.robots import GOPIGO3
from fpga_robotics.viz.readback import read_rrd

W, H = 160, 120


def scene_bgr(k, size=(480, 640)):
    """A grey room with a red block that moves right by 40 px a frame; frame 3 is empty."""
    img = np.full((*size, 3), 110, np.uint8)
    img[::7, :] = 90  # some texture, so that resizing has something to blend
    if k != 3:
        x0 = 120 + 40 * k
        img[150:400, x0 : x0 + 120] = (30, 30, 220)  # BGR: red
    return img


@pytest.fixture
def folder(tmp_path):
    d = tmp_path / "frames"
    d.mkdir()
    for k in range(5):
        cv2.imwrite(str(d / f"f{k:03d}.png"), scene_bgr(k))
    (d / "notes.txt").write_text("not an image")
    return d


@pytest.fixture
def video(tmp_path):
    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (640, 480))
    assert writer.isOpened()
    for k in range(5):
        writer.write(scene_bgr(k))
    writer.release()
    return path


def expected_rgb(bgr):
    return cv2.cvtColor(cv2.resize(bgr, (W, H), interpolation=cv2.INTER_LINEAR), cv2.COLOR_BGR2RGB)


def test_folder_frames_are_resized_and_converted_to_rgb(folder):
    src = open_source(str(folder), W, H)
    frames = list(src)
    assert len(frames) == 5 and src.kind == "folder"
    for k, f in enumerate(frames):
        assert f.shape == (H, W, 3) and f.dtype == np.uint8
        assert np.array_equal(f, expected_rgb(scene_bgr(k)))
    # Red lands in the R channel (index 0) after the BGR -> RGB swap.
    assert frames[0][70, 45].tolist() == [220, 30, 30]


def test_video_frames_come_back_in_order(video):
    src = open_source(str(video), W, H)
    frames = list(src)
    src.close()
    assert src.kind == "video" and len(frames) == 5
    for k, f in enumerate(frames):
        # MJPG is lossy: compare with the original, allowing JPEG error.
        diff = np.abs(f.astype(int) - expected_rgb(scene_bgr(k)).astype(int))
        assert diff.mean() < 4, k


def test_run_source_matches_the_golden_model_frame_by_frame(folder):
    params = FollowTargetParams(width=W, height=H)
    out = run_source(open_source(str(folder), W, H), ModelBackend(params), color="red")
    model = FollowTargetModel(params)
    for k, f in enumerate(open_source(str(folder), W, H)):
        m = model.process(f, 0b100)
        r = out["results"][k]
        assert (r["found"], r["proximity"], r["centroid_x"], r["motor_left"], r["motor_right"]) == (
            m.tracker.found,
            m.tracker.proximity,
            m.tracker.centroid_x,
            m.motor_left,
            m.motor_right,
        )
    found = [r["found"] for r in out["results"]]
    assert found == [True, True, True, False, True]
    # The block moves right: so does the centroid (scaled by 160/640).
    cx = [r["centroid_x"] for r in out["results"] if r["found"]]
    assert cx == sorted(cx) and abs(cx[0] - (120 + 60) / 4) <= 1
    assert out["frames"] == 5 and out["found_fraction"] == 0.8


def test_frames_are_stamped_at_the_sources_frame_rate(folder, tmp_path):
    """A video's frames at the rate it states, a folder's at the rate given (the scenario's
    camera.fps), so a run of the same input is stamped the same every time."""
    clip = tmp_path / "clip25.avi"
    writer = cv2.VideoWriter(str(clip), cv2.VideoWriter_fourcc(*"MJPG"), 25, (640, 480))
    for k in range(5):
        writer.write(scene_bgr(k))
    writer.release()
    params = FollowTargetParams(width=W, height=H)
    for spec, fps in ((clip, 25), (folder, 20)):
        records = []
        run_source(
            open_source(str(spec), W, H, fps=20), ModelBackend(params), on_frame=records.append
        )
        assert [r.sim_time for r in records] == [k / fps for k in range(5)], spec


def test_cli_stamps_a_folders_bag_at_the_scenarios_frame_rate(folder, tmp_path):
    from rosbags.highlevel import AnyReader  # lazy: rosbags, for this test only

    assert (
        main(
            ["--source", str(folder), "--backend", "model", "--rerun", "off", "--quiet"]
            + ["--set", "camera.fps=10", "--bag", str(tmp_path / "b")]
        )
        == 0
    )
    with AnyReader([tmp_path / "b"]) as reader:
        (clock,) = [c for c in reader.connections if c.topic == "/clock"]
        stamps = [t for _, t, _ in reader.messages([clock])]
    assert stamps == [k * 100_000_000 for k in range(5)]


def test_max_frames_stops_early(video):
    params = FollowTargetParams(width=W, height=H)
    out = run_source(open_source(str(video), W, H), ModelBackend(params), max_frames=2)
    assert out["frames"] == 2


def test_one_image_is_one_frame_of_its_own_kind(tmp_path):
    # A single image was opened as a video ("source x.png (video)"): it is one frame, read as
    # a folder's images are, and the summary calls it an image.
    for k in range(3):  # numbered like frames of a sequence: still only the one named
        cv2.imwrite(str(tmp_path / f"f{k:03d}.png"), scene_bgr(k))
    src = open_source(str(tmp_path / "f001.png"), W, H)
    frames = list(src)
    assert src.kind == "image" and len(frames) == 1
    assert np.array_equal(frames[0], expected_rgb(scene_bgr(1)))


def test_an_image_that_does_not_decode_is_said_so_when_opened(tmp_path):
    bad = tmp_path / "photo.png"
    bad.write_bytes(b"\x00" * 100)
    with pytest.raises(UsageError, match=r"cannot read image '.*photo\.png': OpenCV cannot decode"):
        open_source(str(bad), W, H)


@pytest.mark.slow  # a fresh Python process (about a second)
def test_a_video_that_does_not_decode_is_one_line_with_nothing_of_ffmpegs(tmp_path):
    # FFmpeg printed "[mov,mp4,...] moov atom not found" before the one-line error. FFmpeg's
    # log level is set once a process, so a fresh one opens it.
    bad = tmp_path / "clip.mp4"
    bad.write_bytes(b"\x00" * 1000)
    code = (
        "import sys\n"
        "from fpga_robotics.loop.sources import open_source\n"
        "try:\n"
        f"    open_source({str(bad)!r}, 160, 120)\n"
        "except Exception as exc:\n"
        "    print(exc, file=sys.stderr)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "OPENCV_FFMPEG_LOGLEVEL"}
    done = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.stderr == f"cannot read video {str(bad)!r}: OpenCV cannot decode it\n"


def test_empty_folder_and_bad_specs_are_usage_errors(tmp_path):
    with pytest.raises(UsageError, match="holds no images"):
        open_source(str(tmp_path), W, H)
    with pytest.raises(UsageError, match="device number"):
        open_source("camera:front", W, H)
    with pytest.raises(UsageError, match="no such file"):
        open_source(str(tmp_path / "x.mp4"), W, H)


def test_cli_runs_a_video_and_writes_the_results(video, tmp_path, capsys):
    path = tmp_path / "src.json"
    with pytest.raises(SystemExit) as info:
        run_cli(
            main,
            [
                "--source",
                str(video),
                "--backend",
                "model",
                "--rerun",
                "off",
                "--summary",
                str(path),
                "--quiet",
            ],
        )
    out, _ = capsys.readouterr()
    assert info.value.code == 0
    s = json.loads(path.read_text())
    assert s["frames"] == 5 and s["found_frames"] == 4 and s["source_kind"] == "video"
    assert "found in 4 frames" in out


def test_a_design_of_ones_own_reports_its_other_outputs_from_real_frames(folder, tmp_path, capsys):
    # Its outputs no connector reads (RedFrames' red_count and red_sum) were missing from
    # --source's summary and terminal lines, which a closed-loop run has.
    scenario = Path(__file__).parent / "data" / "user_designs" / "red_frames.toml"
    path = tmp_path / "src.json"
    argv = ["--scenario", str(scenario), "--source", str(folder), "--backend", "pysim"]
    with pytest.raises(SystemExit) as info:
        run_cli(main, [*argv, "--rerun", "off", "--summary", str(path), "--quiet"])
    out, _ = capsys.readouterr()
    assert info.value.code == 0
    # The design's rule on each frame as the design sees it (40x30, RGB444).
    counts = []
    for k in range(5):
        rgb = (
            cv2.cvtColor(
                cv2.resize(scene_bgr(k), (40, 30), interpolation=cv2.INTER_LINEAR),
                cv2.COLOR_BGR2RGB,
            ).astype(int)
            >> 4
        )
        red = (rgb[..., 0] >= 8) & (rgb[..., 1] < 5) & (rgb[..., 2] < 5)
        counts.append(int(red.sum()))
    assert counts[3] == 0 and min(counts[:3]) > 0  # frame 3 is empty
    s = json.loads(path.read_text())
    assert [r["extra"]["red_count"] for r in s["results"]] == counts
    # red_sum: the last four frames' counts, added up after frame_done.
    sums = [sum(counts[max(0, k - 3) : k + 1]) for k in range(5)]
    assert [r["extra"]["red_sum"] for r in s["results"]] == sums
    assert s["extra_outputs"]["red_count"] == {
        "last": counts[-1],
        "min": min(counts),
        "max": max(counts),
    }
    assert f"design output red_sum: last {sums[-1]}, min {min(sums)}, max {max(sums)}" in out


def test_cli_folder_at_another_resolution(folder, tmp_path, capsys):
    path = tmp_path / "src.json"
    with pytest.raises(SystemExit) as info:
        run_cli(
            main,
            [
                "--source",
                str(folder),
                "--backend",
                "model",
                "--rerun",
                "off",
                "--resolution",
                "320x240",
                "--summary",
                str(path),
                "--quiet",
            ],
        )
    assert info.value.code == 0
    s = json.loads(path.read_text())
    assert s["resolution"] == "320x240" and s["found_frames"] == 4


class _Frames:
    """Two frames from a source of ``kind``."""

    spec = "two frames"

    def __init__(self, kind):
        self.kind = kind

    def __iter__(self):
        return iter([expected_rgb(scene_bgr(0))] * 2)

    def close(self):
        pass


class _CutOff:
    """``source``'s first two frames, then ``interrupt`` (Ctrl-C or SIGTERM arriving mid-run)."""

    def __init__(self, source, interrupt):
        self.source, self.interrupt = source, interrupt
        self.spec, self.kind = source.spec, source.kind

    def __iter__(self):
        yield from itertools.islice(self.source, 2)
        raise self.interrupt()

    def close(self):
        self.source.close()


def test_a_camera_runs_until_ctrl_c():
    params = FollowTargetParams(width=W, height=H)
    out = run_source(_CutOff(_Frames("camera"), KeyboardInterrupt), ModelBackend(params))
    assert out["frames"] == 2 and out["found_frames"] == 2


@pytest.mark.parametrize(
    "kind, interrupt",
    [(kind, KeyboardInterrupt) for kind in ("video", "folder", "bag")]
    + [(kind, Terminated) for kind in ("camera", "video", "folder", "bag")],
)
def test_an_interrupted_finite_source_or_a_terminated_run_is_not_a_result(kind, interrupt):
    params = FollowTargetParams(width=W, height=H)
    with pytest.raises(interrupt):
        run_source(_CutOff(_Frames(kind), interrupt), ModelBackend(params))


@pytest.mark.parametrize("interrupt, code", [(KeyboardInterrupt, 130), (Terminated, 143)])
def test_cli_video_cut_off_exits_as_interrupted_and_writes_no_summary(
    video, tmp_path, monkeypatch, interrupt, code
):
    monkeypatch.setattr(
        "fpga_robotics.cli.run.open_source",
        lambda *args, **kwargs: _CutOff(open_source(*args, **kwargs), interrupt),
    )
    summary, recording = tmp_path / "s.json", tmp_path / "r.rrd"
    with pytest.raises(SystemExit) as info:
        run_cli(
            main,
            [
                "--source",
                str(video),
                "--backend",
                "model",
                "--rerun",
                f"save:{recording}",
                "--summary",
                str(summary),
                "--quiet",
            ],
        )
    assert info.value.code == code
    assert not summary.exists()  # no summary of a cut-off run
    assert recording.exists()  # the recording is closed under its own name


def test_frames_carry_the_twist_the_design_commands_on_the_robots_wheels(folder):
    params = FollowTargetParams(width=W, height=H)
    records = []
    out = run_source(
        open_source(str(folder), W, H), ModelBackend(params), robot=GOPIGO3, on_frame=records.append
    )
    # Differential drive by hand: v = r (wl + wr) / 2, w = r (wr - wl) / separation.
    r, sep = GOPIGO3.wheel_radius, GOPIGO3.wheel_separation
    for row, record in zip(out["results"], records, strict=True):
        left, right = np.radians(row["motor_left"]), np.radians(row["motor_right"])
        assert record.cmd_v == pytest.approx(r * (left + right) / 2)
        assert record.cmd_w == pytest.approx(r * (right - left) / sep)
        assert (record.robot_v, record.robot_w) == (0.0, 0.0)  # nothing moves
    assert any(record.cmd_v > 0 for record in records)  # the design drives towards the block


def test_a_recording_of_real_frames_has_no_map_of_a_world_it_never_saw(folder, tmp_path):
    """Real frames have no world: no robot parked at 0, 0 with its field of view, no map view
    in the layout; the frames, the design's outputs and the commanded twist are there."""
    path = tmp_path / "src.rrd"
    argv = ["--source", str(folder), "--backend", "model", "--rerun", f"save:{path}", "--quiet"]
    with pytest.raises(SystemExit) as info:
        run_cli(main, argv)
    assert info.value.code == 0
    data = read_rrd(str(path))
    for entity in (*data.entities, *data.static):
        assert not entity.startswith("map"), entity
    assert len(data.entities["camera/raw"]) == len(data.entities["design/tracking"]) == 5
    assert len(data.entities["twist/v"]) == 5
    reader = RrdReader(str(path))
    views = [
        chunk.to_record_batch().column("ViewBlueprint:display_name").to_pylist()[-1][0]
        for chunk in reader.stream(store=reader.blueprints()[-1])
        if "ViewBlueprint:display_name" in chunk.to_record_batch().schema.names
    ]
    assert "Filtered (design output)" in views and "Events" in views
    assert "World (top-down)" not in views
