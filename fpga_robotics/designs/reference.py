"""Design references: one text names the design a run simulates, wherever it is taken
(``[design] top``, ``run --design``, a campaign's ``design.top`` axis, ``fpga-robotics
designs``).

A reference is one of

- a built-in name: ``follow_target``, ``follow_target_safe``, ``follow_line``;
- a name an installed package registers in the entry-point group ``fpga_robotics.designs``
  (``name = "package.module:Name"``);
- ``path/to/file.py:Name`` or ``package.module:Name``: an Amaranth ``wiring.Component``
  class, or a function returning one, called with the ``[design.params]`` values as keyword
  arguments;
- ``verilog:TOP.v[,MORE.v...]``: a Verilog design with its port map (docs/foreign.md).

Ports bind by declaration (docs/your_design.md): a component's ``connectors`` attribute,
``{kind: {connector pin: port}}``, binds the pins it names; a connector kind whose pins are all
ports of the same names binds by that convention (``motor_left``/``motor_right`` are the
wheels, ``pixels``/``color_sel`` the camera, ``trig``/``echo`` an ultrasound, ``pressed`` a
bumper, ``line`` line sensors). Every output no connector reads, other than FollowTarget's
per-frame outputs, is an extra output: recorded under its own name.
"""

import contextlib
import difflib
import enum
import functools
import hashlib
import importlib
import importlib.metadata
import importlib.util
import inspect
import re
import sys
import traceback
import types
import typing
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from fpga_robotics.designs.builtin import TOPS, Top, build_component, design_tables, foreign_top
from fpga_robotics.hw.errors import USER_CODE_ERRORS, UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.connectors import CONNECTORS

__all__ = [
    "ENTRY_POINT_GROUP",
    "FRAME_OUTPUTS",
    "DesignError",
    "DesignSpec",
    "bindings_of",
    "design_parameters",
    "entry_point_designs",
    "extra_outputs_of",
    "is_builtin",
    "resolve_design",
    "stream_ports",
]

#: The entry-point group through which installed packages offer designs.
ENTRY_POINT_GROUP = "fpga_robotics.designs"
#: FollowTarget's per-frame outputs: trajectory columns of their own, not extra outputs.
FRAME_OUTPUTS = ("found", "proximity", "centroid_x", "centroid_leds")
#: Outputs the camera's stream machinery reads (the frame strobe, the filtered stream).
_STREAM_OUTPUTS = ("frame_done", "filtered__valid", "filtered__payload")
#: The camera's stream input ports, by Amaranth's naming of ``pixels: In(stream)``.
CAMERA_PORTS = ("pixels__valid", "pixels__payload")


class DesignError(UsageError, ValueError):
    """A design reference that cannot be resolved: the message says what and how to fix it."""


class _ParamError(DesignError):
    """A parameter ``key`` the design cannot take, ``text`` what is wrong with it: said for
    ``[design.params]``, or by ``said_for`` for the command-line option the parameters came
    from (``"--param"``)."""

    def __init__(self, key, text):
        self.key, self.text = key, text
        super().__init__(self.said_for(None))

    def said_for(self, option):
        where = f"design.params.{self.key}" if option is None else f"{option} {self.key}"
        how = (
            f"in [design.params] (or --set design.params.{self.key}=VALUE)"
            if option is None
            else f"as {option} {self.key}=VALUE"
        )
        # Not str.format: the text quotes the user's values, which may hold braces.
        return self.text.replace("{where}", where).replace("{how}", how)


@dataclass(frozen=True, eq=False)
class DesignSpec:
    """A resolved design reference.

    Attributes
    ----------
    reference : str
        The reference as resolved (a file path made absolute).
    kind : str
        ``"builtin"``, ``"amaranth"`` or ``"verilog"``.
    description : str
    ports : dict
        Port name -> (direction ``"in"``/``"out"``, width); empty for a Verilog design (its
        widths come from Verilator when it is built).
    bindings : dict
        Connector kind -> {connector pin: design port} (a Verilog design's camera
        ``pixels``: the ports of its stream, ``"valid/payload"``).
    extra_outputs : tuple
        The outputs no connector reads, recorded under their own names.
    params : dict
        The keyword arguments the component is built with.
    top : Top
        What the closed loop runs (``fpga_robotics.designs.builtin.Top``).
    port_map : PortMap or None
        A Verilog design's port map as read (``sim.backends.port_map.PortMap``).
    clocked : bool
        Whether it has a clock (an Amaranth design of one's own may have none).
    black_boxes : tuple
        The modules an Amaranth design of one's own instantiates (``Instance``) without
        defining them: Verilog or vendor cells no simulator here has.
    free_domains : tuple
        The clock domains an Amaranth design of one's own uses (``m.d.fast``) without defining
        them: Amaranth makes each an input clock ``fast_clk`` that nothing here drives.
    signed : frozenset
        The names of its ports of a signed shape (``ports`` has direction and width).
    netlist_digest : str
        An Amaranth design of one's own: sha256 of its elaborated netlist, what it is
        whatever its file imports or reads (a campaign's run identity hashes it).
    """

    reference: str
    kind: str
    description: str
    ports: dict
    bindings: dict
    extra_outputs: tuple
    params: dict = field(default_factory=dict)
    top: Top = None
    port_map: object = None
    clocked: bool = True
    black_boxes: tuple = ()
    free_domains: tuple = ()
    signed: frozenset = frozenset()
    netlist_digest: str = ""
    #: A Verilog design's parameters and `define macros (``VerilogOverrides``).
    overrides: object = None

    @property
    def camera(self):
        return "camera" in self.bindings

    def real_clock_reason(self):
        """Why the design runs in real-clock timing only, or None for a camera-only design,
        which compressed timing runs frame by frame (fpga_robotics.loop.pin_frames): it
        binds no connector but the camera and the wheels, has no input the camera does not
        drive, and raises a 1-bit ``frame_done`` once a frame, when its results are out."""
        others = [kind for kind in self.bindings if kind not in ("camera", "wheels")]
        if others:
            return f"it binds the {others[0]} connector"
        if not self.camera:
            return "it has no camera input"
        camera = {*stream_ports(self.bindings), *self.bindings["camera"].values()}
        inputs = [n for n, (d, _) in self.ports.items() if d == "in" and n not in camera]
        if inputs:
            return f"its input {inputs[0]!r} is not the camera's"
        if self.ports.get("frame_done") != ("out", 1):
            return "it has no 1-bit frame_done output to say when a frame's results are out"
        return None

    def require_clock(self):
        """``DesignError`` for a design without a clock (nothing in its ``sync`` domain), which
        ``mutate`` cannot judge (a run clocks it through loop/bindings.py's wrapper; an exported
        design need not have one)."""
        if not self.clocked:
            raise DesignError(
                f"design {self.reference!r} has no clock: nothing in its sync domain "
                "(m.d.sync). The mutation judges run the mutants through the design's clock, "
                "so give it at least one register"
            )

    def require_no_black_boxes(self):
        """``DesignError`` for a design with an ``Instance`` of a module it does not define:
        no simulator here has that module (pysim would read its outputs as 0)."""
        if self.black_boxes:
            raise DesignError(
                f"design {self.reference!r} instantiates {self.black_boxes[0]!r} (an "
                "Instance), which the simulators here cannot run: only export and board "
                "take it"
            )

    def require_defined_domains(self):
        """``DesignError`` for a design that uses a clock domain it does not define: no
        simulator or board here drives its clock, so its registers would never change."""
        if self.free_domains:
            name = self.free_domains[0]
            raise DesignError(
                f"design {self.reference!r} uses clock domain {name!r} (m.d.{name}) without "
                f"defining it, so nothing here clocks it (Amaranth makes it an input "
                f"{name}_clk): use m.d.sync, or define it (m.domains.{name} = "
                f"ClockDomain(...)) and drive its clock in the design"
            )

    def source_files(self):
        """The files a design of one's own was loaded from: its file, then the modules it
        imported beside it (a ``package.module:Name`` design: its module's file, then those of
        its package); none for a built-in or a Verilog design."""
        return design_source_files(self.reference) if self.kind == "amaranth" else ()

    def build(self):
        """A new Amaranth component of the design (a built-in one at its default
        parameters); not for Verilog designs, which Verilator builds."""
        if self.kind == "verilog":
            raise DesignError(f"design {self.reference!r} is Verilog: Verilator builds it")
        if self.kind == "builtin":
            return build_component(self.top, FollowTargetParams(), design_tables(self.top, {}))
        return self.top.component()


def is_builtin(reference):
    return reference in TOPS


def entry_point_designs():
    """Designs installed packages register: name -> ``"module:Name"``."""
    return {ep.name: ep.value for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)}


def resolve_design(reference, params=None, *, ports=None, base=None, option=None, defines=None):
    """The ``DesignSpec`` of ``reference`` built with ``params`` (``[design.params]``).

    ``ports`` is the port map of a ``verilog:`` reference; ``base`` the folder relative file
    paths are taken from (a scenario file's; default the current folder); ``option`` the
    command-line option ``params`` came from (``"--param"``; None: a scenario's
    ``[design.params]``), which errors about them name; ``defines`` a Verilog design's
    `define macros (``--define``). Raises ``DesignError`` (one line:
    what is wrong and how to fix it)."""
    if not isinstance(reference, str) or not reference.strip():
        raise DesignError(
            f"design.top must be a design reference (a built-in name, "
            f"FILE.py:Name, package.module:Name or verilog:FILE.v), got "
            f"{reference!r}"
        )
    params = dict(params or {})
    reference = reference.strip()
    if reference.startswith("verilog:"):
        return _verilog_spec(reference, ports, base, params, option, defines)
    if reference in TOPS:
        if params:
            given = option or "design.params"
            raise DesignError(
                f"{given}: the built-in design {reference!r} takes its "
                f"parameters from [design] and its own tables, not "
                f"{given} ({', '.join(sorted(params))})"
            )
        return _builtin_spec(TOPS[reference])
    reference = _own_reference(reference, base)
    frozen = tuple(sorted((k, _freeze(v)) for k, v in params.items()))
    key = (reference, frozen)
    cached = _OWN_SPECS.get(key)
    if cached is not None and _stamps(cached[0]) == cached[1]:
        return cached[2]
    try:
        spec = _amaranth_spec(reference, params)
    except _ParamError as exc:
        raise DesignError(exc.said_for(option)) from None
    files = _design_files(reference)
    _OWN_SPECS.pop(key, None)
    _OWN_SPECS[key] = (files, _stamps(files), spec)
    if len(_OWN_SPECS) > _OWN_SPECS_KEPT:
        del _OWN_SPECS[next(iter(_OWN_SPECS))]  # the least recently resolved
    return spec


def design_parameters(reference, base=None):
    """The ``[design.params]`` names ``reference`` takes, as ``{name: required}`` (required:
    it has no default); ``{}`` for a built-in or Verilog design (they take none), None for
    a design that takes any name (``**kwargs``). Raises ``DesignError`` as
    ``resolve_design`` does for a reference that does not load."""
    reference = str(reference).strip()
    if reference.startswith("verilog:") or reference in TOPS:
        return {}
    known, takes_any = _signature_parameters(_load_target(_own_reference(reference, base)))
    if takes_any:
        return None
    return {n: p.default is p.empty for n, p in known.items()}


def _own_reference(reference, base):
    """A design of one's own's reference as ``_amaranth_spec`` takes it: a file path made
    absolute (from ``base``), an installed design's name as its ``module:Name``."""
    installed = entry_point_designs()
    target = installed.get(reference, reference)
    if ":" not in target:
        raise DesignError(
            f"unknown design {reference!r}: give a built-in name ({', '.join(TOPS)}"
            f"{', ' + ', '.join(installed) if installed else ''}), FILE.py:Name, "
            f"package.module:Name or verilog:FILE.v"
        )
    where, _, name = target.rpartition(":")
    if not where.strip():
        raise DesignError(
            f"design {reference!r}: name the file or module before ':' "
            f"(FILE.py:{name or 'Name'} or package.module:{name or 'Name'})"
        )
    if where.endswith(".py"):
        path = Path(where).expanduser()
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        return f"{path.resolve()}:{name}"
    return target  # an installed design's name stands for its module:Name


def _freeze(value):
    """``value`` as part of a cache key: hashable, and unequal for values a design takes
    differently (``1``, ``1.0`` and ``True``; ``[1]`` and ``(1,)``)."""
    if isinstance(value, list | tuple):
        return type(value), tuple(map(_freeze, value))
    if isinstance(value, dict):
        return dict, tuple((k, _freeze(v)) for k, v in value.items())
    try:
        hash(value)
    except TypeError:  # an object from Python: the spec cached for it keeps it alive
        return type(value), id(value)
    return type(value), value


#: (reference, frozen params) of a design of one's own -> (the files its resolution read,
#: their ``_stamps`` then, its ``DesignSpec``): resolved again when any of them changed.
_OWN_SPECS = {}
_OWN_SPECS_KEPT = 64
#: A design file's path -> the files of the modules its last load imported beside it.
_IMPORTED_BESIDE = {}


def _design_files(reference):
    """The files a design of one's own was loaded from: its file and the modules it imported
    beside it (none for an installed design's module)."""
    where = reference.rpartition(":")[0]
    if not where.endswith(".py"):
        return ()
    where = str(Path(where))
    return (where, *_IMPORTED_BESIDE.get(where, ()))


def design_source_files(reference):
    """The source files of a resolved design of one's own (``DesignSpec.reference``, a
    scenario's ``top``): its file, then the modules it imported beside it, or a
    ``package.module:Name`` design's module, then its package's; none for a built-in name."""
    if reference in TOPS or reference.startswith("verilog:"):
        return ()
    return _design_files(reference) or _module_files(reference)


def _module_files(reference):
    """The files of a ``package.module:Name`` design: its module's, then those of the other
    modules loaded from its package's folder (a flat module's: the modules beside it), which
    it may import; a file written over them would lose the design's source."""
    module = sys.modules.get(reference.rpartition(":")[0])
    own = getattr(module, "__file__", None)
    if own is None:
        return ()
    root = sys.modules.get(module.__name__.partition(".")[0])
    if hasattr(root, "__path__") and getattr(root, "__file__", None):
        folder = Path(root.__file__).parent  # the package's, with its subpackages

        def mine(file):
            return folder in Path(file).parents
    else:
        folder = Path(own).parent  # a flat module's, without the folders below it

        def mine(file):
            return Path(file).parent == folder

    files = {f for m in list(sys.modules.values()) if (f := getattr(m, "__file__", None))}
    return (own, *sorted(f for f in files - {own} if mine(f)))


def _stamps(files):
    """What makes a cached resolution stale: its files' modification times and sizes (None:
    gone)."""
    stamps = []
    for file in files:
        try:
            stat = Path(file).stat()
            stamps.append((stat.st_mtime_ns, stat.st_size))
        except OSError:
            stamps.append(None)
    return tuple(stamps)


# Built-in designs ------------------------------------------------------------------------


#: id of a registered ``Top`` -> (the Top, its spec): ``register_top`` may replace a name.
_TOP_SPECS = {}


def _builtin_spec(registered):
    cached = _TOP_SPECS.get(id(registered))
    if cached is not None and cached[0] is registered:
        return cached[1]

    component = build_component(registered, FollowTargetParams(), design_tables(registered, {}))
    signed = signed_ports(component)
    ports = component_ports(component)
    bindings = bindings_of(component, ports, registered.bindings)
    extra = {n: n for n in extra_outputs_of(ports, bindings)}
    extra.update(registered.extra_outputs)
    top = Top(
        registered.name,
        registered.description,
        camera="camera" in bindings,
        tables=registered.tables,
        bindings=bindings,
        extra_outputs=extra,
        component=registered.component,
        takes_follow_target_params=registered.takes_follow_target_params,
    )
    spec = DesignSpec(
        registered.name,
        "builtin",
        registered.description,
        ports,
        bindings,
        tuple(extra),
        {},
        top,
        signed=signed,
    )
    _TOP_SPECS[id(registered)] = (registered, spec)
    return spec


# Amaranth designs of one's own ------------------------------------------------------------


def _amaranth_spec(reference, params):
    target = _load_target(reference)
    values = _check_params(target, params, reference)
    factory = functools.partial(_call, target, values, reference)
    component = factory()
    clocked, black_boxes, free_domains, netlist_digest = _check_elaborates(
        component, target, reference
    )
    signed = signed_ports(component)
    ports = component_ports(component)
    _check_port_names(ports, reference.rpartition(":")[2])
    _check_port_widths(ports, reference.rpartition(":")[2])
    bindings = bindings_of(component, ports)
    extra = extra_outputs_of(ports, bindings)
    # Its own docstring only: a class without one would show wiring.Component's.
    own = target.__dict__.get("__doc__") if inspect.isclass(target) else target.__doc__
    doc = (inspect.cleandoc(own) if own else "").strip().splitlines()
    description = doc[0] if doc else f"the Amaranth design {reference.rpartition(':')[2]}"
    name = reference.rpartition(":")[2]
    top = Top(
        name,
        description,
        camera="camera" in bindings,
        bindings=bindings,
        extra_outputs={n: n for n in extra},
        component=factory,
        takes_follow_target_params=False,
    )
    return DesignSpec(
        reference,
        "amaranth",
        description,
        ports,
        bindings,
        extra,
        params,
        top,
        clocked=clocked,
        black_boxes=black_boxes,
        free_domains=free_domains,
        signed=signed,
        netlist_digest=netlist_digest,
    )


def _takes_platform(component):
    """Whether the component's ``elaborate`` can be called as Amaranth calls it."""
    try:
        inspect.signature(component.elaborate).bind(None)
    except TypeError:
        return False
    return True


def _check_elaborates(component, target, reference):
    """``DesignError`` (one line) if ``component``, made by the user's ``target``, does not
    elaborate to a netlist: its ``elaborate`` raises or returns nothing, or it drives a
    signal from two places or one of its input ports, or defines its own ``sync`` domain.
    Found here, before any simulator is built for it. Returns whether it has a clock
    (anything in its ``sync`` domain), the modules it instantiates without defining them (its
    ``Instance``s) and the netlist's sha256."""
    from amaranth.back import rtlil  # lazy: only a design of one's own is converted here
    from amaranth.hdl import Fragment, UnusedElaboratable  # lazy: as rtlil

    from fpga_robotics.hw.verilog import directed_ports, verilog_ports  # lazy: as rtlil

    # Its ports as export and the board have them: each in its declared direction, so that
    # an input the design drives is a conflict here too, not only when exported.
    ports = directed_ports(component)
    declared = verilog_ports(component)
    inputs = {id(value): name for name, (value, flow) in declared.items() if flow == "i"}
    try:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            fragment = Fragment.get(component, None)
            own_sync = _defines_sync(fragment)  # before the conversion adds the outer one
            driven = _driven_input(fragment, inputs)
            if driven is None:
                text = rtlil.convert(fragment, ports=ports)
    except USER_CODE_ERRORS as exc:  # the user's elaborate may raise anything
        # The modules its elaborate made are never used now: no warning for each at exit.
        warnings.filterwarnings("ignore", category=UnusedElaboratable)
        # What Amaranth said on the way ("elaborate() returned None; missing return?").
        hint = next((f"; {w.message}" for w in said if w.category is UserWarning), "")
        if type(exc).__name__ == "CombinationalCycle":
            hint += "; break the loop with a register (m.d.sync) on one of its signals"
        if isinstance(exc, TypeError) and not _takes_platform(component):
            hint += "; Amaranth calls elaborate(self, platform): add the platform argument"
        raise DesignError(
            f"design {reference!r} does not elaborate: {type(exc).__name__}: "
            f"{_first_line(exc)}{_user_line(exc, target)}{hint}"
        ) from None
    if driven is not None:
        port, (file, line) = driven
        raise DesignError(
            f"design {reference!r} drives its input port {port!r} ({Path(file).name}:{line}): "
            "an In port is driven by its connector; declare it Out(...) or drive another signal"
        )
    for w in said:  # a design that elaborates keeps its warnings
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if own_sync:
        # Amaranth would leave its clock undriven here and refuse it beside the board's.
        raise DesignError(
            f"design {reference!r} defines its own 'sync' clock domain (m.domains.sync); the "
            "simulators and the board drive its sync domain (ports clk and rst, a synchronous "
            "reset): leave the definition out and use m.d.sync"
        )
    clocked = bool(re.search(r"^  wire .*\binput \d+ +\\clk$", text, re.MULTILINE))
    # Cells of a type that is no $ primitive and no module of its own netlist.
    defined = set(re.findall(r"^module \\(\S+)$", text, re.MULTILINE))
    used = re.findall(r"^ +cell \\(\S+) ", text, re.MULTILINE)
    black_boxes = tuple(dict.fromkeys(name for name in used if name not in defined))
    # A domain used and defined nowhere: Amaranth makes its clock an input NAME_clk of the top.
    top = text[: text.index("\nend\n")]
    free = tuple(
        name.removesuffix("_clk")
        for name in re.findall(r"^  wire width 1 input \d+ +\\(\S+_clk)$", top, re.MULTILINE)
        if name not in declared
    )
    return clocked, black_boxes, free, hashlib.sha256(text.encode()).hexdigest()


def _driven_input(fragment, inputs):
    """``(port, src_loc)``: the first assignment in ``fragment`` or a module below it to an
    input port (``inputs``, ``{id(signal): port}``), with its line; None if none."""
    for statements in fragment.statements.values():
        for statement in _assignments(statements):
            for signal in statement._lhs_signals():
                if id(signal) in inputs:
                    return inputs[id(signal)], statement.src_loc
    for subfragment, _, _ in fragment.subfragments:
        found = _driven_input(subfragment, inputs)
        if found is not None:
            return found
    return None


def _assignments(statements):
    """The statements of a list, those inside ``m.If``/``m.Switch`` cases in their place."""
    from amaranth.hdl._ast import Switch  # lazy: as rtlil

    for statement in statements:
        if isinstance(statement, Switch):
            for _, case, _ in statement.cases:
                yield from _assignments(case)
        else:
            yield statement


def _defines_sync(fragment):
    """Whether ``fragment`` or one below it defines a ``sync`` domain that is not local."""
    domain = fragment.domains.get("sync")
    if domain is not None and not domain.local:
        return True
    return any(_defines_sync(sub) for sub, *_ in fragment.subfragments)


def _check_port_names(ports, name):
    """``DesignError`` if a port of design ``name`` is named ``clk`` or ``rst``: those are the
    clock domain's own ports, and Amaranth would rename the design's (``clk$3``)."""
    taken = [port for port in ("clk", "rst") if port in ports]
    if taken:
        raise DesignError(
            f"design {name!r} has a port named {taken[0]!r}, the name of the clock domain's "
            f"own {'clock' if taken[0] == 'clk' else 'reset'}; rename the port"
        )


#: The widest port the pin backends (and so every run) take: a C++ uint64_t.
MAX_PORT_WIDTH = 64


def _check_port_widths(ports, name):
    """``DesignError`` if a port of design ``name`` is wider than ``MAX_PORT_WIDTH``: no run
    could take the design, so every command says so when it resolves it."""
    wide = next(((port, w) for port, (_, w) in ports.items() if w > MAX_PORT_WIDTH), None)
    if wide:
        raise DesignError(
            f"design {name!r}: port {wide[0]!r} is {wide[1]} bits; the simulators take ports "
            f"of at most {MAX_PORT_WIDTH} bits: split it into narrower ports"
        )


def _user_line(exc, target):
    """`` (file.py:LINE)``: where in the design's own file ``exc`` was raised ("" if not
    there)."""
    try:
        source = inspect.getsourcefile(target)
    except TypeError:
        return ""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if f.filename == source]
    return f" ({Path(source).name}:{frames[-1].lineno})" if frames else ""


def _load_target(reference):
    where, _, name = reference.rpartition(":")
    if not name.isidentifier():
        raise DesignError(
            f"design {reference!r}: {name!r} is not a Python name; write "
            f"FILE.py:ClassName or package.module:ClassName"
        )
    if where.endswith(".py"):
        module = _load_file(Path(where), reference)
    else:
        try:
            module = _import_module(where)
        except ModuleNotFoundError as exc:
            raise DesignError(
                f"design {reference!r}: no module {exc.name!r} in the current folder or the "
                f"installed packages; install the package, run in the folder that holds it, "
                f"or give the file as path/to/file.py:{name}"
            ) from None
        except USER_CODE_ERRORS as exc:  # the user's module may raise anything
            # A module of a package named from inside the package's folder (top:Name).
            file = Path.cwd() / f"{where.replace('.', '/')}.py"
            hint = _package_hint(exc, file, name) if file.is_file() else ""
            raise DesignError(
                f"design {reference!r}: importing {where} raised "
                f"{type(exc).__name__}: {_first_line(exc)}{hint}"
            ) from None
    target = getattr(module, name, None)
    if target is None:
        found = sorted(
            n
            for n, v in vars(module).items()
            if _is_component_class(v) and v.__module__ == module.__name__
        )
        raise DesignError(
            f"design {reference!r}: {where} has no {name!r}"
            + (f"; its components: {', '.join(found)}" if found else "")
        )
    if not _is_factory(target):
        # A callable object (a data.StructLayout, a built component) is no design either.
        raise DesignError(
            f"design {reference!r}: {name} is a {type(target).__name__}, not a "
            f"wiring.Component class or a function returning one"
            + ("; name its class" if _is_component(target) else "")
        )
    if inspect.isclass(target) and not _is_component_class(target):
        raise DesignError(
            f"design {reference!r}: class {name} is not an Amaranth "
            f"wiring.Component; derive it from amaranth.lib.wiring.Component"
        )
    return target


def _import_module(name):
    """Import the module of a ``package.module:Name`` reference as ``python -m fpga_robotics``
    finds it, with the current folder on the path: the ``fpga-robotics`` script's path lacks
    it. Last on the path, so that nothing installed is hidden by a folder of the same name."""
    folder = str(Path.cwd())
    added = folder not in sys.path and "" not in sys.path
    if added:
        sys.path.append(folder)
    try:
        return importlib.import_module(name)
    finally:
        if added:
            sys.path.remove(folder)


def _load_file(path, reference):
    if not path.is_file():
        raise DesignError(
            f"design {reference!r}: no file {str(path)!r}; give the path of "
            f"a .py file (a relative path is taken from the current folder, or in a "
            f"scenario file from that file's folder)"
        )
    # A module name of its own per file, so that two files of one name do not collide.
    name = "fpga_robotics_user_design_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        with _importing_beside(path):
            spec.loader.exec_module(module)
    except USER_CODE_ERRORS as exc:  # the user's file may raise anything
        sys.modules.pop(name, None)
        line = _error_line(exc, path)
        raise DesignError(
            f"design {reference!r}: loading {path.name}{line} raised "
            f"{type(exc).__name__}: {_first_line(exc)}"
            f"{_package_hint(exc, path, reference.rpartition(':')[2])}"
        ) from None
    return module


def _package_hint(exc, path, name):
    """How to name a file of a package that imports relatively (``from .parts import X``):
    loaded as a file, it has no package."""
    if not (isinstance(exc, ImportError) and "relative import" in str(exc)):
        return ""
    parts = [path.stem]
    folder = path.parent
    while (folder / "__init__.py").is_file():
        parts.insert(0, folder.name)
        folder = folder.parent
    if len(parts) == 1:
        return ""
    return (
        f"; {path.name} is a module of the package {parts[0]!r}: name it "
        f"{'.'.join(parts)}:{name}, running in {str(folder)!r} (or install the package)"
    )


@contextlib.contextmanager
def _importing_beside(path):
    """The folder of the design file ``path`` first on ``sys.path`` while it loads, so that it
    imports the modules beside it (``from helper import Latch``) wherever the command runs.
    The modules it so imports are then forgotten by name: another design's ``helper.py``, or
    this one's after an edit, is imported afresh (the design keeps what it imported)."""
    folder = path.parent
    known = {name.partition(".")[0] for name in sys.modules}
    sys.path.insert(0, str(folder))
    imported = []
    try:
        yield
    finally:
        sys.path.remove(str(folder))
        for name, module in list(sys.modules.items()):
            origin = getattr(getattr(module, "__spec__", None), "origin", None)
            if name.partition(".")[0] not in known and origin and folder in Path(origin).parents:
                del sys.modules[name]
                imported.append(origin)
        # An edit of one of them makes the design's cached resolution stale (_OWN_SPECS).
        _IMPORTED_BESIDE[str(path)] = tuple(imported)


def _error_line(exc, path):
    if isinstance(exc, SyntaxError) and exc.lineno:
        return f" (line {exc.lineno})"
    tb = exc.__traceback__
    line = None
    while tb is not None:
        if Path(tb.tb_frame.f_code.co_filename) == path:
            line = tb.tb_lineno
        tb = tb.tb_next
    return f" (line {line})" if line else ""


def _first_line(exc):
    """The first line of ``exc``'s message; a first line that ends with a colon introduces a
    list (Amaranth's combinational cycle, signal by signal), which is kept on the line."""
    lines = [line.strip() for line in str(exc).strip().splitlines() if line.strip()]
    if not lines:
        return "(no message)"
    if lines[0].endswith(":") and len(lines) > 1:
        return f"{lines[0]} {'; '.join(lines[1:])}"
    return lines[0]


def _is_factory(value):
    """A class, a function or a method (a ``functools.partial`` of one): what a design
    reference may name."""
    if isinstance(value, functools.partial):
        value = value.func
    return inspect.isclass(value) or inspect.isroutine(value)


def _is_component(value):
    from amaranth.lib import wiring  # lazy: Amaranth (~0.3 s)

    return isinstance(value, wiring.Component)


def _is_component_class(value):
    from amaranth.lib import wiring  # lazy: Amaranth (~0.3 s)

    return inspect.isclass(value) and issubclass(value, wiring.Component)


def _check_params(target, params, reference):
    """``params`` against the signature of ``target``: known names, required ones given,
    each value of its annotation's (or default's) type. Returns them as the design takes
    them: an enum member by its name, an array as the list or tuple its parameter is, an
    integer as a float parameter's float."""
    known, takes_any = _signature_parameters(target)
    name = reference.rpartition(":")[2]
    values = dict(params)
    for key, value in params.items():
        if key not in known:
            if takes_any:
                continue
            close = difflib.get_close_matches(str(key), list(known), n=1, cutoff=0.7)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise _ParamError(
                key,
                f"{{where}}: {name} takes no parameter {key!r}{hint}; it takes: "
                f"{', '.join(known) or 'none'}",
            )
        parameter = known[key]
        annotation, optional = _annotation(parameter)
        if value is None and (optional or parameter.default is None):
            continue
        if typing.get_origin(annotation) is typing.Literal:
            choices = typing.get_args(annotation)
            # 1 is not True, nor 1.0 a choice of 1: the value's type is the choice's.
            if not any(type(value) is type(c) and value == c for c in choices):
                raise _ParamError(
                    key,
                    f"{{where}} must be one of {', '.join(map(repr, choices))} (a parameter "
                    f"of {name}), got {value!r}",
                )
            continue
        expected = _expected_type(parameter)
        if expected is None:
            continue
        if issubclass(expected, enum.Enum):
            values[key] = _enum_member(value, expected)
            if values[key] is None:
                raise _ParamError(
                    key,
                    f"{{where}} must be one of {', '.join(expected.__members__)} (a parameter "
                    f"of {name}), got {value!r}",
                )
        elif not _fits(value, expected):
            raise _ParamError(
                key,
                f"{{where}} must be {_type_name(expected)} (a parameter of {name}), got {value!r}",
            )
        elif expected is float:
            values[key] = float(value)
        elif expected in (list, tuple):
            items = _items(annotation, value)
            if items is None:
                raise _ParamError(
                    key,
                    f"{{where}} must be {_items_name(annotation)} (a parameter of {name}), "
                    f"got {value!r}",
                )
            values[key] = expected(items)
    missing = [n for n, p in known.items() if p.default is p.empty and n not in params]
    if missing:
        raise _ParamError(
            missing[0],
            f"design {reference!r}: parameter {missing[0]!r} has no default; give it {{how}}",
        )
    return values


def _signature_parameters(target):
    """``(known, takes_any)``: the parameters ``target`` takes by name ({name:
    inspect.Parameter}) and whether it takes any other (``**kwargs``, or a signature
    Python cannot read)."""
    try:
        # Annotations written as text (``from __future__ import annotations``) as the types
        # they name, where the design's module can name them.
        signature = inspect.signature(target, eval_str=True)
    except USER_CODE_ERRORS:  # evaluating them runs the user's code
        try:
            signature = inspect.signature(target)
        except (TypeError, ValueError):
            return {}, True
    from amaranth.lib import wiring  # lazy: Amaranth (~0.3 s)

    if inspect.isclass(target) and target.__init__ is wiring.Component.__init__:
        # Its signature is in its annotations: Component's own arguments are not its params.
        signature = inspect.Signature()
    known = {
        n: p
        for n, p in signature.parameters.items()
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    }
    takes_any = any(p.kind == p.VAR_KEYWORD for p in signature.parameters.values())
    return known, takes_any


def _annotation(parameter):
    """``(annotation, optional)``: the parameter's annotation without ``None`` (of
    ``Optional[X]``, ``X | None``) and whether it takes ``None``."""
    annotation = parameter.annotation
    if isinstance(annotation, str):  # from __future__ import annotations
        annotation = {
            "int": int,
            "float": float,
            "bool": bool,
            "str": str,
            "list": list,
            "tuple": tuple,
        }.get(annotation)
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = typing.get_args(annotation)
        others = [a for a in args if a is not type(None)]
        if len(others) == 1:
            return others[0], len(others) < len(args)
        return typing.Any, type(None) in args  # a union of several types: not checked
    return annotation, False


def _items(annotation, value):
    """The items of the array ``value`` as ``list[X]``, ``tuple[X, ...]`` or ``tuple[X, Y]``
    take them (a float item's integer as a float), or None when one does not fit; any items
    for a bare ``list`` or ``tuple`` or an item type that is not checked."""
    args = typing.get_args(annotation)
    if not args:
        return list(value)
    if typing.get_origin(annotation) is tuple and not (len(args) == 2 and args[1] is ...):
        if len(args) != len(value):
            return None
        kinds = args
    else:
        kinds = [args[0]] * len(value)
    items = []
    for item, kind in zip(value, kinds, strict=True):
        if kind in (int, float, bool, str) and not _fits(item, kind):
            return None
        items.append(float(item) if kind is float else item)
    return items


def _items_name(annotation):
    args = typing.get_args(annotation)
    names = {int: "integers", float: "numbers", bool: "true or false values", str: "strings"}
    if typing.get_origin(annotation) is tuple and not (len(args) == 2 and args[1] is ...):
        kinds = [_type_name(a) if a in names else getattr(a, "__name__", str(a)) for a in args]
        return f"an array of {len(args)} items ({', '.join(kinds)})"
    return f"an array of {names[args[0]]}"


def _expected_type(parameter):
    annotation = _annotation(parameter)[0]
    if annotation is typing.Any:
        return None
    annotation = typing.get_origin(annotation) or annotation  # list[int] is a list
    if annotation in (int, float, bool, str, list, tuple) or _is_enum(annotation):
        return annotation
    default = parameter.default
    if default is not parameter.empty and default is not None:
        kind = type(default)
        if kind in (int, float, bool, str, list, tuple) or _is_enum(kind):
            return kind
    return None


def _is_enum(kind):
    return inspect.isclass(kind) and issubclass(kind, enum.Enum)


def _enum_member(value, kind):
    """The member of the enum ``kind`` that ``value`` is or names (``NAME`` or
    ``Kind.NAME``); None if none."""
    if isinstance(value, kind):
        return value
    if isinstance(value, enum.Enum) and type(value).__qualname__ == kind.__qualname__:
        # The same enum from the user's own import of the design's file (a module apart
        # from the one loaded here): its member of the same name.
        return kind.__members__.get(value.name)
    if isinstance(value, str):
        return kind.__members__.get(value.removeprefix(f"{kind.__name__}."))
    return None


def _fits(value, expected):
    if expected is bool:
        return isinstance(value, bool)
    if isinstance(value, bool):
        return False
    if expected is float:
        return isinstance(value, (int, float))
    if expected in (list, tuple):
        return isinstance(value, (list, tuple))
    return isinstance(value, expected)


def _type_name(kind):
    return {
        int: "an integer",
        float: "a number",
        bool: "true or false",
        str: "a string",
        list: "an array",
        tuple: "an array",
    }[kind]


def _call(target, params, reference):
    """``target(**params)``, the component it returns (an error names what went wrong)."""
    from amaranth.lib import wiring  # lazy: Amaranth (~0.3 s)

    try:
        component = target(**params)
    except USER_CODE_ERRORS as exc:  # the user's constructor may raise anything
        raise DesignError(
            f"design {reference!r}: building it raised {type(exc).__name__}: "
            f"{_first_line(exc)}{_user_line(exc, target)}"
        ) from None
    if not isinstance(component, wiring.Component):
        raise DesignError(
            f"design {reference!r}: it returned {type(component).__name__}, "
            f"not an Amaranth wiring.Component"
        )
    if not hasattr(component, "signature"):  # made by wiring.Component.__init__
        from amaranth.hdl import UnusedElaboratable  # lazy: Amaranth (~0.3 s)

        # It is never elaborated now: no warning for it at exit.
        warnings.filterwarnings("ignore", category=UnusedElaboratable)
        raise DesignError(
            f"design {reference!r}: {type(component).__name__} has no signature: its "
            "__init__ must call super().__init__() (wiring.Component's), which makes its ports"
        )
    return component


def component_ports(component):
    """Port name (as the generated Verilog names it) -> (direction, width). The component
    was only looked at: it is marked so that Amaranth does not warn it was never used."""
    from amaranth.hdl import Fragment  # lazy: Amaranth (~0.3 s)

    from fpga_robotics.hw.verilog import verilog_ports  # lazy: Amaranth (~0.3 s)

    ports = {
        name: ("in" if direction == "i" else "out", value.shape().width)
        for name, (value, direction) in verilog_ports(component).items()
    }
    # Elaborated once, so that neither it nor the submodules its constructor made warn
    # when collected unused (a design that cannot elaborate fails when built for a run).
    with contextlib.suppress(Exception):
        Fragment.get(component, None)
    return ports


def signed_ports(component):
    """The names (as ``component_ports`` gives them) of the component's signed ports."""
    from fpga_robotics.hw.verilog import verilog_ports  # lazy: Amaranth (~0.3 s)

    return frozenset(
        name for name, (value, _) in verilog_ports(component).items() if value.shape().signed
    )


def _connector_pins():
    """Connector kind -> its pin names (the camera's stream is its ``pixels`` pin)."""
    return {kind: tuple(cls.pins) for kind, cls in CONNECTORS.items()}


def bindings_of(component, ports, given=None):
    """Connector kind -> {pin: port}: ``given`` and the component's declared ``connectors``
    (a declared camera without ``color_sel`` takes an input of that name), then every kind
    whose pins are all ports of the same names (the camera: ``pixels`` a stream input,
    ``color_sel`` when it has one)."""
    name = type(component).__name__
    declared = getattr(component, "connectors", None) or {}
    if not isinstance(declared, dict):
        raise DesignError(
            f"{name}.connectors must be a dict {{kind: {{pin: port}}}}, got {declared!r}"
        )
    declared = {**declared, **(given or {})}
    kinds = _connector_pins()
    bindings = {}
    for kind, pins in declared.items():
        if kind not in kinds:
            raise DesignError(
                f"{name}.connectors: unknown connector kind "
                f"{kind!r}; known: {', '.join(sorted(kinds))}"
            )
        if not isinstance(pins, dict):
            raise DesignError(
                f"{name}.connectors[{kind!r}] must be a dict {{pin: port}}, got {pins!r}"
            )
        for pin, port in pins.items():
            if pin not in kinds[kind]:
                raise DesignError(
                    f"{name}.connectors[{kind!r}]: the "
                    f"{kind} connector has no pin {pin!r}; its pins: "
                    f"{', '.join(kinds[kind])}"
                )
            if kind == "camera" and pin == "pixels":
                _check_stream(
                    port,
                    ports,
                    f"{name}.connectors['camera']['pixels']: {port!r} is no pixel stream "
                    f"input of {name}",
                )
                continue
            if port not in ports:
                raise DesignError(
                    f"{name}.connectors[{kind!r}][{pin!r}]: "
                    f"no port {port!r}; its ports: {', '.join(ports)}"
                )
        bindings[kind] = dict(pins)
    camera = bindings.get("camera")
    if (
        camera is not None
        and "color_sel" not in camera
        and ports.get("color_sel", ("",))[0] == "in"
    ):
        # A declaration that names the stream only: color_sel binds by its name all the same.
        camera["color_sel"] = "color_sel"
    for kind, pins in kinds.items():
        if kind in bindings:
            continue
        if kind == "camera":
            if all(ports.get(p, ("",))[0] == "in" for p in CAMERA_PORTS):
                _check_stream(
                    "pixels",
                    ports,
                    f"design {name}: port 'pixels' is not the camera's pixel stream",
                )
                bindings[kind] = {
                    "pixels": "pixels",
                    **({"color_sel": "color_sel"} if "color_sel" in ports else {}),
                }
            elif _inputs_named(ports, "pixels"):
                # An input named pixels meant for the camera, of some other shape.
                _check_stream(
                    "pixels",
                    ports,
                    f"design {name}: port 'pixels' is not the camera's pixel stream",
                )
            elif all(ports.get(p, ("",))[0] == "out" for p in CAMERA_PORTS):
                # pixels: Out(stream), the direction turned: the run would pass, seeing nothing.
                raise DesignError(
                    f"design {name}: port 'pixels' is an output stream; the camera streams "
                    "its frames into an input, pixels: "
                    "In(fpga_robotics.hw.pixel.pixel_stream_signature()): declare it In, or "
                    "give an output stream of its own another name"
                )
            elif ports.get("color_sel", ("",))[0] == "in":
                _refuse_partial(name, kind, ["color_sel"], ["pixels"])
        elif pins and all(p in ports for p in pins):
            bindings[kind] = {p: p for p in pins}
        else:
            # A typo or a forgotten pin would silently leave the whole connector unbound.
            spec = CONNECTORS[kind].pins
            present = [p for p in pins if ports.get(p, ("",))[0] == spec[p].direction]
            if present:
                _refuse_partial(name, kind, present, [p for p in pins if p not in ports])
    if "wheels" in bindings:
        _check_wheels(component, bindings["wheels"])
    if "camera" in bindings:
        _check_frame_outputs(component)
        select = bindings["camera"].get("color_sel")
        if select is not None and ports[select] != ("in", 3):
            # A narrower port lost the colour's high bits (red, 4, was refused mid-run).
            raise DesignError(
                f"design {name}: port {select!r} (the camera's color_sel) is "
                f"{ports[select][0]}put of {ports[select][1]} bits; the colour select is 3 "
                "bits: In(3) or In(fpga_robotics.hw.pixel.TargetColor) (docs/contract.md)"
            )
    return bindings


def _inputs_named(ports, port):
    """Whether the design has an input ``port``, or one of a stream ``port``'s members."""
    return any(
        direction == "in" and (name == port or name.startswith(f"{port}__"))
        for name, (direction, _width) in ports.items()
    )


def _refuse_partial(name, kind, present, missing):
    """``DesignError``: design ``name`` has some of connector ``kind``'s pins by name
    (``present``) but not the ``missing`` ones, so the connector binds none of them."""
    pins = CONNECTORS[kind].pins
    if kind == "camera":  # its color_sel is optional, its pixels a stream
        needed = ["pixels"]
        wanted = "pixels: In(fpga_robotics.hw.pixel.pixel_stream_signature())"
    else:
        needed = list(pins)
        wanted = ", ".join(f"{p}: {_pin_shape(pins[p])}" for p in missing)
    raise DesignError(
        f"design {name} has {', '.join(present)} but no {', '.join(missing)}: the {kind} "
        f"connector binds by name only when the design has {' and '.join(needed)}; add "
        f'{wanted}, or declare connectors = {{"{kind}": {{pin: port}}}} (docs/your_design.md)'
    )


def _pin_shape(pin):
    """The port a connector pin takes, as an Amaranth annotation: ``Out(signed(16))``."""
    shape = f"signed({pin.width})" if pin.signed else str(pin.width)
    return f"{'In' if pin.direction == 'in' else 'Out'}({shape})"


def _check_wheels(component, wheels):
    """``DesignError`` unless every wheel port is a signed output of at most the connector's
    16 bits (a narrower one is sign-extended, as a Verilog design's)."""
    from fpga_robotics.hw.verilog import verilog_ports  # lazy: Amaranth (~0.3 s)

    found = verilog_ports(component)
    for pin, spec in CONNECTORS["wheels"].pins.items():
        port = wheels.get(pin)
        if port not in found:
            continue
        value, direction = found[port]
        shape = value.shape()
        if direction != "o" or not shape.signed or shape.width > spec.width:
            kind = f"{'signed' if shape.signed else 'unsigned'}({shape.width})"
            raise DesignError(
                f"design {type(component).__name__}: port {port!r} (the wheels' {pin} pin) is "
                f"{'an output' if direction == 'o' else 'an input'} of {kind}; the wheels "
                f"take a signed output of at most {spec.width} bits, e.g. "
                f"Out(signed({spec.width}))"
            )


#: The shapes of FollowTarget's per-frame outputs (docs/contract.md): name -> width (None:
#: any), all unsigned. The runs read them by name, as these numbers.
FRAME_OUTPUT_WIDTHS = {"found": 1, "proximity": 3, "centroid_x": None, "centroid_leds": 8}


def _check_frame_outputs(component):
    """``DesignError`` unless each per-frame output a camera design has is of its contract
    shape, and comes with the 1-bit ``frame_done`` at which the runs read it: a run would
    judge a 2-bit ``found`` or a signed ``centroid_x`` as the contract's, and without the
    strobe never read them at all (their checks not measured, the run passing)."""
    from fpga_robotics.hw.verilog import verilog_ports  # lazy: Amaranth (~0.3 s)

    found = verilog_ports(component)
    design = type(component).__name__
    shapes = {
        "frame_done": (1, "the frame strobe"),
        **{name: (width, "the per-frame output") for name, width in FRAME_OUTPUT_WIDTHS.items()},
    }
    for name, (width, role) in shapes.items():
        if name not in found or found[name][1] != "o":
            continue
        shape = found[name][0].shape()
        if shape.signed or (width is not None and shape.width != width):
            kind = f"{'signed' if shape.signed else 'unsigned'}({shape.width})"
            wanted = f"Out({width})" if width is not None else "unsigned, Out(N)"
            raise DesignError(
                f"design {design}: port {name!r} is {kind}; {role} {name} is {wanted} "
                "(docs/contract.md): change its shape, or rename it to record it as an output "
                "of its own"
            )
    outputs = [n for n in FRAME_OUTPUT_WIDTHS if n in found and found[n][1] == "o"]
    if outputs and found.get("frame_done", (None, ""))[1] != "o":
        raise DesignError(
            f"design {design}: it has {', '.join(outputs)} but no frame_done output: the runs read "
            "the per-frame outputs when it rises; add frame_done: Out(1), high for one cycle "
            "when a frame's results are out, or rename them to record them as outputs of "
            "their own"
        )


def stream_ports(bindings):
    """``(valid, payload)``: the input ports of the camera's pixel stream as the bindings
    name it (``cam: In(stream)`` is ``cam__valid``/``cam__payload``); None without a camera."""
    camera = bindings.get("camera")
    if camera is None:
        return None
    name = camera.get("pixels", "pixels")
    return (f"{name}__valid", f"{name}__payload")


def _check_stream(port, ports, problem):
    """``DesignError`` saying ``problem`` unless ``port`` names a pixel stream input of the
    design: a 1-bit ``PORT__valid`` and a 14-bit ``PORT__payload``
    (``In(pixel_stream_signature())``)."""
    valid, payload, ready = f"{port}__valid", f"{port}__payload", f"{port}__ready"
    if ports.get(valid) == ("in", 1) and ports.get(payload) == ("in", 14):
        if ready not in ports:
            return
        # The camera streams a pixel a clock whatever the design says: pixels it is not
        # ready for would be lost without a word.
        raise DesignError(
            f"{problem}: it has a ready output, {ready}, and a camera does not wait; declare "
            "it In(fpga_robotics.hw.pixel.pixel_stream_signature()), a stream always ready"
        )
    raise DesignError(
        f"{problem} (ports {valid} of 1 bit and {payload} of 14 bits, "
        f"In(fpga_robotics.hw.pixel.pixel_stream_signature())); its ports: {', '.join(ports)}"
    )


def extra_outputs_of(ports, bindings):
    """The outputs no connector reads and that are not FollowTarget's per-frame outputs."""
    bound = {port for pins in bindings.values() for port in pins.values()}
    camera = "camera" in bindings
    return tuple(
        name
        for name, (direction, _width) in ports.items()
        if direction == "out"
        and name not in bound
        and not (camera and (name in FRAME_OUTPUTS or name in _STREAM_OUTPUTS))
    )


# Verilog designs ------------------------------------------------------------------------


def _verilog_spec(reference, ports, base, params, option, defines):
    from fpga_robotics.sim.backends.port_map import (  # lazy: the simulator (~0.5 s)
        PortMapError,
        load_port_map,
    )
    from fpga_robotics.sim.backends.verilog_params import VerilogOverrides  # lazy: as above

    files = [f for f in reference[len("verilog:") :].split(",") if f.strip()]
    if not files:
        raise DesignError(
            f"design {reference!r}: name the Verilog files, verilog:TOP.v[,MORE.v...]"
        )
    try:  # the names are checked against the design when Verilator reads it
        overrides = VerilogOverrides.of(params, defines)
    except PortMapError as exc:
        raise DesignError(str(exc)) from None
    resolved = []
    for text in files:
        path = Path(text).expanduser()
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        if not path.is_file():
            raise DesignError(f"design {reference!r}: no file {text!r} (looked for {str(path)!r})")
        resolved.append(str(path))
    if ports is None:
        raise DesignError(
            f"design {reference!r} needs its port map: --ports PORTS.toml "
            f"(or design.ports in the scenario; docs/foreign.md)"
        )
    try:
        port_map = load_port_map(ports)
    except PortMapError as exc:
        raise DesignError(f"design {reference!r}: {ports}: {exc}") from None
    top = foreign_top(port_map)
    # The design's own ports, as the map names them (top.bindings has the wrapper's names).
    camera = {}
    if port_map.has_pixels:
        stream = (port_map.valid, port_map.payload, port_map.data, port_map.first, port_map.last)
        if port_map.style == "framebuffer":
            stream = (port_map.valid, port_map.address, port_map.data, port_map.new_frame)
        camera["pixels"] = "/".join(p for p in stream if p)
        if port_map.color_port:
            camera["color_sel"] = port_map.color_port
    wheels = {
        k: port_map.outputs[k].port for k in ("motor_left", "motor_right") if k in port_map.outputs
    }
    bindings = {
        **{k: v for k, v in top.bindings.items() if k not in ("camera", "wheels")},
        **({"camera": camera} if camera else {}),
        **({"wheels": wheels} if wheels else {}),
    }
    return DesignSpec(
        "verilog:" + ",".join(resolved),
        "verilog",
        f"the Verilog design {port_map.top} (port map {ports})",
        {},
        bindings,
        (),
        {},
        top,
        port_map,
        overrides=overrides,
    )
