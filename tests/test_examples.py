"""The example projects (examples/) as their READMEs say to run them: each folder copied to a
scratch folder outside the repository, then ``python -m pytest`` there, against the installed
package."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).parent.parent / "examples"


@pytest.mark.slow
@pytest.mark.parametrize("name, tests", [("amaranth_avoider", 4), ("verilog_ranger", 3)])
def test_an_example_passes_its_own_tests_from_a_scratch_folder(tmp_path, name, tests):
    project = tmp_path / name
    shutil.copytree(EXAMPLES / name, project, ignore=shutil.ignore_patterns("runs", "__pycache__"))
    readme = (project / "README.md").read_text()
    assert "python -m pytest" in readme
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
        check=False,
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert f"{tests} passed" in done.stdout
