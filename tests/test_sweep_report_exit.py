"""``sweep report DIR`` exits as the campaign did: 1 when a run failed (no known limit
explaining it) or never ran, 0 when all passed or only known limits failed; ``--exit-zero``
gives 0 whatever the results."""

import json

from fpga_robotics.cli import sweep as cli

#: follow_person for 1 s: too short to acquire the person, so the checks below fail.
CAMPAIGN = """scenarios = ["follow_person"]
seeds = [0, 1]
backend = "model"
resolution = "40x24"
duration = 1.0

[[known_limits]]
check = "acquired_within_s"
reason = "1 s is too short"

[[known_limits]]
check = "found_min_fraction"
reason = "1 s is too short"

[[known_limits]]
check = "max_mean_aim_error_deg"
reason = "1 s is too short to turn to the person"
"""


def test_report_exit_code_follows_the_runs(tmp_path, monkeypatch, capsys):
    (tmp_path / "c.toml").write_text(CAMPAIGN)
    monkeypatch.chdir(tmp_path)
    argv = ["c.toml", "--workers", "1", "--out", "out", "--quiet", "--record", "none"]
    assert cli.main(argv) == 0  # every failure is a known limit
    assert cli.main(["report", "out"]) == 0

    meta_path = tmp_path / "out" / "campaign.json"
    meta = json.loads(meta_path.read_text())
    assert len(meta["known_limits"]) == 3
    # One failed check no longer explained: both runs count as failures.
    meta_path.write_text(json.dumps({**meta, "known_limits": meta["known_limits"][:1]}))
    assert cli.main(["report", "out"]) == 1
    assert cli.main(["report", "out", "--exit-zero"]) == 0
    # Every run present passed in effect, but one never ran (an interrupted campaign).
    meta_path.write_text(json.dumps({**meta, "missing": 1}))
    assert cli.main(["report", "out"]) == 1
    assert cli.main(["report", "out", "--exit-zero"]) == 0
    meta_path.write_text(json.dumps(meta))
    assert cli.main(["report", "out"]) == 0
    assert "report: out/report.html" in capsys.readouterr().out
