"""Fork at divergence in real-clock timing: pin design variants judged against one
reference run, each re-simulated in the world only from where it parts from the reference.

A ``PinReferenceRun`` runs the reference design (a ``PinBackend``) in a real-clock loop
through a journal (fpga_robotics.loop.pin_journal) and takes a world checkpoint
(fpga_robotics.loop.checkpoint) every ``checkpoint_every`` frames and at the end.

``run_variant(design)`` puts the variant through the reference's journal alone (no world, no
connectors): the same pokes, schedules and pixel streams at the same edges, until the first
call whose answer differs from the reference's (a watched pin changing elsewhere, a frame
output or an extra output read otherwise). Up to that call the loop would have done exactly
what it did with the reference, so:

- if no answer differs, the variant's run is the reference's (its own name in the summary);
- otherwise the world is restored from the last checkpoint before that call and the loop
  runs on from there, its calls answered from the journal up to that call and by the variant
  (already there) after it.

Either way the ``RunResult`` equals the variant's full run, the wall-clock fields excepted.
A variant whose pins the loop binds otherwise (other ports, connectors, extra outputs) has
nothing to share with the reference: it gets a full run.
"""

import bisect
import time
from types import SimpleNamespace

from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.fork import ReferenceRun, check_same_world
from fpga_robotics.loop.pin_journal import JournalPins, PlayBack, first_difference
from fpga_robotics.loop.real_clock import RealClockLoop
from fpga_robotics.loop.reference_data import PinReferenceData
from fpga_robotics.loop.shadow import is_shadow_event
from fpga_robotics.loop.timings import run_scenario

__all__ = ["PinReferenceRun", "reference_run"]


def reference_run(scenario, *, design, seed=None, checkpoint_every=30, **run_args):
    """The reference run for the scenario's timing: a ``ReferenceRun`` (compressed, a
    frame-level design) or a ``PinReferenceRun`` (real clock, a pin design); ``run_args``
    as theirs (``progress``, ``recorder``, ``on_frame``, ``shadow``, ``shadow_label``)."""
    kind = PinReferenceRun if scenario.sim.timing == "real_clock" else ReferenceRun
    return kind(scenario, design=design, seed=seed, checkpoint_every=checkpoint_every, **run_args)


class _RecordingPinLoop(RealClockLoop):
    """A real-clock loop that takes the checkpoints variants restore."""

    def __init__(self, scenario, *, seed, design, checkpoint_every, watch=None, **loop_args):
        super().__init__(scenario, seed=seed, design=design, **loop_args)
        self.every = checkpoint_every
        # Watch bit -> the row it first rose in (None: no watch); ``watch`` reads the
        # design itself, not through the journal, which variants replay.
        self._watch = watch
        self.watch_first = None if watch is None else {}
        self.checkpoints = []  # in frame order
        self.frame_calls = []  # the journal's length as each frame starts
        self.extra_reads = {}  # journal index of a read of an extra output -> (row, name)
        self._extra_names = {port: name for name, port in self.top.extra_outputs.items()}
        self.final = None

    def run_frame(self, k):
        self.frame_calls.append(len(self.primary.calls))
        if k % self.every == 0:
            self.checkpoints.append(checkpoint.take(self))
        super().run_frame(k)

    def finish_row(self):
        row, start = self.pending, len(self.primary.calls)
        super().finish_row()
        if row is None:
            return
        self._read_watch(row.k)
        names = self._extra_names
        for i, call in enumerate(self.primary.calls[start:], start):
            if call.op == "peek" and call.args[0] in names:
                self.extra_reads[i] = (row.k, names[call.args[0]])

    def _read_watch(self, k):
        for bit in self._watch() if self._watch is not None else ():
            self.watch_first.setdefault(bit, k)

    def finish_run(self, wall_start, cpu_start):
        self.final = checkpoint.take(self)
        self._read_watch(self.frames_done)  # what rose after the last row
        return super().finish_run(wall_start, cpu_start)


def _interface(loop):
    """How the loop binds its design: what must agree for a variant to share the journal
    (the reference's watch outputs aside: only the reference is watched)."""
    source = getattr(loop.pins, "source", None)
    watch = {name for name, _ in getattr(source, "watch", None) or ()}
    return (
        {name: port for name, port in loop.pins.ports.items() if name not in watch},
        {c.name: io.binding for c, io in loop.io.items()},
        sorted(loop.watched),
        loop.top.camera,
        dict(loop.top.extra_outputs),
    )


class PinReferenceRun:
    """The reference pin design's real-clock run of ``scenario``, ready to fork variants
    from; the interface of ``fpga_robotics.loop.fork.ReferenceRun``.

    Parameters
    ----------
    scenario : Scenario
        In real-clock timing.
    design : PinBackend
        The reference design, for ``scenario``; reset here, not closed.
    seed : int, optional
    checkpoint_every : int
        Frames between world checkpoints.
    progress, **loop_args
        As ``ReferenceRun``'s (a ``shadow`` is a pin design, given the primary's inputs).
    """

    def __init__(
        self, scenario, *, design, seed=None, checkpoint_every=30, progress=None, **loop_args
    ):
        if scenario.sim.timing != "real_clock":
            raise ValueError('PinReferenceRun needs sim.timing = "real_clock"')
        if checkpoint_every < 1:
            raise ValueError(f"checkpoint_every must be at least 1, got {checkpoint_every}")
        self.scenario = scenario
        design.reset()
        if loop_args.get("shadow") is not None:
            loop_args["shadow"].reset()
        self.journal = JournalPins(design)
        self._loop = _RecordingPinLoop(
            scenario,
            seed=seed,
            design=self.journal,
            checkpoint_every=checkpoint_every,
            watch=_watch_of(design),
            **loop_args,
        )
        self.seed = self._loop.seed
        self.result = self._loop.run(progress=progress)
        self._end_cycle = design.cycle  # where a variant that is not run ends
        self._interface = _interface(self._loop)
        self.last_divergence = self.last_world_from = None  # as ReferenceRun's
        self.last_design_ran = True

    def portable(self):
        """This reference as a ``PinReferenceData``: picklable, for another process."""
        ref = self._loop
        return PinReferenceData(
            scenario=self.scenario,
            seed=self.seed,
            result=self.result,
            calls=list(self.journal.calls),
            frame_calls=list(ref.frame_calls),
            extra_reads=dict(ref.extra_reads),
            n_frames=ref.n_frames,
            frames_done=ref.frames_done,
            checkpoints=[checkpoint.portable(c) for c in ref.checkpoints],
            final=checkpoint.portable(ref.final),
            watch_first=None if ref.watch_first is None else dict(ref.watch_first),
            interface=self._interface,
            end_cycle=self._end_cycle,
        )

    @classmethod
    def from_portable(cls, data):
        """The ``PinReferenceRun`` that ``data`` (``portable()``) was made from, without its
        design: ``run_variant`` gives the same results as the original's."""
        self = cls.__new__(cls)
        self.scenario, self.seed, self.result = data.scenario, data.seed, data.result
        self.journal = SimpleNamespace(calls=data.calls)
        # What run_variant reads of the recording loop.
        self._loop = SimpleNamespace(
            frame_calls=data.frame_calls,
            extra_reads=data.extra_reads,
            n_frames=data.n_frames,
            frames_done=data.frames_done,
            checkpoints=data.checkpoints,
            final=data.final,
            watch_first=data.watch_first,
        )
        self._interface, self._end_cycle = data.interface, data.end_cycle
        self.last_divergence = self.last_world_from = None
        self.last_design_ran = True
        return self

    @property
    def frames(self):
        return self._loop.frames_done

    def run_variant(self, design, scenario=None, *, progress=None, watch_bit=None):
        """The run of ``design`` (a ``PinBackend`` for ``scenario``; reset here, not closed)
        in the reference's world. ``scenario`` as in ``ReferenceRun.run_variant``;
        ``progress(done, total)`` after every frame replayed or run. ``watch_bit``: as
        ``ReferenceRun.run_variant``'s (a mutant whose bit never rose is not run)."""
        scenario = self.scenario if scenario is None else scenario
        check_same_world(self.scenario, scenario)
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        ref, calls = self._loop, self.journal.calls
        loop = RealClockLoop(scenario, seed=self.seed, design=design)
        self.last_design_ran = True
        if _interface(loop) != self._interface:
            self.last_divergence = self.last_world_from = 0
            return run_scenario(scenario, seed=self.seed, backend=design, progress=progress)
        starts = ref.frame_calls

        def replayed(i):
            if progress is not None and i + 1 in starts[1:]:
                progress(bisect.bisect_right(starts, i), ref.n_frames)

        watched = watch_bit is not None and ref.watch_first is not None
        if watched and ref.watch_first.get(watch_bit) is None:
            # Every signal of the variant is the reference design's, edge for edge: every
            # answer is the journal's.
            i, extra = None, {}
            self.last_design_ran = False
        else:
            # Its extra outputs drive nothing: where only they differ, the world is the same.
            i, answer, extra = first_difference(design, calls, replayed, ref.extra_reads)
        if i is None:
            self.last_divergence = self.last_world_from = None
            last = ref.final.design_calls
            rest = calls[last:]
            loop.use_design(
                PlayBack(
                    design,
                    rest,
                    rest[0].cycle if rest else self._end_cycle,
                    answers={j - last: a for j, a in extra.items() if j >= last},
                )
            )
            _restore(loop, ref.final)
            _rewrite_extra(loop, ref, extra, last)
            return loop.finish_run(wall_start, cpu_start)
        self.last_divergence = bisect.bisect_right(starts, i) - 1
        start = [c for c in ref.checkpoints if c.design_calls <= i][-1]
        self.last_world_from = start.frame
        first = start.design_calls
        answers = {j - first: a for j, a in extra.items() if j >= first}
        loop.use_design(PlayBack(design, calls[first : i + 1], calls[first].cycle, answer, answers))
        _restore(loop, start)
        _rewrite_extra(loop, ref, extra, first)
        return loop.run(start=start.frame, progress=progress)


def _watch_of(design):
    """The reader of a pin design's ``[watch]`` output (None without one)."""
    source = getattr(design, "source", None)
    return design.watch_risen if getattr(source, "watch", None) else None


def _rewrite_extra(loop, ref, extra, before):
    """The variant's own reads of its extra outputs (``extra``: journal index -> value) made
    before journal index ``before`` into the rows of a restored ``loop``."""
    for i, value in extra.items():
        if i < before:
            k, name = ref.extra_reads[i]
            loop.extra[name][k] = float(value)
            loop.exact_extra.setdefault(name, {})[k] = value


def _restore(loop, saved):
    """The reference's state into the variant's loop, without the reference's shadow's
    events (a variant runs without one)."""
    checkpoint.restore(loop, saved)
    loop.events = [e for e in loop.events if not is_shadow_event(e[2])]
