"""The unit judge of a design on pins: each mutant against the unmutated design on the same
pin stimulus, cycle by cycle.

The stimulus is seeded random: every input port (``mutsel`` aside) changes, at each clock
edge with probability ``CHANGE_PROBABILITY``, to a new random value of its width, so a bit
holds for a few cycles on average and long enough now and then for counters and pulse
measurements to see it. A camera design's pixel stream (``pixels__valid``,
``pixels__payload``, or the ports its camera binding names) carries frames instead, as the
camera gives them: random RGB444 pixels in raster order at one a cycle, the first pixel
flagged ``first`` and each line's last ``last``, a line's time without pixels between
frames, for as many frames as the cycles hold.

The mutant netlist (every mutant behind ``mutsel``) is compiled once as a Verilator pin
model (sim/pins); each run starts from a reset with ``mutsel`` held, applies the same
stimulus (``schedule_many``), and records every change of every output (the model's own
run loop, ``record_changes``).
``mutsel = 0`` gives the reference. A mutant is *caught* when any output's changes differ
from the reference's (a value, or the cycle it came at).
"""

import functools
import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..hw.verilog import TOP_NAME
from ..sim.mutation import MUTATION_SELECT, mutant_netlist, select_width
from ..sim.pins.base import Port
from ..sim.pins.compiled import VerilatorPins

__all__ = [
    "CHANGE_PROBABILITY",
    "MutantPinSource",
    "PinStimulus",
    "PinVerdict",
    "judge_pin_mutant",
    "open_pin_mutants",
    "pin_stimulus",
    "pin_trace",
    "streams_frames",
]

#: The chance that an input takes a new random value at a clock edge.
CHANGE_PROBABILITY = 1 / 8
#: A camera design's pixel stream: (valid, payload) inputs.
STREAM_PORTS = ("pixels__valid", "pixels__payload")
#: The payload's flags above its RGB444 pixel.
_FIRST, _LAST = 1 << 12, 1 << 13


class MutantPinSource:
    """The mutant netlist of a design as a Verilog source for the Verilator pin backend: the
    design's ports (``ports``: name -> ``Port``) plus the ``mutsel`` input. Its outputs are
    read after the design settles (two evaluations an edge), as for any Verilog design."""

    pixels = filtered = frame_size = None
    registered_outputs = False
    verilog_top = TOP_NAME

    def __init__(self, rtlil_text, ports, mutants, name):
        self._rtlil, self._mutants = rtlil_text, list(mutants)
        width = select_width(max((m.index for m in mutants), default=0))
        self.ports = {**ports, MUTATION_SELECT: Port(MUTATION_SELECT, width, "in", False)}
        digest = hashlib.sha256((rtlil_text + "".join(m.command for m in mutants)).encode())
        self.key = f"mutants-{name}-{digest.hexdigest()[:12]}"

    @functools.cached_property
    def verilog(self):
        return mutant_netlist(None, self._mutants, rtlil_text=self._rtlil)

    def verilog_files(self):
        """``(files, compiled)``, as ``VerilogPinSource`` gives them."""
        return {"mutants.v": self.verilog}, ["mutants.v"]


def streams_frames(ports, stream=STREAM_PORTS):
    """Whether ``ports`` (name -> ``Port``) take a camera's pixel stream on ``stream``, its
    (valid, payload) inputs as the design binds them (None: no camera bound)."""
    return stream is not None and all(
        name in ports and ports[name].direction == "in" for name in stream
    )


def pin_stimulus(ports, cycles, seed, frame=None, stream=STREAM_PORTS):
    """``[(edge, input, value)]``: the seeded random changes of every input (``ports``:
    name -> ``Port``; ``mutsel`` left out) over ``cycles`` edges, in edge order; with
    ``frame`` (width, height) and a pixel stream on ``stream`` (``streams_frames``), frames
    of random pixels on it (module doc)."""
    rng = np.random.default_rng(seed)
    changes = []
    framed = frame is not None and streams_frames(ports, stream)
    for port in ports.values():
        if port.direction != "in" or port.name == MUTATION_SELECT:
            continue
        if framed and port.name in stream:
            continue
        edges = np.flatnonzero(rng.random(cycles) < CHANGE_PROBABILITY) + 1
        lo, hi = (
            (-(1 << (port.width - 1)), 1 << (port.width - 1))
            if port.signed
            else (0, 1 << port.width)
        )
        values = rng.integers(lo, hi, size=len(edges), dtype=np.int64)
        changes += [(int(e), port.name, int(v)) for e, v in zip(edges, values)]
    if framed:
        changes += _frames(rng, frame, cycles, stream)
    return PinStimulus(sorted(changes))


class PinStimulus(list):
    """A stimulus: ``(edge, input, value)`` changes in edge order, and the same grouped by
    input (``by_input``) as ``schedule_many`` takes them, once for every mutant."""

    @functools.cached_property
    def by_input(self):
        return _by_input(self)


def _by_input(changes):
    """``{input: (edges, values)}`` of ``changes``, each input's in edge order."""
    grouped = {}
    for edge, name, value in changes:
        grouped.setdefault(name, ([], []))
        grouped[name][0].append(edge)
        grouped[name][1].append(value)
    return {name: (np.array(e, np.int64), _values(v)) for name, (e, v) in grouped.items()}


def _values(values):
    """int64 where every value fits, else Python ints (a 64-bit unsigned input)."""
    try:
        return np.array(values, np.int64)
    except OverflowError:
        return np.array(values, object)


def _frames(rng, frame, cycles, stream):
    """The pixel stream's changes: frames of random pixels from edge 1 (module doc)."""
    width, height = frame
    valid, payload = stream
    flags = np.zeros(width * height, np.int64)
    flags[width - 1 :: width] |= _LAST
    flags[0] |= _FIRST
    changes, start = [], 1
    while start <= cycles:
        pixels = rng.integers(0, 1 << 12, size=width * height, dtype=np.int64) | flags
        shown = min(width * height, cycles - start + 1)
        changes.append((start, valid, 1))
        changes += [(start + k, payload, int(pixels[k])) for k in range(shown)]
        changes.append((start + width * height, valid, 0))
        start += width * (height + 1)  # a line's time without pixels between frames
    return [c for c in changes if c[0] <= cycles]


def pin_trace(backend, index, stimulus, cycles, outputs):
    """Mutant ``index`` (0: the design) on ``stimulus`` from a reset: ``{output: [(cycle,
    value), ...]}``, its value at cycle 0 and every change after."""
    backend.reset()
    backend.poke(MUTATION_SELECT, index)
    grouped = stimulus.by_input if isinstance(stimulus, PinStimulus) else _by_input(stimulus)
    for name, (edges, values) in grouped.items():
        backend.schedule_many(name, edges, values)
    trace = {name: [(0, backend.peek(name))] for name in outputs}
    for name, changes in backend.record_changes(cycles, list(outputs)).items():
        trace[name] += changes
    return trace


@dataclass
class PinVerdict:
    """What the unit judge found for one mutant on the pin stimulus."""

    index: int
    caught: bool
    first_cycle: int | None = None  # the first cycle at which an output differs
    differing: dict = field(default_factory=dict)  # output -> True if its changes differ
    first_difference: dict = field(default_factory=dict)  # output -> (design, mutant) there
    cycles: int = 0
    # output -> (cycles during which it differs, the largest difference of its values), for
    # each output that differs, and the cycles during which any output differs: what the
    # blind spots' reasons read (reasons.py).
    extent: dict = field(default_factory=dict)
    cycles_differing: int = 0

    def effect(self):
        if not self.caught:
            return f"no output differs in {self.cycles} cycles of random inputs"
        first = ", ".join(f"{k} {v[0]} -> {v[1]}" for k, v in self.first_difference.items())
        return f"differs from cycle {self.first_cycle}: {first}"


def _value_at(changes, cycle):
    value = changes[0][1]
    for at, v in changes:
        if at > cycle:
            break
        value = v
    return value


def _first_divergence(want, got):
    """The first cycle at which two change lists of one output give different values."""
    for (ca, va), (cb, vb) in zip(want, got):
        if (ca, va) != (cb, vb):
            return min(ca, cb)
    if len(want) != len(got):
        longer = want if len(want) > len(got) else got
        return longer[min(len(want), len(got))][0]
    return None


def _extent(want, got, cycles, port):
    """(the spans ``(start, end)`` of cycles in which two change lists of one output give
    different values, the largest difference of the values then), over cycles 0 to
    ``cycles - 1``; the values read as signed numbers when ``port`` (a ``Port``, or None)
    says so."""

    def number(value):
        # A signed port's changes come signed from the pin model; a raw pattern with its
        # sign bit set (a Verilog port read unsigned) is made so here.
        if port is not None and port.signed and value >= 0 and value >> (port.width - 1) & 1:
            return value - (1 << port.width)
        return value

    # Both lists walked once, in cycle order: an output may change every cycle.
    events = sorted([(at, 0, v) for at, v in want] + [(at, 1, v) for at, v in got])
    values = [want[0][1], got[0][1]]
    spans, largest, k = [], 0, 0
    while k < len(events) and events[k][0] < cycles:
        start = events[k][0]
        while k < len(events) and events[k][0] == start:
            values[events[k][1]] = events[k][2]
            k += 1
        end = min(events[k][0] if k < len(events) else cycles, cycles)
        if values[0] != values[1]:
            spans.append((start, end))
            largest = max(largest, abs(number(values[0]) - number(values[1])))
    return spans, largest


def _covered(spans):
    """Cycles in the union of ``spans``."""
    total, reach = 0, 0
    for start, end in sorted(spans):
        total += max(0, end - max(start, reach))
        reach = max(reach, end)
    return total


def judge_pin_mutant(backend, index, stimulus, cycles, reference, ports=None):
    """Mutant ``index`` against ``reference`` (``pin_trace`` of index 0): a ``PinVerdict``.
    ``ports`` (name -> ``Port``, optional) tells which outputs are signed."""
    got = pin_trace(backend, index, stimulus, cycles, reference)
    verdict = PinVerdict(index=index, caught=False, cycles=cycles)
    firsts, spans = {}, []
    for name, want in reference.items():
        at = _first_divergence(want, got[name])
        verdict.differing[name] = at is not None
        if at is not None:
            firsts[name] = at
            own, largest = _extent(want, got[name], cycles, (ports or {}).get(name))
            verdict.extent[name] = (sum(end - start for start, end in own), largest)
            spans += own
    verdict.cycles_differing = _covered(spans)
    if firsts:
        verdict.caught = True
        verdict.first_cycle = min(firsts.values())
        verdict.first_difference = {
            name: (
                _value_at(reference[name], verdict.first_cycle),
                _value_at(got[name], verdict.first_cycle),
            )
            for name, at in firsts.items()
            if at == verdict.first_cycle
        }
    return verdict


def open_pin_mutants(source, *, on_build=None):
    """The Verilator pin model of a ``MutantPinSource`` (built once, then from the cache)."""
    return VerilatorPins(source, on_build=on_build)
