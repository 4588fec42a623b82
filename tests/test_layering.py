"""The house rules of the code base, read from the source: imports point downwards through the
rooms of docs/architecture.md, no two modules import each other (directly or round a circle),
the gateware imports no host code, and nothing leans on Amaranth's private internals.

Every import counts: at the top of a module, inside a function, under
``if __name__ == "__main__":``, and the module named by a string literal in
``importlib.import_module("...")``. Importing ``a.b.c`` runs ``a/__init__.py`` and
``a/b/__init__.py`` too, so a circle may close through a package's ``__init__``; a name a
package hands out on first use (a module-level ``__getattr__``, PEP 562) is a dependency of
the module that takes it. Imports sit at the top of their module; one left inside a function
says why on its line, ``# lazy: <reason>`` (an optional dependency, a heavy one most commands
skip); a circle is no reason: it is reported wherever its imports sit.
"""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Source folder -> installed package.
PACKAGE_DIRS = {
    "fpga_robotics": "fpga_robotics",
    "hw": "fpga_robotics.hw",
    "sim": "fpga_robotics.sim",
    "viz": "fpga_robotics.viz",
}

#: The rooms, top first: a module may import its own room and the rooms below it. A module's
#: room is the one with the longest prefix that matches its name (docs/architecture.md).
ROOMS = [
    (
        "aliases",
        (
            "fpga_robotics.__main__",
            "fpga_robotics.run",
            "fpga_robotics.export",
            "fpga_robotics.formal",
            "fpga_robotics.bench.__main__",
            "fpga_robotics.mutation.__main__",
            "fpga_robotics.sweep.__main__",
        ),
    ),
    ("cli", ("fpga_robotics.cli",)),
    ("bench", ("fpga_robotics.bench",)),
    ("mutation", ("fpga_robotics.mutation",)),
    ("sweep", ("fpga_robotics.sweep",)),
    ("testing", ("fpga_robotics.testing",)),
    ("run command", ("fpga_robotics.cli.run",)),
    ("flow", ("fpga_robotics.flow",)),
    ("scenario", ("fpga_robotics.scenario",)),
    ("loop", ("fpga_robotics.loop",)),
    ("designs", ("fpga_robotics.designs",)),
    ("connectors", ("fpga_robotics.loop.connectors",)),
    ("ros", ("fpga_robotics.ros",)),
    ("checks", ("fpga_robotics.checks",)),
    (
        "cli support",
        (
            "fpga_robotics.cli.errors",
            "fpga_robotics.cli.parser",
            "fpga_robotics.cli.param_options",
            "fpga_robotics.cli.sensor_options",
        ),
    ),
    ("package", ("fpga_robotics",)),
    ("viz", ("fpga_robotics.viz",)),
    ("sim", ("fpga_robotics.sim",)),
    ("hw", ("fpga_robotics.hw",)),
]

#: Third-party host packages the gateware must never import.
HOST_PACKAGES = {"numpy", "pymunk", "cv2", "rerun", "scipy", "mujoco", "rosbags", "dask"}


def room_of(module, rooms=ROOMS):
    """``(height, room name)`` of ``module``: 0 is the bottom room."""
    best = None
    for height, (name, prefixes) in enumerate(reversed(rooms)):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and (
                best is None or len(prefix) > best[0]
            ):
                best = (len(prefix), height, name)
    return best[1:] if best else (None, None)


def source_modules(root=ROOT, package_dirs=PACKAGE_DIRS):
    """``{module name: path}`` of every Python file of the installed packages."""
    out = {}
    for folder, package in package_dirs.items():
        for path in sorted((root / folder).rglob("*.py")):
            rel = path.relative_to(root / folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            if folder == "fpga_robotics" and parts and parts[0] in ("hw", "sim", "viz"):
                continue  # not there: the repository keeps them at the top
            out[".".join([package, *parts])] = path
    return out


def _is_main_guard(node):
    test = node.test
    return (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
        and any(isinstance(c, ast.Constant) and c.value == "__main__" for c in test.comparators)
    )


def _main_guard_lines(tree):
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and _is_main_guard(node):
            lines.update(range(node.lineno, node.end_lineno + 1))
    return lines


def _is_import_module_call(node):
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
    return (
        name in ("import_module", "__import__")
        and node.args
        and isinstance(node.args[0], ast.Constant)
        and isinstance(node.args[0].value, str)
    )


def _lazy_attribute_lines(tree):
    """The lines of a module-level ``def __getattr__`` (PEP 562): a package ``__init__`` that
    hands out a name this way imports its module only when the name is asked for."""
    lines = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == "__getattr__":
            lines.update(range(node.lineno, node.end_lineno + 1))
    return lines


def imports_of(module, path, modules):
    """``(line, imported module, under a __main__ guard, in a package's __getattr__)`` for
    every import in the file: ``from package import name`` is the module ``package.name``
    where that is a module of ``modules``, else ``package``; relative imports are resolved."""
    tree = ast.parse(path.read_text(), str(path))
    in_main = _main_guard_lines(tree)
    in_getattr = _lazy_attribute_lines(tree) if path.name == "__init__.py" else set()
    base = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    found = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = base[: len(base) - (node.level - 1)]
                package = ".".join(anchor + ([node.module] if node.module else []))
            else:
                package = node.module
            named = [f"{package}.{alias.name}" for alias in node.names]
            targets = [t for t in named if t in modules]
            if len(targets) < len(named):
                targets.append(package)
        elif isinstance(node, ast.Call) and _is_import_module_call(node):
            targets = [node.args[0].value]
        found.extend(
            (node.lineno, t, node.lineno in in_main, node.lineno in in_getattr) for t in targets
        )
    return found


def _project_module(name, modules):
    """The module of ``modules`` that importing ``name`` runs (its longest known prefix)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def _packages_run(module, imported, modules):
    """The project modules that importing ``imported`` from ``module`` runs: every package
    ``__init__`` on the way down (``a``, ``a.b`` for ``a.b.c``) and ``imported`` itself. The
    packages ``module`` lives in are left out (Python begins them before ``module``), unless
    ``imported`` is one of them: a name taken from that ``__init__``."""
    parts = imported.split(".")
    run = [".".join(parts[:n]) for n in range(1, len(parts))]
    own = {".".join(module.split(".")[:n]) for n in range(1, module.count(".") + 1)}
    if modules[module].name == "__init__.py":
        own.add(module)
    return [m for m in run if m in modules and m not in own] + [imported]


def import_graph(modules):
    """``{module: {imported project module: first line}}`` and the list of every import.
    Importing ``a.b.c`` depends on ``a/__init__``, ``a/b/__init__`` and ``a/b/c``, so a circle
    that closes through a package's ``__init__`` is a circle too."""
    found = {m: imports_of(m, path, modules) for m, path in modules.items()}
    # What a package's __getattr__ imports: a dependency of whoever takes names from it.
    on_request = {m: [] for m in modules}
    for module, imports in found.items():
        for _line, target, _in_main, in_getattr in imports:
            imported = _project_module(target, modules)
            if in_getattr and imported is not None and imported != module:
                on_request[module].append(imported)
    graph, every = {m: {} for m in modules}, []
    for module, imports in found.items():
        for line, target, in_main, in_getattr in imports:
            every.append((module, line, target, in_main))
            imported = _project_module(target, modules)
            if in_getattr or imported is None or imported == module:
                continue
            for runs in _packages_run(module, imported, modules):
                graph[module].setdefault(runs, line)
            for asked in on_request[imported] if target == imported else ():
                for runs in _packages_run(module, asked, modules):
                    graph[module].setdefault(runs, line)
    return graph, every


def circles(graph):
    """The import circles of ``graph``: Tarjan's strongly connected components of more than
    one module, each sorted, and a module that imports itself."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    for start in sorted(graph):
        if start in index:
            continue
        # Iterative depth-first search: (node, iterator over its successors).
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        work = [(start, iter(sorted(graph[start])))]
        while work:
            node, successors = work[-1]
            for nxt in successors:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph.get(nxt, ())))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return sorted(found)


def check(root=ROOT, package_dirs=PACKAGE_DIRS, rooms=ROOMS):
    """Every broken rule of the tree at ``root``, one line each."""
    modules = source_modules(root, package_dirs)
    graph, every = import_graph(modules)
    problems = []
    for module, line, target, in_main in every:
        where = f"{modules[module].relative_to(root)}:{line}"
        main_note = " (under __main__)" if in_main else ""
        mine, my_room = room_of(module, rooms)
        if my_room is None:
            problems.append(f"{where}: {module} is in no room of the table")
            continue
        if my_room == "hw" and target.split(".")[0] in HOST_PACKAGES:
            problems.append(f"{where}: gateware imports host package {target}{main_note}")
        imported = _project_module(target, modules)
        if imported is None or imported == module:
            continue
        theirs, their_room = room_of(imported, rooms)
        if theirs is not None and theirs > mine:
            problems.append(
                f"{where}: {my_room} module {module} imports {imported} of the "
                f"{their_room} room above it{main_note}"
            )
    for circle in circles(graph):
        ring = " -> ".join(circle + circle[:1])
        problems.append(f"import circle: {ring} (move what they share into a module below both)")
    return problems


_LAZY_REASON = re.compile(r"#\s*lazy:\s*\S")
_LAZY_CIRCLE = re.compile(r"#\s*lazy:.*\bcircle", re.IGNORECASE)


def _function_body_imports(tree):
    """Every ``import`` statement inside a function (or method) body of ``tree``."""
    found = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if in_function and isinstance(child, (ast.Import, ast.ImportFrom)):
                found.append(child)
            visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)))

    visit(tree, False)
    return found


def unexplained_lazy_imports(root=ROOT, package_dirs=PACKAGE_DIRS):
    """``path:line: statement`` of every import inside a function whose lines carry no
    ``# lazy: <reason>`` comment."""
    problems = []
    for path in source_modules(root, package_dirs).values():
        text = path.read_text()
        lines = text.splitlines()
        for node in _function_body_imports(ast.parse(text, str(path))):
            statement = lines[node.lineno - 1 : node.end_lineno]
            where = f"{path.relative_to(root)}:{node.lineno}"
            if not any(_LAZY_REASON.search(line) for line in statement):
                problems.append(f"{where}: {statement[0].strip()} (move it to the top, or say why)")
            elif any(_LAZY_CIRCLE.search(line) for line in statement):
                problems.append(
                    f"{where}: {statement[0].strip()} (a circle is no reason: remove it)"
                )
    return problems


def test_every_source_module_is_found_and_has_a_room():
    modules = source_modules()
    assert {
        "fpga_robotics.hw.top",
        "fpga_robotics.sim.models.follow_target",
        "fpga_robotics.viz.recorder",
        "fpga_robotics.loop",
        "fpga_robotics.cli.errors",
        "fpga_robotics.sim.backends.cxxrtl",
        "fpga_robotics.bench.__main__",
    } <= set(modules)
    assert [m for m in modules if room_of(m)[1] is None] == []
    assert room_of("fpga_robotics.loop.connectors.camera")[1] == "connectors"
    assert room_of("fpga_robotics.cli.errors")[1] == "cli support"
    assert room_of("fpga_robotics.cli.sweep")[1] == "cli"


def test_imports_point_downwards_and_never_round_a_circle():
    assert check() == []


def test_the_checker_reports_upward_imports_circles_and_main_blocks(tmp_path):
    files = {
        # an upward import at the top: the gateware imports the simulation
        "hw/top.py": "from fpga_robotics.sim import world\n",
        "hw/pure.py": "import numpy as np\n",
        "sim/__init__.py": "",
        "sim/world.py": "import math\n",
        # an upward import under the __main__ guard (a module keeping its own command line)
        "sim/tool.py": (
            "def f():\n    return 1\n\n"
            "if __name__ == '__main__':\n"
            "    from fpga_robotics.cli import main\n    main()\n"
        ),
        # an upward import by a string literal, inside a function
        "viz/plugin.py": (
            "import importlib\n\n"
            "def load():\n"
            "    return importlib.import_module('fpga_robotics.loop.a')\n"
        ),
        # a circle inside one room, one side importing inside a function
        "fpga_robotics/__init__.py": "",
        "fpga_robotics/cli/__init__.py": "def main():\n    pass\n",
        "fpga_robotics/loop/__init__.py": "",
        "fpga_robotics/loop/a.py": "from fpga_robotics.loop.b import g\n\ndef f():\n    g()\n",
        "fpga_robotics/loop/b.py": ("def g():\n    from . import a\n    return a\n"),
        # allowed: downwards, and its own room
        "fpga_robotics/loop/c.py": "from fpga_robotics.sim import world\nfrom . import b\n",
    }
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    problems = check(tmp_path)
    assert problems == [
        "hw/pure.py:1: gateware imports host package numpy",
        (
            "hw/top.py:1: hw module fpga_robotics.hw.top imports fpga_robotics.sim.world of the "
            "sim room above it"
        ),
        (
            "sim/tool.py:5: sim module fpga_robotics.sim.tool imports fpga_robotics.cli of the "
            "cli room above it (under __main__)"
        ),
        (
            "viz/plugin.py:4: viz module fpga_robotics.viz.plugin imports fpga_robotics.loop.a of "
            "the loop room above it"
        ),
        (
            "import circle: fpga_robotics.loop.a -> fpga_robotics.loop.b -> fpga_robotics.loop.a "
            "(move what they share into a module below both)"
        ),
    ]


def _tree(root, files):
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


_RING_ADVICE = " (move what they share into a module below both)"


def test_a_circle_through_a_package_init_is_a_circle(tmp_path):
    # backends' tool imports the camera's frames, which runs the camera package's __init__,
    # which imports the renderer, which imports the tool back: a circle that no two modules
    # close by naming each other, held only by an import inside a function.
    files = {
        "sim/__init__.py": "",
        "sim/cam/__init__.py": "from .raster import render\n",
        "sim/cam/raster.py": (
            "def render():\n    from ..back.tool import build  # lazy: circle\n    return build\n"
        ),
        "sim/cam/frames.py": "import math\n",
        "sim/back/__init__.py": "",
        "sim/back/tool.py": "from ..cam import frames\n\ndef build():\n    return frames\n",
    }
    assert check(_tree(tmp_path, files)) == [
        "import circle: fpga_robotics.sim.back.tool -> fpga_robotics.sim.cam -> "
        "fpga_robotics.sim.cam.raster -> fpga_robotics.sim.back.tool" + _RING_ADVICE
    ]


def test_a_package_name_handed_out_on_use_depends_its_taker_only(tmp_path):
    lazy_init = (
        "def __getattr__(name):\n"
        "    from . import raster  # lazy: on use\n"
        "    return getattr(raster, name)\n"
    )
    files = {
        "sim/__init__.py": "",
        "sim/cam/__init__.py": lazy_init,
        "sim/cam/raster.py": "from ..back import tool\n",
        "sim/cam/frames.py": "",
        "sim/back/__init__.py": "",
        "sim/back/tool.py": "from ..cam import frames\n",
    }
    assert check(_tree(tmp_path, files)) == []
    # Taking the renderer's name from the package does depend on the renderer.
    (tmp_path / "sim/back/tool.py").write_text("from ..cam import render\n")
    assert check(tmp_path) == [
        "import circle: fpga_robotics.sim.back.tool -> fpga_robotics.sim.cam.raster -> "
        "fpga_robotics.sim.back.tool" + _RING_ADVICE
    ]


def test_circles_finds_every_ring_and_nothing_else():
    graph = {
        "a": {"b"},
        "b": {"c"},
        "c": {"a"},
        "d": {"a", "e"},
        "e": {"d"},
        "f": {"a"},
        "g": set(),
    }
    assert circles(graph) == [["a", "b", "c"], ["d", "e"]]
    assert circles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("needle", ["amaranth._", "_MustUse__", "._engine"])
def test_no_private_amaranth_internals(needle):
    hits = []
    for path in source_modules().values():
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if needle in line.split("#", 1)[0]:
                hits.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert hits == []


def test_imports_inside_functions_say_why():
    assert unexplained_lazy_imports() == []


def test_the_checker_reports_function_imports_without_a_reason(tmp_path):
    files = {
        "sim/__init__.py": "",
        "sim/plain.py": (
            "import json\n\n"
            "if __name__ == '__main__':\n    import sys\n"  # module level: not in a function
            "def dump(x):\n    import pickle\n    return pickle.dumps(x)\n"
        ),
        "sim/explained.py": (
            "def load():\n"
            "    import mujoco  # lazy: optional dependency\n"
            "    from numpy import (  # lazy: heavy\n        zeros,\n    )\n"
            "    return mujoco, zeros\n"
            "def cycle():\n    from . import plain  # lazy: circle via the package init\n"
        ),
        "viz/nested.py": (
            "class Viewer:\n"
            "    def open(self):\n"
            "        def inner():\n            from . import other\n"
            "        return inner\n\n"
            "async def serve():\n    import rerun  # lazy:\n"  # a reason must follow
            "    # lazy: a comment on another line does not count\n    import os\n"
        ),
        "viz/other.py": "",
    }
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    problems = unexplained_lazy_imports(tmp_path, {"sim": "fpga_robotics.sim", "viz": "viz"})
    assert problems == [
        (
            "sim/explained.py:8: from . import plain  # lazy: circle via the package init "
            "(a circle is no reason: remove it)"
        ),
        "sim/plain.py:6: import pickle (move it to the top, or say why)",
        "viz/nested.py:4: from . import other (move it to the top, or say why)",
        "viz/nested.py:8: import rerun  # lazy: (move it to the top, or say why)",
        "viz/nested.py:10: import os (move it to the top, or say why)",
    ]
