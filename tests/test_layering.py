"""The house rules of the code base, read from the source: dependencies point one way, the
gateware imports no host code, and nothing leans on Amaranth's private internals.

The layers, lowest first (a module may import its own layer and the ones below):

    fpga_robotics.hw   gateware (Amaranth only)
    fpga_robotics.sim  model, backends, world, camera, shared data types, file helpers
    fpga_robotics.viz  the rerun viewer
    fpga_robotics.*    the application: CLIs, closed loop, connectors, scenarios

Imports under ``if __name__ == "__main__":`` are exempt: that is how a library module keeps
its documented ``python -m`` alias while its CLI lives in the application layer.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Source folder -> installed package.
PACKAGE_DIRS = {"fpga_robotics": "fpga_robotics", "hw": "fpga_robotics.hw",
                "sim": "fpga_robotics.sim", "viz": "fpga_robotics.viz"}

#: Package prefix -> layer; the longest matching prefix decides.
LAYERS = {"fpga_robotics.hw": 0, "fpga_robotics.sim": 1, "fpga_robotics.viz": 2,
          "fpga_robotics": 3}
LAYER_NAMES = {0: "hw", 1: "sim", 2: "viz", 3: "application"}

#: Third-party host packages the gateware must never import.
HOST_PACKAGES = {"numpy", "pymunk", "cv2", "rerun", "scipy"}


def layer_of(module):
    best = max((p for p in LAYERS if module == p or module.startswith(p + ".")), key=len)
    return LAYERS[best]


def source_modules():
    """``(module name, path)`` of every Python file of the installed packages."""
    out = []
    for folder, package in PACKAGE_DIRS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            rel = path.relative_to(ROOT / folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            if folder == "fpga_robotics" and parts and parts[0] in ("hw", "sim", "viz"):
                continue  # not there: the repo keeps them at the top
            out.append((".".join([package, *parts]), path))
    return out


def _is_main_guard(node):
    test = node.test
    return (isinstance(node, ast.If) and isinstance(test, ast.Compare)
            and isinstance(test.left, ast.Name) and test.left.id == "__name__"
            and any(isinstance(c, ast.Constant) and c.value == "__main__"
                    for c in test.comparators))


def imports_of(module, path):
    """``(line, imported module)`` for every import in the file (at any depth), relative
    imports resolved, those under a ``__main__`` guard left out."""
    tree = ast.parse(path.read_text(), str(path))
    is_package = path.name == "__init__.py"
    base = module.split(".") if is_package else module.split(".")[:-1]
    found = []

    def visit(node):
        if isinstance(node, ast.If) and _is_main_guard(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            found.extend((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = base[: len(base) - (node.level - 1)]
                target = ".".join(anchor + ([node.module] if node.module else []))
            else:
                target = node.module
            found.append((node.lineno, target))
            if node.module is None or node.level == 0:  # "from . import x": x may be a module
                found.extend((node.lineno, f"{target}.{a.name}") for a in node.names)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def _is_module(name):
    """Whether ``name`` (inside fpga_robotics) is a module or package of the source tree."""
    return any(m == name for m, _ in source_modules())


def layering_violations():
    bad = []
    for module, path in source_modules():
        mine = layer_of(module)
        for line, target in imports_of(module, path):
            root = target.split(".")[0]
            if mine == 0 and root in HOST_PACKAGES:
                bad.append(f"{path.relative_to(ROOT)}:{line}: gateware imports host "
                           f"package {target}")
            if root != "fpga_robotics" or not _is_module(target):
                continue
            theirs = layer_of(target)
            if theirs > mine:
                bad.append(f"{path.relative_to(ROOT)}:{line}: {LAYER_NAMES[mine]} module "
                           f"{module} imports {LAYER_NAMES[theirs]} module {target}")
    return bad


def test_every_source_module_is_found():
    names = {m for m, _ in source_modules()}
    assert {"fpga_robotics.hw.top", "fpga_robotics.sim.models.follow_target", "fpga_robotics.viz.recorder",
            "fpga_robotics.loop", "fpga_robotics.sim.backends.cxxrtl"} <= names


def test_dependencies_point_one_way():
    assert layering_violations() == []


def test_the_checker_sees_an_upward_import(tmp_path):
    path = tmp_path / "x.py"
    path.write_text("import os\nfrom ...cli.errors import UsageError\n"
                    "def f():\n    from ..world import World\n"
                    "if __name__ == '__main__':\n    from ...run import main\n")
    found = imports_of("fpga_robotics.sim.backends.x", path)
    assert (2, "fpga_robotics.cli.errors") in found
    assert (4, "fpga_robotics.sim.world") in found
    assert all(t != "fpga_robotics.run" for _, t in found)  # the __main__ alias is exempt
    assert layer_of("fpga_robotics.cli.errors") > layer_of("fpga_robotics.sim.backends.x")


@pytest.mark.parametrize("needle", ["amaranth._", "_MustUse__", "._engine"])
def test_no_private_amaranth_internals(needle):
    hits = []
    for _module, path in source_modules():
        for n, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#", 1)[0]
            if needle in code and not (needle == "amaranth._" and "amaranth._" not in code):
                hits.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert hits == []
