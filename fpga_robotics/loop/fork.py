"""Fork at divergence: many designs judged against one world, each re-simulated only from
where it starts to drive the robot differently.

A ``ReferenceRun`` is one closed-loop run of a reference design (compressed timing) that
keeps what a variant design needs: the image and colour select of every frame, the wheel
commands the reference gave, the world's events around the design's own, and a world
checkpoint (fpga_robotics.loop.checkpoint) every ``checkpoint_every`` frames and at the end.

``run_variant(design)`` first replays the variant on the recorded images alone (no
rendering, no physics) until the first frame whose wheel command differs from the
reference's. Up to that frame the variant saw exactly the reference's images, so:

- if no command differs, its world is the reference's world: its result is the reference's
  with the variant's own design outputs, design events (found, lost, search started) and
  cycle count;
- if frame ``k``'s command differs, the world is restored from the last checkpoint at or
  before ``k`` and the run continues in closed loop from there: up to frame ``k`` with the
  variant's outputs as replayed (its images there are the reference's), then with the
  variant design itself, which has processed frame ``k`` already. The design is simulated
  once per frame, the world only from the checkpoint on.

Either way the ``RunResult`` equals the variant's full run (``run_scenario``): trajectory,
events and summary, the wall-clock timing fields excepted.

A ``ReferenceRun`` holds its design and checkpoints that share objects with its loop, so it
stays in its process; ``portable()`` is the same reference picklable
(fpga_robotics.loop.reference_data), which ``ReferenceRun.from_portable`` opens in another
process with the same variants' results.
"""

import time
from types import SimpleNamespace

from fpga_robotics.checks.summary import DESIGN_OUTPUTS
from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.compressed import ClosedLoop, _DesignEvents, _dps
from fpga_robotics.loop.reference_data import ReferenceData, pack_frames, recorded_of

__all__ = ["ReferenceRun"]

#: Scenario sections that may differ between the reference and a variant: they change the
#: design or the judging, never the world the design sees.
VARIANT_SECTIONS = ("name", "description", "design", "checks")


def forkable(scenario):
    """Whether a variant's run of ``scenario`` can be forked from a reference run: the fork
    finds where a variant parts from the world by its wheel commands, so a robot whose design
    also moves a servo, or sees through further cameras, runs in full."""
    return not any(
        spec.role == "actuator" or spec.kind == "camera"
        for spec in getattr(scenario, "connectors", ())
    )


class _RecordingLoop(ClosedLoop):
    """A closed loop that records what variants of its design need (see ``ReferenceRun``)."""

    def __init__(self, scenario, *, seed, design, checkpoint_every, **loop_args):
        super().__init__(scenario, seed=seed, design=design, **loop_args)
        self.every = checkpoint_every
        self.checkpoints = []  # in frame order
        self.seen = []  # (rgb, colour code) per frame
        self.commands = []  # (left, right) DPS per frame, as the motors took them
        self.world_events = []  # (before, after) the design's events, per frame
        self.final = None  # the checkpoint once the frames and the physics after them are done
        self._ref_events = _DesignEvents(scenario.params.lost_frames)
        self._before = 0
        self._shadow_events = 0  # the shadow's, after the design's: no variant has them

    def run_frame(self, k):
        if k % self.every == 0:
            self.checkpoints.append(checkpoint.take(self))
        first = len(self.events)
        super().run_frame(k)
        texts = [e for _, _, e in self.events[first:]]
        result = self._result
        mine = self._ref_events.update(bool(result.found)) if result.found is not None else []
        after = self._before + len(mine) + self._shadow_events
        self.world_events.append((texts[: self._before], texts[after:]))

    def capture(self, t):
        pose, rgb, events = super().capture(t)
        self._before = len(events)  # the world's and the colour select's, before the design's
        self.seen.append((rgb, self.color_code))
        return pose, rgb, events

    def process(self, k, rgb):
        self._result = result = super().process(k, rgb)
        self.commands.append((_dps(result.motor_left), _dps(result.motor_right)))
        return result

    def process_shadow(self, k, t, rgb, result):
        shadow_result, events = super().process_shadow(k, t, rgb, result)
        self._shadow_events = len(events)
        return shadow_result, events

    def finish_run(self, wall_start, cpu_start):
        self.final = checkpoint.take(self)
        return super().finish_run(wall_start, cpu_start)


class ReferenceRun:
    """The reference design's run of ``scenario``, ready to fork variants from.

    Parameters
    ----------
    scenario : Scenario
        In compressed timing (``sim.timing = "compressed"``).
    design : DesignBackend
        The reference design, built for ``scenario.params``; reset here, not closed.
    seed : int, optional
        Default the scenario's seed.
    checkpoint_every : int
        Frames between world checkpoints: fewer frames re-simulated per diverging variant
        against more memory and copying.
    progress : callable(done, total), optional
        Called after every frame of the reference's run.
    **loop_args
        More ``ClosedLoop`` arguments for the reference's run: ``recorder``, ``on_frame``,
        ``shadow`` (reset here) and ``shadow_label``.

    Attributes
    ----------
    result : RunResult
        The reference's own run.
    last_divergence : int or None
        For the last ``run_variant``: the first frame whose wheel command differed (None if
        none did).
    """

    def __init__(
        self, scenario, *, design, seed=None, checkpoint_every=30, progress=None, **loop_args
    ):
        if scenario.sim.timing != "compressed":
            raise ValueError('forked runs need sim.timing = "compressed"')
        if not forkable(scenario):
            raise ValueError("forked runs need a robot whose only actuators are its wheels")
        if checkpoint_every < 1:
            raise ValueError(f"checkpoint_every must be at least 1, got {checkpoint_every}")
        if design.params != scenario.params:
            raise ValueError("the backend was built for other parameters than the scenario's")
        self.scenario = scenario
        design.reset()
        if loop_args.get("shadow") is not None:
            loop_args["shadow"].reset()
        self._loop = _RecordingLoop(
            scenario, seed=seed, design=design, checkpoint_every=checkpoint_every, **loop_args
        )
        self.seed = self._loop.seed
        self.result = self._loop.run(progress=progress)
        self.last_divergence = None

    @property
    def frames(self):
        """How many frames the reference ran."""
        return len(self._loop.commands)

    def portable(self):
        """This reference as a ``ReferenceData``: picklable, for another process."""
        ref = self._loop
        return ReferenceData(
            scenario=self.scenario,
            seed=self.seed,
            result=self.result,
            frames=pack_frames(ref.seen),
            colors=[color for _, color in ref.seen],
            commands=list(ref.commands),
            world_events=list(ref.world_events),
            n_frames=ref.n_frames,
            checkpoints=[checkpoint.portable(c) for c in ref.checkpoints],
            final=checkpoint.portable(ref.final),
        )

    @classmethod
    def from_portable(cls, data):
        """The ``ReferenceRun`` that ``data`` (``portable()``) was made from, without its
        design: ``run_variant`` gives the same results as the original's."""
        self = cls.__new__(cls)
        self.scenario, self.seed, self.result = data.scenario, data.seed, data.result
        self._loop = recorded_of(data)
        self.last_divergence = None
        return self

    def run_variant(self, design, scenario=None, *, progress=None):
        """The run of ``design`` (reset here, not closed) in the reference's world.

        ``scenario`` is the variant's own scenario when its design parameters or checks
        differ (its world, camera, timing and seed must be the reference's); default the
        reference's. ``progress(done, total)`` is called after every frame replayed or run
        (it may raise to stop the run)."""
        scenario = self.scenario if scenario is None else scenario
        check_same_world(self.scenario, scenario)
        if design.params != scenario.params:
            raise ValueError("the backend was built for other parameters than the scenario's")
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        ref = self._loop
        design.reset()
        outputs, diverged = [], None
        for k, (rgb, color) in enumerate(ref.seen):
            outputs.append(_outputs(design.process_frame(rgb, color)))
            if progress is not None:
                progress(k + 1, ref.n_frames)
            if (_dps(outputs[k].motor_left), _dps(outputs[k].motor_right)) != ref.commands[k]:
                diverged = k
                break
        self.last_divergence = diverged
        loop = ClosedLoop(scenario, seed=self.seed, design=design)
        if diverged is None:
            checkpoint.restore(loop, ref.final)
            _rewrite_design_part(loop, outputs, ref)
            return loop.finish_run(wall_start, cpu_start)
        start = [c for c in ref.checkpoints if c.frame <= diverged][-1]
        checkpoint.restore(loop, start)
        _rewrite_design_part(loop, outputs[: start.frame], ref)
        # The variant has run up to frame `diverged` already: from the checkpoint to there
        # the loop gets its outputs as replayed (the frames are the same), then the design.
        loop.design = _Replayed(outputs[start.frame :], design)
        return loop.run(start=start.frame, progress=progress)


class _Replayed:
    """A design that gives recorded outputs for its first frames, then hands over to
    ``design`` (which has processed those frames already)."""

    def __init__(self, outputs, design):
        self.outputs = list(outputs)
        self.design = design
        self.name = design.name

    def process_frame(self, rgb, color_sel):
        if self.outputs:
            return self.outputs.pop(0)
        return self.design.process_frame(rgb, color_sel)


def _outputs(result):
    """What the loop keeps of a ``FrameResult`` (its image buffer may be reused)."""
    return SimpleNamespace(
        cycles=result.cycles, **{name: getattr(result, name) for name in DESIGN_OUTPUTS}
    )


def _rewrite_design_part(loop, outputs, ref):
    """Make the first ``len(outputs)`` frames of a restored ``loop`` the variant's: its design
    outputs, cycles, absent outputs and design events, among the reference world's events."""
    n = len(outputs)
    for name in DESIGN_OUTPUTS:
        loop.traj[name][:n] = 0
    loop.absent, loop.cycles = set(), 0
    loop.design_events = _DesignEvents(loop.scenario.params.lost_frames)
    events = []
    for k, out in enumerate(outputs):
        loop.store_outputs(k, out)
        mine = loop.design_events.update(bool(out.found)) if out.found is not None else []
        before, after = ref.world_events[k]
        t = round(float(loop.traj["t"][k]), 6)
        events += [(k, t, e) for e in (*before, *mine, *after)]
    loop.events = events + [e for e in loop.events if e[0] >= n]


def check_same_world(reference, variant):
    if reference is variant:
        return
    a = {k: v for k, v in reference.data.items() if k not in VARIANT_SECTIONS}
    b = {k: v for k, v in variant.data.items() if k not in VARIANT_SECTIONS}
    if a != b:
        raise ValueError(
            "a variant's scenario may differ from the reference's only in its "
            f"{', '.join(VARIANT_SECTIONS)} sections"
        )
