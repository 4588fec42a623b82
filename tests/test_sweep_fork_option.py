"""``sweep --fork`` (the default) and ``--no-fork`` reach the campaign as its ``fork``."""

import pytest

from fpga_robotics.cli import sweep as cli
from fpga_robotics.cli.errors import UsageError


class _Ran(Exception):
    pass


@pytest.mark.parametrize(
    ("options", "fork"), [([], True), (["--fork"], True), (["--no-fork"], False)]
)
def test_fork_options_reach_the_campaign(tmp_path, monkeypatch, options, fork):
    (tmp_path / "c.toml").write_text('scenarios = ["follow_person"]\nbackend = "model"\n')
    monkeypatch.chdir(tmp_path)
    given = {}

    def run_campaign(_campaign, _out, **kwargs):
        given.update(kwargs)
        raise _Ran

    monkeypatch.setattr(cli, "run_campaign", run_campaign)
    with pytest.raises(_Ran):
        cli.main(["c.toml", "--out", "out", "--quiet", *options])
    assert given["fork"] is fork


def test_no_fork_does_not_go_with_bench():
    with pytest.raises(UsageError, match="--no-fork does not apply to it"):
        cli.main(["--bench", "--no-fork"])
