"""Fork at divergence: many designs judged against one world, each re-simulated only from
where it starts to drive the robot differently.

A ``ReferenceRun`` is one closed-loop run of a reference design (compressed timing) that
keeps what a variant design needs: the image and colour select of every frame, the wheel
commands the reference gave, the world's events around the design's own, and a world
checkpoint (fpga_robotics.loop.checkpoint) every ``checkpoint_every`` frames and at the end.
A robot with further cameras and servos (fpga_robotics.loop.camera_rig) adds every capture
its design channels were given (image, colour select) and their outputs, among them the
servo commands.

``run_variant(design)`` first replays the variant on the recorded images alone (no
rendering, no physics), in the order the reference's run gave them (a frame's further
captures before its body frame), until the first frame where an output that drives the world
differs from the reference's: a wheel command, or a servo command from one of its channels
(the variant's own, built from its scenario). Up to there the variant saw exactly the
reference's images, so:

- if no command differs, its world is the reference's world: its result is the reference's
  with the variant's own design outputs, design events (found, lost, search started) and
  cycle count;
- if frame ``k``'s command differs, the world is restored from the last checkpoint at or
  before ``k`` and the run continues in closed loop from there: up to frame ``k`` with the
  variant's outputs as replayed (its images there are the reference's), then with the
  variant design itself, which has processed frame ``k`` already (its channels likewise:
  the captures they replayed, then themselves). The design is simulated once per frame, the
  world only from the checkpoint on.

Either way the ``RunResult`` equals the variant's full run (``run_scenario``): trajectory,
events and summary, the wall-clock timing fields excepted.

A ``ReferenceRun`` holds its design and checkpoints that share objects with its loop, so it
stays in its process; ``portable()`` is the same reference picklable
(fpga_robotics.loop.reference_data), which ``ReferenceRun.from_portable`` opens in another
process with the same variants' results.
"""

import collections
import time
from types import SimpleNamespace

from fpga_robotics.checks.summary import DESIGN_OUTPUTS
from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.compressed import ClosedLoop, _DesignEvents, _dps, run_compressed
from fpga_robotics.loop.reference_data import ReferenceData, pack_frames, recorded_of

__all__ = ["ReferenceRun"]

#: Scenario sections that may differ between the reference and a variant: they change the
#: design or the judging, never the world the design sees.
VARIANT_SECTIONS = ("name", "description", "design", "checks")


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
        # Further cameras' channels: every capture, in the order the run made them.
        self.captures = []  # _Capture
        self.rig_interface = _rig_interface(self)
        self.servo_ports = _servo_ports(self)
        # Watch bit -> the frame it first rose in; None: the design has no watch.
        self.watch_first = None
        self._watch = getattr(design, "watch_risen", None)
        if self.rig is not None:
            for i, cam in enumerate(self.rig.cameras):
                if cam.channel is not None:
                    cam.channel = _RecordingChannel(cam.channel, i, self)

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
        risen = self._watch() if self._watch is not None else None
        if risen is not None:  # the reset's bits come with frame 0's
            self.watch_first = {} if self.watch_first is None else self.watch_first
            for bit in risen:
                self.watch_first.setdefault(bit, k)
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
        For the last ``run_variant``: the first frame where a wheel or servo command
        differed (None if none did; 0 for a variant whose further cameras or servos bind
        its design otherwise, which has nothing to share and runs in full).
    last_world_from : int or None
        For the last ``run_variant``: the frame from which the world was simulated again
        (the checkpoint restored; None: not at all).
    last_design_ran : bool
        For the last ``run_variant``: whether the variant's design was run (not for one
        whose watch bit never rose).
    """

    def __init__(
        self, scenario, *, design, seed=None, checkpoint_every=30, progress=None, **loop_args
    ):
        if scenario.sim.timing != "compressed":
            raise ValueError('forked runs need sim.timing = "compressed"')
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
        try:
            self.result = self._loop.run(progress=progress)
        finally:  # its channels are done with: each variant runs its own
            if self._loop.rig is not None:
                self._loop.rig.close()
        self.last_divergence = self.last_world_from = None
        self.last_design_ran = True

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
            captures=list(ref.captures),
            rig_interface=ref.rig_interface,
            servo_ports=ref.servo_ports,
            watch_first=None if ref.watch_first is None else dict(ref.watch_first),
        )

    @classmethod
    def from_portable(cls, data):
        """The ``ReferenceRun`` that ``data`` (``portable()``) was made from, without its
        design: ``run_variant`` gives the same results as the original's."""
        self = cls.__new__(cls)
        self.scenario, self.seed, self.result = data.scenario, data.seed, data.result
        self._loop = recorded_of(data)
        self.last_divergence = self.last_world_from = None
        self.last_design_ran = True
        return self

    def watch_first(self, bit):
        """The frame in which bit ``bit`` of the reference design's watch output first rose
        (None: it never did); ``ValueError`` if the reference design had no watch."""
        if self._loop.watch_first is None:
            raise ValueError("the reference design has no watch output")
        return self._loop.watch_first.get(bit)

    def run_variant(self, design, scenario=None, *, progress=None, watch_bit=None):
        """The run of ``design`` (reset here, not closed) in the reference's world.

        ``scenario`` is the variant's own scenario when its design parameters or checks
        differ (its world, camera, timing and seed must be the reference's); default the
        reference's. ``progress(done, total)`` is called after every frame replayed or run
        (it may raise to stop the run). ``watch_bit``: the bit of the reference design's
        watch output that rises wherever the variant would act otherwise than the
        reference (a mutant's, sim.mutant_watch); if it never rose in the reference's run,
        the variant's run is the reference's and its design is not run at all (ignored
        when the reference design had no watch)."""
        scenario = self.scenario if scenario is None else scenario
        check_same_world(self.scenario, scenario)
        if design.params != scenario.params:
            raise ValueError("the backend was built for other parameters than the scenario's")
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        ref = self._loop
        design.reset()
        loop = ClosedLoop(scenario, seed=self.seed, design=design)
        channels = [cam.channel for cam in loop.rig.cameras] if loop.rig is not None else []
        try:
            # A variant with camera channels of its own has more than its design to run.
            has_channels = any(c is not None for c in channels)
            watched = watch_bit is not None and ref.watch_first is not None
            if watched and not has_channels and ref.watch_first.get(watch_bit) is None:
                # Every signal of the variant is the reference design's, frame for frame.
                self.last_divergence = self.last_world_from = None
                self.last_design_ran = False
                checkpoint.restore(loop, ref.final)
                return loop.finish_run(wall_start, cpu_start)
            self.last_design_ran = True
            if _rig_interface(loop) != ref.rig_interface:  # nothing to share: a run of its own
                self.last_divergence = self.last_world_from = 0
                return run_compressed(scenario, seed=self.seed, backend=design, progress=progress)
            ran = [cam.channel_ran for cam in loop.rig.cameras] if loop.rig is not None else []
            outputs, captured, diverged = _replay(design, channels, ref, progress)
            self.last_divergence = diverged
            self.last_world_from = None
            if diverged is None:
                checkpoint.restore(loop, ref.final)
                _rewrite_design_part(loop, outputs, ref)
                _hand_over_channels(loop, channels, ran, captured, ref, len(outputs))
                return loop.finish_run(wall_start, cpu_start)
            start = [c for c in ref.checkpoints if c.frame <= diverged][-1]
            self.last_world_from = start.frame
            checkpoint.restore(loop, start)
            _rewrite_design_part(loop, outputs[: start.frame], ref)
            _hand_over_channels(loop, channels, ran, captured, ref, start.frame)
            # The variant has run up to frame `diverged` already: from the checkpoint to there
            # the loop gets its outputs as replayed (the frames are the same), then the design.
            loop.design = _Replayed(outputs[start.frame :], design)
            return loop.run(start=start.frame, progress=progress)
        finally:
            for channel in channels:
                close = getattr(channel, "close", None)
                if close is not None:
                    close()


def _replay(design, channels, ref, progress):
    """The variant's ``design`` and ``channels`` (one per further camera, None for one that
    only films) on the reference's recorded inputs, in the order its run gave them, until
    the first output that drives the world differs. Returns the design's outputs per frame,
    each channel's outputs per capture, and the frame of the first difference (None)."""
    outputs, captured = [], [[] for _ in channels]
    captures, i, n = ref.captures, 0, len(ref.seen)
    for k in range(n + 1):  # k = n: the captures after the last frame
        while i < len(captures) and captures[i].frame == k:
            cap = captures[i]
            i += 1
            out = dict(channels[cap.camera].process(cap.rgb, cap.color))
            captured[cap.camera].append(out)
            if _driving(out, ref.servo_ports) != _driving(cap.outputs, ref.servo_ports):
                return outputs, captured, k
        if k == n:
            break
        rgb, color = ref.seen[k]
        outputs.append(_outputs(design.process_frame(rgb, color)))
        if progress is not None:
            progress(k + 1, ref.n_frames)
        if (_dps(outputs[k].motor_left), _dps(outputs[k].motor_right)) != ref.commands[k]:
            return outputs, captured, k
    return outputs, captured, None


def _hand_over_channels(loop, channels, ran, captured, ref, frame):
    """Give a ``loop`` restored at ``frame`` the variant's ``channels``: their outputs as
    replayed for the captures from ``frame`` on, then the channels themselves; the
    latest outputs and the rows before ``frame`` theirs."""
    rig = loop.rig
    for i, channel in enumerate(channels):
        if channel is None:
            continue
        cam, frames = rig.cameras[i], [c.frame for c in ref.captures if c.camera == i]
        done = sum(f < frame for f in frames)  # its captures before the checkpoint
        cam.channel = _Replayed(captured[i][done:], channel)
        cam.channel_ran = ran[i]
        cam.outputs = dict(captured[i][done - 1]) if done else {}
        seen = 0  # its captures up to each row (the row samples the latest)
        for k in range(frame):
            while seen < len(frames) and frames[seen] <= k:
                seen += 1
            for port, value in (captured[i][seen - 1] if seen else {}).items():
                rig.put(f"{cam.name}.{port}", k, loop.n_frames, value)


class _Replayed:
    """A design (``process_frame``) or a further camera's channel (``process``) that gives
    recorded outputs for its first calls, then hands over to ``live``, which has made those
    calls already."""

    def __init__(self, outputs, live):
        self.outputs = collections.deque(outputs)
        self.live = live

    def __getattr__(self, name):  # the live one's name, ports (view_ports ...)
        if name in ("outputs", "live"):
            raise AttributeError(name)
        return getattr(self.live, name)

    def process_frame(self, rgb, color_sel):
        return self.outputs.popleft() if self.outputs else self.live.process_frame(rgb, color_sel)

    def process(self, frame, color_sel):
        return self.outputs.popleft() if self.outputs else self.live.process(frame, color_sel)


class _Capture:
    """One capture of a further camera in the reference's run: the camera's index, the
    frame it came in (before that frame's body capture; the frame count after the last), the
    image and colour select its channel was given and the outputs the channel gave."""

    __slots__ = ("camera", "color", "frame", "outputs", "rgb")

    def __init__(self, camera, frame, rgb, color, outputs):
        self.camera, self.frame, self.rgb, self.color = camera, frame, rgb, color
        self.outputs = outputs


class _RecordingChannel:
    """A further camera's channel in the reference's run: every capture it is given goes to
    the loop's ``captures``."""

    def __init__(self, channel, camera, loop):
        self.channel, self.camera, self.loop = channel, camera, loop

    def __getattr__(self, name):  # the channel's ports (view_ports ...)
        if name in ("channel", "camera", "loop"):
            raise AttributeError(name)
        return getattr(self.channel, name)

    def process(self, frame, color_sel):
        outputs = self.channel.process(frame, color_sel)
        capture = _Capture(self.camera, self.loop.frames_done, frame, color_sel, dict(outputs))
        self.loop.captures.append(capture)
        return outputs

    def close(self):
        close = getattr(self.channel, "close", None)
        if close is not None:
            close()

    def __deepcopy__(self, memo):
        # In a checkpoint: a variant's run puts its own channel in its place.
        return _Detached(self.camera)


class _Detached:
    """A recorded channel in a checkpoint, replaced by the variant's on restore."""

    def __init__(self, camera):
        self.camera = camera

    def process(self, frame, color_sel):
        raise RuntimeError(f"camera {self.camera}'s channel was not handed over on restore")


def _rig_interface(loop):
    """How the loop's rig binds its design (None without a rig): what must agree for a
    variant to replay the reference's captures."""
    rig = loop.rig
    if rig is None:
        return None
    cameras = tuple(
        (
            cam.name,
            cam.port,
            cam.color_port,
            None if cam.channel is None else tuple(getattr(cam.channel, "output_ports", ())),
        )
        for cam in rig.cameras
    )
    return cameras, tuple((name, s.port) for name, s in rig.servos.items())


def _servo_ports(loop):
    """The channel outputs that command a servo."""
    servos = loop.rig.servos.values() if loop.rig is not None else ()
    return frozenset(s.port for s in servos if s.port is not None)


def _driving(outputs, ports):
    """Of a channel's outputs, those that drive the world (servo commands)."""
    return {port: outputs[port] for port in ports if port in outputs}


def _outputs(result):
    """What the loop keeps of a ``FrameResult`` (its image buffer may be reused)."""
    return SimpleNamespace(
        cycles=result.cycles,
        extra=result.extra,
        **{name: getattr(result, name) for name in DESIGN_OUTPUTS},
    )


def _rewrite_design_part(loop, outputs, ref):
    """Make the first ``len(outputs)`` frames of a restored ``loop`` the variant's: its design
    outputs (its extra outputs too), cycles, absent outputs and design events, among the
    reference world's events."""
    n = len(outputs)
    for name in DESIGN_OUTPUTS:
        loop.traj[name][:n] = 0
    for name in [c for c in loop.traj if c.startswith("design.")]:  # the reference's extras
        del loop.traj[name]
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
    """``ValueError`` unless ``variant`` runs in ``reference``'s world and timing."""
    if reference is variant:
        return
    a = {k: v for k, v in reference.data.items() if k not in VARIANT_SECTIONS}
    b = {k: v for k, v in variant.data.items() if k not in VARIANT_SECTIONS}
    if a != b:
        raise ValueError(
            "a variant's scenario may differ from the reference's only in its "
            f"{', '.join(VARIANT_SECTIONS)} sections"
        )
    # The design resolves sim.timing = "auto": equal sections may still run in two timings.
    if variant.sim.timing != reference.sim.timing:
        raise ValueError(
            f"a variant runs in {variant.sim.timing} timing, the reference in "
            f"{reference.sim.timing} timing"
        )
