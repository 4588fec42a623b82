"""A pin design's state as the calls that made it: journaled, replayed, played back.

A pin backend (fpga_robotics.sim.pins) cannot save its simulator's state, but a design is a
function of its inputs: the same pokes, schedules and pixel streams at the same edges bring a
reset design to the same state, bit for bit. So the real-clock loop talks to its design
through ``JournalPins``, which keeps every call in order with its answer (``Call``):

- ``replay(design, calls)`` brings a reset design to the state after ``calls`` (a world
  checkpoint's design part, fpga_robotics.loop.checkpoint) by re-running only the calls that
  change it, without the world;
- ``first_difference(design, calls)`` puts another design through the same calls and stops
  at the first whose answer differs (a wheel pin, a trigger, a frame output): up to there the
  loop would have done exactly the same with it (fpga_robotics.loop.pin_fork);
- ``PlayBack`` answers a loop's calls from the journal (the loop restored from a checkpoint
  makes them again, in the same order) and then hands over to a live design.
"""

from dataclasses import dataclass

import numpy as np

__all__ = ["Call", "JournalPins", "PlayBack", "first_difference", "replay"]

#: Calls that change the design's state (the others only read it).
_CHANGING = ("poke", "schedule", "stream_frame", "watch", "run")
#: ``PlayBack(last=...)`` left out (an answer may be None).
RECORDED = object()


@dataclass(frozen=True)
class Call:
    """One call made on the design: ``op`` (the method or property), its arguments, its
    answer, and the design's cycle before it."""

    op: str
    args: tuple
    answer: object
    cycle: int


def _same(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and np.array_equal(a, b)
    return a == b


def _call(design, op, args):
    if op == "frame_pending":
        return design.frame_pending
    return getattr(design, op)(*args)


class JournalPins:
    """``design`` (a ``PinBackend``, reset) as the loop sees it, every call kept in
    ``calls``."""

    def __init__(self, design):
        self.design = design
        self.calls = []
        #: The design itself, for a look that is no part of the loop's calls (a shadow's
        #: comparison).
        self.unrecorded = design

    @property
    def name(self):
        return self.design.name

    @property
    def ports(self):
        return self.design.ports

    @property
    def source(self):
        """The design's source: its ``[runtime]`` inputs are held by the backend, no call."""
        return getattr(self.design, "source", None)

    @property
    def cycle(self):
        return self.design.cycle

    def _do(self, op, *args):
        cycle = self.design.cycle
        answer = _call(self.design, op, args)
        self.calls.append(Call(op, args, answer, cycle))
        return answer

    @property
    def frame_pending(self):
        return self._do("frame_pending")

    def poke(self, name, value):
        self._do("poke", name, value)

    def schedule(self, edge, name, value):
        self._do("schedule", edge, name, value)

    def stream_frame(self, packed, timing):
        self._do("stream_frame", packed.copy(), timing)

    def peek(self, name):
        return self._do("peek", name)

    def watch(self, names):
        self._do("watch", list(names))

    def filtered_frame(self):
        return self._do("filtered_frame")

    def run(self, cycles):
        return self._do("run", cycles)

    def reset(self):
        raise RuntimeError("a journaled design is reset before its journal starts")

    def close(self):
        """The design belongs to who opened it: nothing to release here."""


def replay(design, calls):
    """Reset ``design`` and bring it to its state after ``calls`` (from a ``JournalPins``
    started on a reset design): each state-changing call at its cycle, the design run
    without stops in between. Returns ``design``."""
    design.reset()
    design.watch([])
    watching = []
    for call in calls:
        if call.op not in _CHANGING:
            continue
        _run_to(design, call.cycle)
        if call.op == "run":
            _run_to(design, call.answer.cycle)
        elif call.op == "watch":
            watching = call.args[0]
        else:
            getattr(design, call.op)(*call.args)
    if calls:
        _run_to(design, calls[-1].answer.cycle if calls[-1].op == "run" else calls[-1].cycle)
    design.watch(watching)
    return design


def _run_to(design, edge):
    while design.cycle < edge:
        design.run(edge - design.cycle)


def first_difference(design, calls, progress=None, tolerated=()):
    """Reset ``design`` and make ``calls`` on it in order until one's answer differs from
    the recorded one: returns ``(index, answer, differing)``: that call's index and answer,
    or ``(None, None, ...)`` when every answer agreed. The calls whose indices are in
    ``tolerated`` (reads of outputs that drive nothing) may differ: their answers go into
    ``differing`` (``{index: answer}``) and the calls go on. ``progress(index)`` is called
    after every call."""
    design.reset()
    differing = {}
    for i, call in enumerate(calls):
        answer = _call(design, call.op, call.args)
        if not _same(answer, call.answer):
            if i not in tolerated:
                return i, answer, differing
            differing[i] = answer
        if progress is not None:
            progress(i)
    return None, None, differing


class PlayBack:
    """A pin design for a loop restored from a checkpoint: it answers ``calls`` (the calls
    the reference loop made from the checkpoint on, checked against the loop's own) with
    their recorded answers (``answers``: the live design's own, where its differed), ``last``
    (when given) with that answer instead, then passes every call on to ``design`` (which has
    made those calls already)."""

    def __init__(self, design, calls, cycle, last=RECORDED, answers=None):
        self.live = design
        self.calls = list(calls)
        self.last = last  # the answer of the final call, when it is the live design's own
        self.answers = answers or {}  # {index in calls: the live design's answer there}
        self.i = 0
        self._cycle = cycle

    @property
    def name(self):
        return self.live.name

    @property
    def ports(self):
        return self.live.ports

    @property
    def source(self):
        return getattr(self.live, "source", None)

    @property
    def playing(self):
        return self.i < len(self.calls)

    @property
    def cycle(self):
        return self._cycle if self.playing else self.live.cycle

    def _do(self, op, *args):
        if not self.playing:
            return _call(self.live, op, args)
        call = self.calls[self.i]
        if call.op != op or not all(_same(a, b) for a, b in zip(call.args, args, strict=True)):
            raise RuntimeError(
                f"the restored loop called {op}{args!r} where the reference called "
                f"{call.op}{call.args!r}: the run is not deterministic"
            )
        i, self.i = self.i, self.i + 1
        if self.playing or self.last is RECORDED:
            answer = self.answers.get(i, call.answer)
        else:
            answer = self.last
        if op == "run":
            self._cycle = answer.cycle
        return answer

    @property
    def frame_pending(self):
        return self._do("frame_pending")

    def poke(self, name, value):
        self._do("poke", name, value)

    def schedule(self, edge, name, value):
        self._do("schedule", edge, name, value)

    def stream_frame(self, packed, timing):
        self._do("stream_frame", packed, timing)

    def peek(self, name):
        return self._do("peek", name)

    def watch(self, names):
        self._do("watch", list(names))

    def filtered_frame(self):
        return self._do("filtered_frame")

    def run(self, cycles):
        return self._do("run", cycles)

    def close(self):
        """The design belongs to who opened it."""
