"""The viewer package depends only downwards (hw <- sim <- viz <- application) and never prints:
checked on the source, so that a new import or print anywhere in viz/ fails here."""

import ast
import pathlib

import pytest

VIZ = pathlib.Path(__file__).resolve().parent.parent / "viz"
ALLOWED = ("fpga_robotics.hw", "fpga_robotics.sim", "fpga_robotics.viz")


def _is_main_guard(node):
    # `if __name__ == "__main__":` -- the one place a module run as a script may call the CLI.
    test = node.test
    return (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
        and any(isinstance(c, ast.Constant) and c.value == "__main__" for c in test.comparators)
    )


def _library_nodes(tree):
    """Every node outside `if __name__ == "__main__":` blocks."""
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        if isinstance(node, ast.If) and _is_main_guard(node):
            continue
        yield node
        stack.extend(ast.iter_child_nodes(node))


def _imported(node, module):
    """Absolute names of the modules an import node brings in (relative ones resolved)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if isinstance(node, ast.ImportFrom):
        if node.level == 0:
            return [node.module]
        base = module.split(".")[: -node.level] if node.level else []
        return [".".join(base + ([node.module] if node.module else []))]
    return []


SOURCES = sorted(VIZ.glob("*.py"))


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.name)
def test_viz_imports_only_lower_layers(source):
    module = f"fpga_robotics.viz.{source.stem}"
    tree = ast.parse(source.read_text())
    for node in _library_nodes(tree):
        for name in _imported(node, module):
            if name == "fpga_robotics" or name.startswith("fpga_robotics."):
                assert name.startswith(ALLOWED), f"{source.name}:{node.lineno} imports {name}"


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.name)
def test_viz_never_prints(source):
    tree = ast.parse(source.read_text())
    for node in _library_nodes(tree):
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print":
            pytest.fail(f"{source.name}:{node.lineno} prints; return a notice instead")
        if isinstance(node, ast.Attribute) and node.attr in ("stderr", "stdout"):
            assert getattr(node.value, "id", None) != "sys", f"{source.name}:{node.lineno}"


def test_the_viewer_commands_run_from_the_application(tmp_path):
    import subprocess
    import sys

    for args in (["bench", "viewer", "--help"], ["readback"]):
        proc = subprocess.run(
            [sys.executable, "-m", "fpga_robotics", *args],
            capture_output=True, text=True, timeout=120, check=False, cwd=tmp_path,
        )
        if args[0] == "bench":
            assert proc.returncode == 0 and "--frames" in proc.stdout, proc.stderr
        else:  # a usage error: one line, exit 2
            assert proc.returncode == 2, proc.stderr
            assert proc.stderr.startswith("fpga-robotics readback: error: "), proc.stderr
            assert proc.stderr.count("\n") == 1, proc.stderr
