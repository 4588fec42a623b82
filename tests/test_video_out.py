"""run --save-video: the camera frames of a run as a video that --source plays back."""

import json

import numpy as np
import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario


def cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(main, argv, prog="fpga-robotics run")
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.mark.parametrize("suffix", [".mp4", ".avi"])
def test_saved_video_holds_the_camera_frames(suffix, tmp_path, monkeypatch, capsys):
    import cv2

    monkeypatch.chdir(tmp_path)
    code, _out, err = cli(
        [
            "--backend",
            "model",
            "--duration",
            "2",
            "--rerun",
            "off",
            "--quiet",
            "--save-video",
            f"clip{suffix}",
        ],
        capsys,
    )
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"clip{suffix}"]  # no temp file

    frames = []
    run_scenario(
        load_scenario("follow_person", ["sim.duration=2"]),
        backend="model",
        on_frame=lambda r: frames.append(r.camera_rgb),
    )
    cap = cv2.VideoCapture(str(tmp_path / f"clip{suffix}"))
    decoded = []
    while True:
        ok, bgr = cap.read()
        if not ok:
            break
        decoded.append(bgr[:, :, ::-1])
    cap.release()
    assert len(decoded) == len(frames) == 60
    # Lossy codecs: close to the rendered frames, not equal (8-bit levels).
    errors = [np.abs(d.astype(int) - f.astype(int)).mean() for d, f in zip(decoded, frames)]
    assert max(errors) < 8


def test_source_runs_the_design_on_the_saved_clip(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert (
        cli(
            [
                "--backend",
                "model",
                "--duration",
                "2",
                "--rerun",
                "off",
                "--quiet",
                "--save-video",
                "clip.mp4",
            ],
            capsys,
        )[0]
        == 0
    )
    code, _out, err = cli(
        [
            "--backend",
            "model",
            "--rerun",
            "off",
            "--quiet",
            "--source",
            "clip.mp4",
            "--summary",
            "s.json",
        ],
        capsys,
    )
    assert code == 0, err
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["frames"] == 60 and s["found_frames"] >= 57


@pytest.mark.parametrize("suffix", [".mp4", ".avi"])
@pytest.mark.parametrize("width, height", [(168, 97), (41, 30)])
def test_a_frame_of_odd_size_keeps_its_last_row_and_column(suffix, width, height, tmp_path):
    # The codecs take even sizes; OpenCV dropped the odd last row (168x97 came back 168x96).
    import cv2

    from fpga_robotics.loop.video_out import CameraVideo

    frame = np.zeros((height, width, 3), np.uint8)
    frame[-1, :] = frame[:, -1] = 255  # a white last row and column on black
    path = tmp_path / f"odd{suffix}"
    with CameraVideo(path, 10) as video:
        for _ in range(3):
            video.write(frame)
    ok, bgr = cv2.VideoCapture(str(path)).read()
    assert ok
    assert bgr.shape == (height + height % 2, width + width % 2, 3)
    assert bgr[height - 1, : width // 2].mean() > 200  # the last row, white
    assert bgr[: height // 2, width - 1].mean() > 200  # the last column, white
    assert bgr[: height // 2, : width // 2].mean() < 30  # the rest, black
