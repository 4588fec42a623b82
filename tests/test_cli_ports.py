"""``fpga-robotics ports``: writes the exported follow_target's port map (never over a file),
checks a port map, and reports a bad one as one line with exit code 2."""

import pytest

from fpga_robotics import cli


def _ports(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["ports", *argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_example_is_written_and_then_checked(tmp_path, capsys):
    path = tmp_path / "ports.toml"
    code, out, err = _ports(["--example", str(path)], capsys)
    assert (code, out, err) == (0, f"wrote {path}\n", "")
    code, out, err = _ports([str(path)], capsys)
    assert code == 0, err
    # The six per-frame outputs of follow_target, as docs/foreign.md lists them.
    assert out == (f"{path}: follow_target, outputs found, proximity, centroid_x, "
                   "centroid_leds, motor_left, motor_right\n")


def test_example_never_replaces_a_file(tmp_path, capsys):
    path = tmp_path / "ports.toml"
    path.write_text("keep me\n")
    code, out, err = _ports(["--example", str(path)], capsys)
    assert code == 2 and out == ""
    assert err.startswith(f"fpga-robotics ports: error: cannot write {path}") and \
        err.count("\n") == 1
    assert path.read_text() == "keep me\n"


@pytest.mark.parametrize("text, word", [
    ("style = \n", "not valid TOML"),
    ('style = "pixels"\n', "style"),
])
def test_a_bad_port_map_is_one_line(text, word, tmp_path, capsys):
    path = tmp_path / "ports.toml"
    path.write_text(text)
    code, out, err = _ports([str(path)], capsys)
    assert code == 2 and out == ""
    assert err.startswith("fpga-robotics ports: error: ") and err.count("\n") == 1
    assert word in err
