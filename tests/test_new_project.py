"""``fpga-robotics new NAME``: a skeleton that passes its own test at once, run as a user runs
it (``cd NAME && python -m pytest``); an existing non-empty folder refused, nothing written."""

import os
import stat
import subprocess
import sys

import pytest

from fpga_robotics import cli


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def test_the_skeleton_passes_its_own_test(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = _cli(["new", "rover"], capsys)
    assert code == 0 and "next: cd rover && python -m pytest" in out
    project = tmp_path / "rover"
    assert sorted(p.relative_to(project).as_posix() for p in project.rglob("*") if p.is_file()) == [
        "README.md",
        "design.py",
        "pyproject.toml",
        "scenario.toml",
        "tests/test_rover.py",
    ]
    assert 'name = "rover"' in (project / "scenario.toml").read_text()
    assert not [p for p in tmp_path.iterdir() if p.name != "rover"]  # no staging folder left
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed" in done.stdout


def test_two_projects_collect_in_one_pytest_session(tmp_path, capsys, monkeypatch):
    # From a folder above both (a repository of several designs): each test module is named
    # after its project, or pytest would refuse the second `test_scenario` module.
    monkeypatch.chdir(tmp_path)
    for name in ("rover", "crawler"):
        assert _cli(["new", name], capsys)[0] == 0
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"]
        + ["rover", "crawler"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "test_rover.py::test_stops_at_the_wall" in done.stdout
    assert "test_crawler.py::test_stops_at_the_wall" in done.stdout
    assert "2 tests collected" in done.stdout


def test_the_project_folder_gets_the_mode_of_a_plain_mkdir(tmp_path, capsys, monkeypatch):
    # Readable as the umask allows, as its tests/ folder is (not mkdtemp's private 0700).
    monkeypatch.chdir(tmp_path)
    umask = os.umask(0o027)
    try:
        assert _cli(["new", "shared"], capsys)[0] == 0
    finally:
        os.umask(umask)
    for folder in (tmp_path / "shared", tmp_path / "shared" / "tests"):
        assert stat.S_IMODE(folder.stat().st_mode) == 0o750, folder


def test_the_skeleton_test_fails_when_the_design_breaks(tmp_path, monkeypatch, capsys):
    # The skeleton's test is not a formality: a design that never stops fails it.
    monkeypatch.chdir(tmp_path)
    assert _cli(["new", "broken"], capsys)[0] == 0
    design = tmp_path / "broken" / "design.py"
    design.write_text(design.read_text().replace("self.stopped.eq(1)", "self.stopped.eq(0)"))
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"],
        cwd=tmp_path / "broken",
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 1
    assert "[fail] max_wall_collisions" in done.stdout


def test_a_non_empty_folder_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "taken").mkdir()
    (tmp_path / "taken" / "notes.txt").write_text("mine")
    code, out, err = _cli(["new", "taken"], capsys)
    assert code == 2 and out == ""
    assert err.strip() == (
        "fpga-robotics new: error: folder 'taken' exists and is not empty; "
        "give a new name or empty it"
    )
    assert [p.name for p in (tmp_path / "taken").iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]
    for bad in ("bad name!", "my-robot", "v1.2", "3rd"):
        code, _, err = _cli(["new", bad], capsys)
        assert code == 2 and "must be a Python name" in err and len(err.splitlines()) == 1, bad
    # A project folder named after a module hides it from Python run in the folder above.
    for module in ("fpga_robotics", "amaranth", "numpy", "test", "json"):
        code, _, err = _cli(["new", module], capsys)
        assert code == 2 and len(err.splitlines()) == 1, module
        assert f"would hide the module {module}" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]
    # An empty name was the current folder: "folder '.' exists and is not empty".
    code, _, err = _cli(["new", ""], capsys)
    assert code == 2 and err.strip() == (
        "fpga-robotics new: error: the project's folder NAME is empty; give one, e.g. my_robot"
    )
    # An empty folder is taken.
    (tmp_path / "empty").mkdir()
    assert _cli(["new", "empty"], capsys)[0] == 0
    assert (tmp_path / "empty" / "design.py").is_file()


def test_a_folder_that_refuses_the_project_is_one_line(tmp_path, capsys, monkeypatch):
    # os.access says a folder is writable to root, where a read-only mount or /sys still
    # refuses: the staging folder's mkdir raised PermissionError with a traceback (exit 1).
    def refuse(**kwargs):
        raise PermissionError(1, "Operation not permitted", kwargs["dir"])

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("fpga_robotics.cli.new.tempfile.mkdtemp", refuse)
    code, out, err = _cli(["new", "rover"], capsys)
    assert (code, out) == (2, "")
    assert err == (
        f"fpga-robotics new: error: cannot write in {str(tmp_path.resolve())!r} (Operation not "
        "permitted); choose another place\n"
    )
    assert list(tmp_path.iterdir()) == []
