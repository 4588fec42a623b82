"""The viewer package never prints (it returns notices for the application to show): checked
on the source, so that a new print anywhere in viz/ fails here. Its imports are checked with
every other module's in test_layering.py."""

import ast
import pathlib
import subprocess
import sys

import pytest

VIZ = pathlib.Path(__file__).resolve().parent.parent / "viz"


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


SOURCES = sorted(VIZ.glob("*.py"))


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.name)
def test_viz_never_prints(source):
    tree = ast.parse(source.read_text())
    for node in _library_nodes(tree):
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print":
            pytest.fail(f"{source.name}:{node.lineno} prints; return a notice instead")
        if isinstance(node, ast.Attribute) and node.attr in ("stderr", "stdout"):
            assert getattr(node.value, "id", None) != "sys", f"{source.name}:{node.lineno}"


def test_the_viewer_commands_run_from_the_application(tmp_path):

    for args in (["bench", "viewer", "--help"], ["readback"]):
        proc = subprocess.run(
            [sys.executable, "-m", "fpga_robotics", *args],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
            cwd=tmp_path,
        )
        if args[0] == "bench":
            assert proc.returncode == 0 and "--frames" in proc.stdout, proc.stderr
        else:  # a usage error: one line, exit 2
            assert proc.returncode == 2, proc.stderr
            assert proc.stderr.startswith("fpga-robotics readback: error: "), proc.stderr
            assert proc.stderr.count("\n") == 1, proc.stderr
