"""``--bag`` for campaigns: every recorded run is also a ROS 2 bag in ``bags/<run_id>/``, with
as many camera images as the run had frames (docs/ros.md, docs/campaigns.md)."""

import json

import pytest
from rosbags.highlevel import AnyReader

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.sweep import main


def test_recorded_runs_are_written_as_bags(tmp_path, capsys):
    campaign = tmp_path / "tiny.toml"
    campaign.write_text(
        'scenarios = ["follow_person"]\nseeds = "0-1"\nbackend = "model"\n'
        'resolution = "40x24"\nduration = 1.0\n'
    )
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        run_cli(
            main,
            [
                str(campaign),
                "--out",
                str(out),
                "--workers",
                "1",
                "--record",
                "all",
                "--bag",
                "--quiet",
            ],
            prog="fpga-robotics sweep",
        )
    assert info.value.code in (0, 1), capsys.readouterr().err  # 1: a run failed its checks
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    mkdir_mode = (out / "recordings").stat().st_mode & 0o777  # a folder made by mkdir
    assert len(rows) == 2 and {r["status"] for r in rows} <= {"pass", "fail"}
    for row in rows:
        bag = out / row["bag"]
        assert bag == out / "bags" / row["run_id"] and (bag / "metadata.yaml").is_file()
        assert bag.stat().st_mode & 0o777 == mkdir_mode  # not mkdtemp's private 0700
        with AnyReader([bag]) as reader:
            images = [c for c in reader.connections if c.topic == "/camera/image_raw"]
            assert sum(1 for _ in reader.messages(connections=images)) == row["frames"]


def test_bag_needs_recorded_runs(tmp_path, capsys):
    campaign = tmp_path / "tiny.toml"
    campaign.write_text('scenarios = ["follow_person"]\n')
    with pytest.raises(SystemExit) as info:
        run_cli(main, [str(campaign), "--record", "none", "--bag"], prog="fpga-robotics sweep")
    assert info.value.code == 2
    assert "--bag writes the recorded runs as ROS 2 bags" in capsys.readouterr().err
