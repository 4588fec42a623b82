"""``fpga-robotics new NAME``: a project skeleton in folder NAME — an Amaranth design, a
scenario it passes, a pytest test of that scenario (``fpga_robotics.testing``) and a README.

The files come from the package's ``templates/new/`` (``${name}`` becomes the folder's name).
They are written into a hidden folder next to NAME first and moved into place at the end, so
a failure leaves nothing behind; an existing folder that is not empty is refused.
"""

import os
import re
import shutil
import string
import sys
import tempfile
from importlib import metadata, resources
from pathlib import Path

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.sim.files import default_dir_mode

__all__ = ["main", "write_project"]

#: Template (in ``templates/new/``, plus ``.tmpl``) -> the file it becomes. The test module is
#: named after the project: two projects' tests in one pytest session (from a folder above
#: both) would otherwise be two modules ``test_scenario``, which pytest refuses to collect.
_TEMPLATES = {
    "design.py": "design.py",
    "scenario.toml": "scenario.toml",
    "README.md": "README.md",
    "pyproject.toml": "pyproject.toml",
    "tests/test_scenario.py": "tests/test_${name}.py",
}
#: A project's name: a Python name (the folder is importable from the folder above, as
#: ``python -m`` runs there), and a scenario name (it names the run's recording).
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


def _shadowed_module(name):
    """The installed or standard module a folder called ``name`` would hide from Python run in
    the folder above it (``python -m`` puts that folder first on the path), or None."""
    installed = {"fpga_robotics", "test", *sys.stdlib_module_names}
    installed.update(metadata.packages_distributions())
    return name if name in installed else None


def _template(relative):
    return (
        resources.files("fpga_robotics.cli") / "templates" / "new" / f"{relative}.tmpl"
    ).read_text(encoding="utf-8")


def write_project(folder):
    """Write the skeleton into ``folder`` (absent or empty); return the files written."""
    # Path("") is '.', which would be refused as "folder '.' exists and is not empty".
    if not str(folder).strip():
        raise UsageError("the project's folder NAME is empty; give one, e.g. my_robot")
    folder = Path(folder)
    name = folder.resolve().name
    if not _NAME.fullmatch(name):
        raise UsageError(
            f"{str(folder)!r}: the project's name {name!r} must be a Python name: ASCII "
            f"letters, digits and '_' (at most 64), not starting with a digit"
        )
    if _shadowed_module(name):
        raise UsageError(
            f"{str(folder)!r}: a project named {name!r} would hide the module {name} from "
            f"Python run in the folder above it (python -m fpga_robotics...); choose another name"
        )
    if folder.exists():
        if not folder.is_dir():
            raise UsageError(f"{str(folder)!r} exists and is not a folder; give a new name")
        if any(folder.iterdir()):
            raise UsageError(
                f"folder {str(folder)!r} exists and is not empty; give a new name or empty it"
            )
    parent = folder.resolve().parent
    if not parent.is_dir():
        raise UsageError(f"no folder {str(parent)!r} to create {name!r} in; create it first")
    if not os.access(parent, os.W_OK):
        raise UsageError(f"folder {str(parent)!r} is not writable")
    written = [string.Template(t).substitute(name=name) for t in _TEMPLATES.values()]
    try:  # os.access says yes to root, where a read-only mount or /sys still refuses
        staging = Path(tempfile.mkdtemp(prefix=f".{name}.", dir=parent))
    except OSError as exc:
        raise UsageError(
            f"cannot write in {str(parent)!r} ({exc.strerror}); choose another place"
        ) from None
    try:
        for template, relative in zip(_TEMPLATES, written, strict=True):
            text = string.Template(_template(template)).safe_substitute(name=name)
            target = staging / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")
        os.chmod(staging, default_dir_mode())  # mkdtemp's folder is private
        if folder.exists():
            folder.rmdir()  # empty: checked above
        staging.rename(folder)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return [folder / r for r in written]


def main(argv=None, prog="fpga-robotics new"):
    p = CommandParser(
        prog=prog,
        description="Write a project skeleton: an Amaranth design (design.py), a "
        "scenario it passes (scenario.toml), a pytest test of it and a README. "
        "Then: cd NAME && python -m pytest",
    )
    p.add_argument("name", metavar="NAME", help="the project's folder (new or empty)")
    args = p.parse_args(argv)
    for path in write_project(args.name):
        print(f"wrote {path}")
    print(f"next: cd {args.name} && python -m pytest")
    return 0


if __name__ == "__main__":  # python -m fpga_robotics.cli.new: as fpga-robotics new
    from fpga_robotics.cli import run_command

    run_command("new")
