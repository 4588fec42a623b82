"""A campaign's [[known_limits]]: parsed and checked, matched against the runs that failed, shown
in the report with their reasons, and not counted against the design; the robustness
campaign's small version runs (slow)."""

import pytest

from fpga_robotics.sweep.campaign import CampaignError, load_campaign, read_campaign_file
from fpga_robotics.sweep.report import (
    campaign_passed,
    explained,
    failures_by_check,
    format_report,
    known_limit,
    write_html,
)
from fpga_robotics.sweep.results import make_row

BASE = {
    "name": "t",
    "scenarios": ["follow_person"],
    "seeds": "0",
    "sets": [{"camera.resolution": "80x60"}, {"camera.fps": 15.0}],
}
LIMIT = {
    "check": "found_min_fraction",
    "when": {"camera.resolution": "80x60"},
    "reason": "at 80x60 the target is too few pixels far away",
}


def test_known_limits_are_parsed_with_their_scope():
    c = load_campaign(
        {**BASE, "known_limits": [LIMIT, {**LIMIT, "scenarios": "divider", "when": {}}]}
    )
    assert c.known_limits == [
        {
            "check": ["found_min_fraction"],
            "when": {"camera.resolution": "80x60"},
            "scenarios": [],
            "reason": LIMIT["reason"],
        },
        {
            "check": ["found_min_fraction"],
            "when": {},
            "scenarios": ["divider"],
            "reason": LIMIT["reason"],
        },
    ]
    both = load_campaign(
        {
            **BASE,
            "known_limits": [{**LIMIT, "check": ["found_min_fraction", "max_person_collisions"]}],
        }
    ).known_limits
    assert both[0]["check"] == ["found_min_fraction", "max_person_collisions"]
    assert load_campaign(dict(BASE)).known_limits == []


@pytest.mark.parametrize(
    "entry, says",
    [
        ({**LIMIT, "check": "found_min"}, "registered check"),
        ({**LIMIT, "check": []}, "registered check"),
        ({**LIMIT, "reason": " "}, "give a reason"),
        ({**LIMIT, "when": {"camera.noise_std": 0.0}}, "no grid axis or set"),
        # A value no run has would explain nothing, silently.
        (
            {**LIMIT, "when": {"camera.resolution": "80x61"}},
            (
                'when camera.resolution = "80x61" matches no run \\(the campaign\'s values of '
                'camera.resolution: "80x60"\\)'
            ),
        ),
        (
            {**LIMIT, "when": {"camera.resolution": "80x60", "camera.fps": 15.0}},
            'when camera.resolution = "80x60", camera.fps = 15.0 matches no run',
        ),
        ({**LIMIT, "why": "x"}, "unknown key 'why'"),
    ],
)
def test_a_malformed_known_limit_says_what_is_wrong(entry, says):
    with pytest.raises(CampaignError, match=says):
        load_campaign({**BASE, "known_limits": [entry]})


def test_a_known_limit_off_an_axis_the_command_line_replaced_does_not_apply():
    grid = {**BASE, "sets": [{"camera.fps": 15.0}], "grid": {"camera.resolution": ["160x120"]}}
    limits = [LIMIT, {**LIMIT, "when": {"camera.fps": 30.0}}]
    # --grid replaced the resolution axis: the entry for 80x60 does not apply. The fps of
    # the file's sets is still checked.
    with pytest.raises(CampaignError, match="when camera.fps = 30.0 matches no run"):
        load_campaign(
            {**grid, "known_limits": limits}, command_line={"grid": ["camera.resolution"]}
        )
    with pytest.raises(CampaignError, match='when camera.resolution = "80x60" matches no run'):
        load_campaign({**grid, "known_limits": [LIMIT]})
    c = load_campaign(
        {**grid, "known_limits": [LIMIT]}, command_line={"grid": ["camera.resolution"]}
    )
    assert c.known_limits[0]["when"] == {"camera.resolution": "80x60"}


def _row(status, failed="", resolution=None, scenario="follow_person"):
    return {
        "scenario": scenario,
        "seed": 0,
        "status": status,
        "failed_checks": failed,
        "camera.resolution": resolution,
        "replay": f"replay {scenario} {resolution}",
        "na_checks": "",
        "checks_json": "[]",
        "message": "",
    }


def test_a_failure_is_explained_only_where_the_limit_applies():
    limits = load_campaign({**BASE, "known_limits": [LIMIT]}).known_limits
    at_limit = _row("fail", "found_min_fraction", "80x60")
    elsewhere = _row("fail", "found_min_fraction", None)
    also_other = _row("fail", "found_min_fraction;max_person_collisions", "80x60")
    assert explained(at_limit, limits)
    assert not explained(elsewhere, limits)
    assert not explained(also_other, limits)  # a second failed check is not explained
    assert campaign_passed([_row("pass"), at_limit], limits)
    assert not campaign_passed([_row("pass"), at_limit, elsewhere], limits)
    assert not campaign_passed([_row("pass"), at_limit], [])
    groups = failures_by_check([at_limit, elsewhere, also_other], limits)
    assert [r["replay"] for r in groups["found_min_fraction"]] == [elsewhere["replay"]]
    assert groups["max_person_collisions"] == [also_other]
    # A limit naming both checks explains the run that failed both.
    both = load_campaign(
        {
            **BASE,
            "known_limits": [{**LIMIT, "check": ["found_min_fraction", "max_person_collisions"]}],
        }
    ).known_limits
    assert explained(also_other, both) and not explained(elsewhere, both)


def test_the_report_shows_each_known_limit_with_its_reason(tmp_path):
    limits = load_campaign({**BASE, "known_limits": [LIMIT]}).known_limits
    rows = [_row("pass"), _row("fail", "found_min_fraction", "80x60")]
    rows[1]["recording"] = "recordings/abc123.rrd"  # a failing run's, as the sweep keeps it
    text = format_report(rows, ["camera.resolution"], limits)
    assert ("found_min_fraction (camera.resolution=80x60): 1 run(s): " + LIMIT["reason"]) in text
    assert "failures by check" not in text
    write_html(
        tmp_path / "report.html", rows, ["camera.resolution"], {"name": "t", "known_limits": limits}
    )
    page = (tmp_path / "report.html").read_text()
    assert "Known limits of the design" in page and LIMIT["reason"] in page
    assert "replay follow_person 80x60" in page
    # The known limit's table links the run's recording, as the failing runs' tables do.
    limit_table = page[page.index("Known limits of the design") : page.index("Failing runs")]
    assert "<a href='recordings/abc123.rrd'>abc123.rrd</a>" in limit_table


def test_the_shipped_robustness_campaigns_load():
    for name in ("robustness", "robustness_small"):
        data, path = read_campaign_file(name)
        c = load_campaign(data, source=str(path))
        assert c.runs and all(e["reason"] for e in c.known_limits)


@pytest.mark.slow
def test_robustness_small_passes_or_fails_only_at_known_limits(tmp_path):
    from fpga_robotics.sweep import run_campaign

    data, path = read_campaign_file("robustness_small")
    campaign = load_campaign(data, source=str(path))
    rows = run_campaign(campaign, tmp_path, workers=1, record="none", quiet=True)
    assert len(rows) == len(campaign.runs)
    bad = [
        r["replay"]
        for r in rows
        if not (r["status"] == "pass" or explained(r, campaign.known_limits))
    ]
    assert not bad, bad


def test_a_known_limit_on_a_list_value_matches_the_runs_with_it():
    # A colour axis: the row keeps the list as JSON text, the entry as a tuple.
    green, red = [0, 200, 0], [255, 0, 0]
    c = load_campaign(
        {
            "name": "t",
            "scenarios": ["follow_person"],
            "seeds": "0",
            "grid": {"people.0.shirt_color": [red, green]},
            "known_limits": [{**LIMIT, "when": {"people.0.shirt_color": green}}],
        }
    )
    rows = {}
    for spec in c.runs:
        outcome = {"status": "fail", "message": "", "summary": None, "wall_s": 0.0}
        row = make_row(spec, "id", "follow_person", outcome)
        row["failed_checks"] = "found_min_fraction"
        rows[tuple(dict(spec.overrides)["people.0.shirt_color"])] = row
    assert known_limit(rows[tuple(green)], "found_min_fraction", c.known_limits) is not None
    assert known_limit(rows[tuple(red)], "found_min_fraction", c.known_limits) is None
