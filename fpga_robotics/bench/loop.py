"""``fpga-robotics bench loop``: where the closed loop's time goes, per frame.

Each size runs the scenario once untimed (it keeps the frames), then ``--repeats`` turns of:
the loop as users run it (no timers, no frame records), the design alone on the kept frames,
and the loop with every step of ``ClosedLoop`` timed (one compiled model, built or loaded
before timing): the design's C++ frame loop (as the harness
measures it; the RGB888 to RGB444 packing happens in it), the frame hand-over on the Python
side (checks, picking the entry point), the call and its results, the camera render, the
physics, the measurements and events, the frame record. It prints milliseconds per frame
(medians over the turns), the real-time factors, and the two ratios of issue 12: the whole
loop and the rest of the loop (render + physics + bookkeeping) against the design's own
``process_frame``, taken as it runs in the timed loop, and alone (wall clock and CPU time of
this thread; the CPU time is what a machine with a core to spare gives while other jobs share
this one; in the loop the render and the physics between its frames cost the design cache
misses, which count as the rest's against the design alone). ``--profile N`` adds the N functions of largest own time in one more run
under cProfile.
"""

import cProfile
import io
import math
import pstats
import statistics
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.compressed import ClosedLoop, make_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BACKEND_NAMES, BackendError

__all__ = ["STEPS", "main", "measure"]

#: Targets of issue 12 at 160x120 and 640x480.
TARGET_LOOP_RATIO = 2.2
TARGET_REST_RATIO = 1.2
TARGET_REALTIME_640 = 4.0

#: The rows of the breakdown: key -> label.
STEPS = {
    "loop": "design: C++ frame loop (RGB888 packing included)",
    "handover": "design: frame hand-over (Python: checks, entry point)",
    "results": "design: call and results (Python: ctypes call, FrameResult)",
    "render": "render (camera pose, scene, image, sensor noise)",
    "physics": "physics (world steps, motor commands)",
    "measure": "measure + events (trajectory row, design events)",
    "record": "recording (FrameRecord; the viewer's cost: bench viewer)",
    "other": "other (the loop's own bookkeeping)",
    "finish": "after the frames (physics to the end, the summary), per frame",
}


def _timed_loop_class():
    class TimedLoop(ClosedLoop):
        """``ClosedLoop`` whose steps add their wall time to ``self.spent``."""

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.spent = dict.fromkeys((k for k in STEPS if k != "finish"), 0.0)
            self.want_records = True  # the record is built (and dropped) every frame
            self.keep_frames, self.frames = False, []
            design = self.design
            self._harness = hasattr(design, "_run_harness")
            if self._harness:  # the instance's own method, timed (process_frame calls it)
                inner = design._run_harness

                def run_harness(*a):
                    start = time.perf_counter()
                    result = inner(*a)
                    self._call = time.perf_counter() - start
                    return result

                design._run_harness = run_harness

        def _timed(self, key, fn, *args):
            start = time.perf_counter()
            value = fn(*args)
            self.spent[key] += time.perf_counter() - start
            return value

        def advance_physics(self, to_step):
            return self._timed("physics", super().advance_physics, to_step)

        def capture(self, t):
            return self._timed("render", super().capture, t)

        def process(self, k, rgb):
            if self.keep_frames:
                self.frames.append((rgb, self.color_code))
            start = time.perf_counter()
            result = super().process(k, rgb)
            whole = time.perf_counter() - start
            if self._harness:
                loop = self.design.last_loop_seconds
                self.spent["loop"] += loop
                self.spent["results"] += self._call - loop
                self.spent["handover"] += whole - self._call
            else:
                self.spent["loop"] += whole
            return result

        def measure(self, k, t, pose, result):
            return self._timed("measure", super().measure, k, t, pose, result)

        def record(self, *args, **kwargs):
            start = time.perf_counter()
            super().record(*args, **kwargs)
            self.spent["record"] += time.perf_counter() - start

        def run_frame(self, k):
            before = sum(self.spent.values())
            start = time.perf_counter()
            super().run_frame(k)
            # What the frame took beyond its timed steps: the loop's own bookkeeping.
            self.spent["other"] += time.perf_counter() - start - (sum(self.spent.values()) - before)

    return TimedLoop


def _timed(fn):
    """``fn()``'s wall and CPU time (this thread), seconds."""
    with scaffold.stopwatch(time.thread_time) as t:
        fn()
    return t.wall, t.cpu


def measure(scenario, design, repeats):
    """Medians over ``repeats`` turns, per frame: each step's milliseconds (a run with every
    step timed; ``loop_ms`` its whole, the sum of the steps); the loop as users run it (no
    timers, no frame records: ``plain_ms`` and ``plain_cpu_ms``, wall clock and CPU time, and
    the real-time factors); the design alone on the frames of a first untimed run
    (``design_alone_ms``, ``design_alone_cpu_ms``). A turn runs the three one after the other,
    so that all see the same period of a shared machine."""
    TimedLoop = _timed_loop_class()
    design.reset()
    first = TimedLoop(scenario, design=design)  # also warms up; keeps the frames to replay
    first.keep_frames = True
    first.run()
    frames, n = first.frames, max(1, first.frames_done)
    sim_time = first.step * first.dt
    runs, plain, alone = [], [], []
    for _ in range(repeats):
        design.reset()
        plain.append(_timed(ClosedLoop(scenario, design=design).run))

        def replay():
            for rgb, color in frames:
                design.process_frame(rgb, color)

        design.reset()
        alone.append(_timed(replay))
        design.reset()
        loop = TimedLoop(scenario, design=design)
        wall, _ = _timed(loop.run)
        # The rest of the run's wall time: what comes after the last frame.
        loop.spent["finish"] = wall - sum(loop.spent.values())
        runs.append(({k: 1e3 * v / n for k, v in loop.spent.items()}, 1e3 * wall / n))

    def median_ms(values):
        return 1e3 * statistics.median(values) / n

    return {
        "steps_ms": {k: statistics.median(r[0][k] for r in runs) for k in STEPS},
        "loop_ms": statistics.median(r[1] for r in runs),
        "plain_ms": median_ms(w for w, _ in plain),
        "plain_cpu_ms": median_ms(c for _, c in plain),
        "realtime": sim_time / statistics.median(w for w, _ in plain),
        # The thread's CPU time: what the loop takes where it has a core to itself.
        "cpu_realtime": sim_time / statistics.median(c for _, c in plain),
        "design_alone_ms": median_ms(w for w, _ in alone),
        "design_alone_cpu_ms": median_ms(c for _, c in alone),
        "frames": n,
    }


def _profile(scenario, design, top):
    design.reset()
    profiler = cProfile.Profile()
    profiler.enable()
    run_scenario(scenario, backend=design)
    profiler.disable()
    text = io.StringIO()
    pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(top)
    lines = [ln for ln in text.getvalue().splitlines() if ln.strip()]
    return lines[next(i for i, ln in enumerate(lines) if "function calls" in ln) :]


def _options(p):
    scaffold.add_follow_target_design(p)
    p.add_argument("--scenario", default="follow_person")
    p.add_argument("--backend", default="auto", choices=("auto", *BACKEND_NAMES))
    p.add_argument(
        "--resolutions",
        default="160x120,640x480",
        help="comma-separated WIDTHxHEIGHT list (default 160x120,640x480)",
    )
    p.add_argument("--duration", type=float, default=10.0, help="simulated seconds a run (10)")
    p.add_argument(
        "--profile",
        type=int,
        default=0,
        metavar="N",
        help="also print the N functions of largest own time (cProfile, one run)",
    )


def _check(args):
    scaffold.check_follow_target_design(args, "loop")
    if not args.repeats <= 100:
        raise UsageError(f"--repeats must be 1..100, got {args.repeats}")
    if not (math.isfinite(args.duration) and 0 < args.duration <= 600):
        raise UsageError(
            f"--duration must be more than 0 and at most 600 simulated seconds, got {args.duration}"
        )
    if not 0 <= args.profile <= 200:
        raise UsageError(f"--profile must be 0..200 functions, got {args.profile}")
    args.resolutions = scaffold.parse_sizes(args.resolutions, "a resolution")


def run(args):
    figures = []
    scenarios = [
        load_scenario(
            args.scenario, [f'camera.resolution="{w}x{h}"', f"sim.duration={args.duration}"]
        )
        for w, h in args.resolutions
    ]
    for scenario in scenarios:
        scaffold.check_follow_target_scenario(scenario, "loop")
    for (w, h), scenario in zip(args.resolutions, scenarios, strict=True):
        try:
            design = make_backend(args.backend, scenario.params)
        except BackendError as exc:
            raise UsageError(f"the {args.backend} backend cannot run here: {exc}") from None
        with design:
            m = measure(scenario, design, args.repeats)
            figures.append({"size": f"{w}x{h}", "backend": design.name, **m})
            steps = m["steps_ms"]
            print(
                f"closed loop {w}x{h}: {scenario.name}, {design.name}, {m['frames']} frames x "
                f"{args.repeats} runs; ms per frame (median of the runs)"
            )
            for key, label in STEPS.items():
                print(f"  {label:<62} {steps[key]:8.4f}")
            own = steps["loop"] + steps["handover"] + steps["results"]
            print(f"  {'whole loop (this timed run)':<62} {m['loop_ms']:8.4f}")
            print(
                f"  {'the loop as users run it (no timers, no records)':<62} "
                f"{m['plain_ms']:8.4f}  ({m['realtime']:.1f}x real time)"
            )
            print(
                f"  {'the same, CPU time of the thread':<62} {m['plain_cpu_ms']:8.4f}  "
                f"({m['cpu_realtime']:.1f}x real time with a core to itself)"
            )
            print(
                f"  {'the design alone on the run frames':<62} "
                f"{m['design_alone_ms']:8.4f}  (CPU time {m['design_alone_cpu_ms']:.4f})"
            )
            checks = (
                ("the timed run against the design's time in it", m["loop_ms"], own),
                (
                    "the loop against the design alone, wall clock",
                    m["plain_ms"],
                    m["design_alone_ms"],
                ),
                (
                    "the loop against the design alone, CPU time",
                    m["plain_cpu_ms"],
                    m["design_alone_cpu_ms"],
                ),
            )
            for what, whole, ref in checks:
                ratio = scaffold.figure_against(whole / ref, TARGET_LOOP_RATIO, 2)
                rest = scaffold.figure_against((whole - ref) / ref, TARGET_REST_RATIO, 2)
                line = f"  {what}: whole {ratio}x, the rest {rest}x the design"
                if (w, h) == (160, 120):
                    ok = (
                        whole / ref <= TARGET_LOOP_RATIO
                        and (whole - ref) / ref <= TARGET_REST_RATIO
                    )
                    line += (
                        f" (target 160x120: <= {TARGET_LOOP_RATIO}x, <= "
                        f"{TARGET_REST_RATIO}x): {'met' if ok else 'MISSED'}"
                    )
                print(line)
            if (w, h) == (640, 480):
                for what, factor in (
                    ("wall clock", m["realtime"]),
                    ("CPU time", m["cpu_realtime"]),
                ):
                    verdict = "met" if factor >= TARGET_REALTIME_640 else "MISSED"
                    shown = scaffold.figure_against(factor, TARGET_REALTIME_640, 1)
                    print(
                        f"  target 640x480: {shown}x real time by {what} "
                        f"(>= {TARGET_REALTIME_640:g}x): {verdict}",
                        flush=True,
                    )
            if args.profile:
                print(f"  cProfile of one run, {args.profile} functions of largest own time:")
                for line in _profile(scenario, design, args.profile):
                    print(f"    {line}")
    return {"runs": figures}


main = scaffold.command(run, __doc__, name="loop", options=_options, check=_check, repeats=3)
