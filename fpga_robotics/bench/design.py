"""``fpga-robotics bench design``: every simulation backend, and the paired fraction.

For every backend and resolution it runs seeded synthetic RGB888 frames through
``FollowTarget`` with ``process_frame`` as users call it, and prints the median milliseconds
per frame and the simulated clock cycles per second; for the compiled backends also the C++
frame loop's own time (measured in the harness) and the rest, the Python side of the call
(checks, the call, the results). In the same run it measures a trivial one-pixel-per-clock
design (``PassThrough``: registers the pixel and counts) through the same compiled flows: the
practical limit of this machine. Builds (or cache loads) happen before timing and are
reported separately.
"""

import statistics
import time
from importlib import resources
from pathlib import Path

from fpga_robotics.bench import scaffold
from fpga_robotics.bench.frames import bench_frames
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import BACKEND_NAMES, COMPILED_BACKENDS, BackendError, get_backend
from fpga_robotics.sim.backends.foreign import ForeignVerilatorBackend
from fpga_robotics.sim.camera.frames import to_rgb444

__all__ = ["main", "measure", "measure_paired", "parse_resolutions"]

DEFAULT_RESOLUTIONS = "160x120,320x240,640x480"
#: pysim takes about a second per 160x120 frame: fewer frames, and larger sizes only on request.
PYSIM_DEFAULT_FRAMES = 3
PYSIM_DEFAULT_MAX_PIXELS = 160 * 120
#: Targets of the compiled backends (issue 3), checked in the summary.
TARGET_MS = {(160, 120): 0.4, (640, 480): 6.0}
TARGET_TRIVIAL_FRACTION = 0.5
#: The Python side of ``process_frame`` at most this fraction of the C++ loop (issue 12).
TARGET_PYTHON_FRACTION = 0.05
#: A call whose wall time exceeds its thread's CPU time by more than this fraction (and
#: ``PREEMPTED_S``, above the clocks' own jitter) waited for a core while another job ran:
#: the paired measurement leaves its pair out.
PREEMPTED = 0.05
PREEMPTED_S = 20e-6
TARGET_PYSIM_MS_160 = 1000.0


def parse_resolutions(text):
    return scaffold.parse_sizes(text, "a resolution")


def _loop_seconds(backend):
    """The C++ loop's time of the backend's last frame, or None (no harness)."""
    return getattr(backend, "last_loop_seconds", None)


def measure(backend, frames, min_seconds=0.0):
    """Median ms per frame (wall clock and CPU time) and cycles per second (wall clock) over
    ``frames``, after one warm-up frame; the frames repeat until ``min_seconds`` have passed,
    so that a short burst of other work on a shared machine cannot decide the median."""
    backend.process_frame(frames[0])
    times, cpu_times, cycles, loops = [], [], [], []
    with scaffold.gc_paused():
        begin = time.perf_counter()
        n = 0
        while n < len(frames) or time.perf_counter() - begin < min_seconds:
            frame = frames[n % len(frames)]
            n += 1
            start, cpu_start = time.perf_counter(), time.thread_time()
            result = backend.process_frame(frame)
            times.append(time.perf_counter() - start)
            cpu_times.append(time.thread_time() - cpu_start)
            cycles.append(result.cycles)
            loops.append(_loop_seconds(backend))
    median = statistics.median(times)
    harness = {}
    if loops[0] is not None:
        # Per frame, the call's wall time less its C++ loop: the Python side of that call.
        harness = {
            "loop_ms_per_frame": statistics.median(loops) * 1e3,
            "python_us_per_frame": statistics.median(
                t - lp for t, lp in zip(times, loops, strict=True)
            )
            * 1e6,
        }
    return {
        "frames": len(times),
        "ms_per_frame": median * 1e3,
        # CPU time of this thread: the same on a quiet machine, and steadier on a busy one.
        "cpu_ms_per_frame": statistics.median(cpu_times) * 1e3,
        "cycles_per_frame": int(statistics.median(cycles)),
        "cycles_per_second": statistics.median(c / t for c, t in zip(cycles, times, strict=True)),
        **harness,
    }


def measure_paired(design_backend, trivial_backend, frames, min_seconds=0.0):
    """Cycle rate of ``design_backend`` as a fraction of ``trivial_backend``'s, measured frame
    by frame in alternation (each frame through one, then through the other) so that both see
    the same machine: on a shared machine whose speed drifts within seconds, two cases timed
    one after the other can differ by more than the designs do. The design is timed as users
    call it (the whole ``process_frame``); the trivial design by its C++ loop alone where the
    backend reports it (``last_loop_seconds``), the stricter reference. A pair in which
    either call was preempted (its wall time more than ``PREEMPTED`` above the thread's CPU
    time, plus ``PREEMPTED_S``: on a loaded machine a long frame often waits for a core) is
    left out; when all are, both are timed by their thread's CPU time instead (``clock``
    "cpu", whole calls). Returns the fraction of the two medians of per-frame cycle rates, the number of
    pairs used and the number left out."""
    backends = (design_backend, trivial_backend)
    rates, preempted, cpu_rates = ([], []), ([], []), ([], [])
    for backend in backends:
        backend.process_frame(frames[0])
    with scaffold.gc_paused():
        begin = time.perf_counter()
        n = 0
        while not (rates[0] or preempted[0]) or time.perf_counter() - begin < min_seconds:
            for frame in frames:
                # Which one goes first alternates too: the second finds the frame in the cache.
                pair, waited = [0.0, 0.0], False
                for i in (0, 1) if n % 2 == 0 else (1, 0):
                    start, cpu_start = time.perf_counter(), time.thread_time()
                    result = backends[i].process_frame(frame)
                    seconds = time.perf_counter() - start
                    cpu = time.thread_time() - cpu_start
                    waited |= seconds - cpu > PREEMPTED * seconds + PREEMPTED_S
                    cpu_rates[i].append(result.cycles / max(cpu, 1e-9))
                    if i == 1:
                        seconds = _loop_seconds(backends[i]) or seconds
                    pair[i] = result.cycles / seconds
                for i in (0, 1):
                    (preempted if waited else rates)[i].append(pair[i])
                n += 1
    if rates[0]:
        used, clock = rates, "wall"
    else:  # every pair waited for a core: the threads' CPU time is the better measure
        used, clock = cpu_rates, "cpu"
    return {
        "fraction": statistics.median(used[0]) / statistics.median(used[1]),
        "frames": len(used[0]),
        "preempted": len(preempted[0]),
        "clock": clock,
    }


def run_paired(name, params, frames, min_seconds=0.0):
    """``measure_paired`` of FollowTarget against the trivial design on backend ``name``."""
    with (
        get_backend(name, params) as design,
        get_backend(name, params, design="passthrough") as trivial,
    ):
        figures = measure_paired(design, trivial, frames, min_seconds)
    figures.update(backend=name, width=params.width, height=params.height)
    return figures


def run_one(name, params, frames, design, min_seconds=0.0):
    kwargs = {"design": design} if design != "follow_target" else {}
    start = time.perf_counter()
    backend = get_backend(name, params, **kwargs)
    build_s = time.perf_counter() - start
    with backend:
        figures = measure(backend, frames, min_seconds)
    figures.update(
        backend=name,
        design=design,
        width=params.width,
        height=params.height,
        build_or_load_s=build_s,
    )
    return figures


#: The published design's Verilog files (docs/foreign.md) and its port map.
PUBLISHED_FILES = (
    "design_top.v",
    "centroid.v",
    "color_proc.v",
    "frame_buffer.v",
    "motor_ctrl_spi.v",
)
PUBLISHED_TARGET_RATIO = 4.5


def published_files(directory):
    """The published RTL's files in ``directory``; ``UsageError`` naming any missing."""
    paths = [Path(directory) / name for name in PUBLISHED_FILES]
    missing = [p.name for p in paths if not p.is_file()]
    if missing:
        raise UsageError(
            f"--published {directory}: no {', '.join(missing)} there; it needs the five files "
            f"of the published repository's paper_verilator_ws/rtl/ folder (docs/foreign.md)"
        )
    return paths


def run_published(paths, name, frames, min_seconds=0.0):
    """The published RTL on Verilator (foreign harness, frames packed beforehand as its own
    harness has them) against backend ``name``'s ``process_frame`` of the same RGB888
    frames as users call it, frame by frame in alternation; median ms of each, and ratio."""
    params = FollowTargetParams(width=160, height=120)
    port_map = resources.files("fpga_robotics.designs") / "port_maps" / "published_design_top.toml"
    packed = [to_rgb444(f, params.width, params.height) for f in frames]
    times = ([], [])
    with (
        ForeignVerilatorBackend(params, files=paths, port_map=str(port_map)) as published,
        get_backend(name, params) as ours,
    ):
        published.process_frame(packed[0])
        ours.process_frame(frames[0])
        with scaffold.gc_paused():
            begin = time.perf_counter()
            n = 0
            while not times[0] or time.perf_counter() - begin < min_seconds:
                for rgb, pk in zip(frames, packed, strict=True):
                    for i in (0, 1) if n % 2 == 0 else (1, 0):
                        start = time.perf_counter()
                        if i == 0:
                            published.process_frame(pk)
                        else:
                            ours.process_frame(rgb)
                        times[i].append(time.perf_counter() - start)
                    n += 1
    ms = [statistics.median(t) * 1e3 for t in times]
    return {
        "backend": name,
        "published_ms": ms[0],
        "ours_ms": ms[1],
        "ratio": ms[0] / ms[1],
        "frames": len(times[0]),
    }


def _options(parser):
    parser.add_argument(
        "--backends",
        default=",".join(BACKEND_NAMES),
        help=f"comma-separated subset of {','.join(BACKEND_NAMES)} (default: all)",
    )
    parser.add_argument(
        "--resolutions", default=DEFAULT_RESOLUTIONS, help=f"default {DEFAULT_RESOLUTIONS}"
    )
    parser.add_argument(
        "--pysim-frames",
        type=int,
        default=PYSIM_DEFAULT_FRAMES,
        help=f"timed frames for pysim ({PYSIM_DEFAULT_FRAMES})",
    )
    parser.add_argument(
        "--pysim-max-pixels",
        type=int,
        default=PYSIM_DEFAULT_MAX_PIXELS,
        help="skip pysim above this many pixels a frame (default 19200 = 160x120; "
        "640x480 takes about 16 s a frame)",
    )
    parser.add_argument(
        "--no-trivial",
        action="store_true",
        help="skip the trivial one-pixel-per-clock reference design",
    )
    parser.add_argument(
        "--published",
        metavar="DIR",
        help="also time the published FPGA-Robotics RTL (the five .v files of its "
        "paper_verilator_ws/rtl/ folder in DIR) on Verilator at 160x120, in alternation "
        "with the fastest compiled backend",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the synthetic frames")


def _format_row(r):
    label = r["backend"] + (" (trivial)" if r["design"] == "passthrough" else "")
    loop = f"{r['loop_ms_per_frame']:>9.3f}" if "loop_ms_per_frame" in r else f"{'-':>9}"
    python = f"{r['python_us_per_frame']:>10.1f}" if "python_us_per_frame" in r else f"{'-':>10}"
    return (
        f"{label:<22} {r['width']:>4}x{r['height']:<4} {r['frames']:>6} "
        f"{r['ms_per_frame']:>10.3f} {r['cpu_ms_per_frame']:>9.3f} {loop} {python} "
        f"{r['cycles_per_second'] / 1e6:>10.2f} "
        f"{r['build_or_load_s']:>8.1f}"
    )


def summary(results, paired=()):
    """Lines comparing the figures with the targets of the compiled backends; the fraction
    of the trivial design's cycle rate comes from ``paired`` (``run_paired``) when there."""
    lines = []
    by = {(r["backend"], r["design"], r["width"], r["height"]): r for r in results}
    pairs = {(r["backend"], r["width"], r["height"]): r for r in paired}
    for (w, h), target in TARGET_MS.items():
        compiled = [
            by[(n, "follow_target", w, h)]
            for n in COMPILED_BACKENDS
            if (n, "follow_target", w, h) in by
        ]
        if compiled:
            best = min(compiled, key=lambda r: r["ms_per_frame"])
            verdict = "met" if best["ms_per_frame"] <= target else "MISSED"
            ms = scaffold.figure_against(best["ms_per_frame"], target, 3)
            lines.append(
                f"target {w}x{h}: fastest compiled ({best['backend']}) "
                f"{ms} ms <= {target} ms: {verdict}"
            )
            if "python_us_per_frame" in best:
                frac = best["python_us_per_frame"] / 1e3 / best["loop_ms_per_frame"]
                verdict = "met" if frac <= TARGET_PYTHON_FRACTION else "MISSED"
                times = scaffold.figure_against(1 + frac, 1 + TARGET_PYTHON_FRACTION, 3)
                lines.append(
                    f"target {w}x{h}: {best['backend']} process_frame(RGB888) takes "
                    f"{times}x its C++ loop alone (Python side "
                    f"{best['python_us_per_frame']:.1f} us; <= {1 + TARGET_PYTHON_FRACTION:.2f}x)"
                    f": {verdict}"
                )
            trivial = by.get((best["backend"], "passthrough", w, h))
            pair = pairs.get((best["backend"], w, h))
            if pair or trivial:
                if pair:
                    frac = pair["fraction"]
                    how = (
                        "measured in alternation; process_frame as users call it against "
                        "the trivial design's C++ loop"
                        if pair.get("clock") != "cpu"
                        else "measured in alternation, CPU time: every call waited for a core"
                    )
                else:
                    frac = best["cycles_per_second"] / trivial["cycles_per_second"]
                    how = "from the two rows above"
                verdict = "met" if frac >= TARGET_TRIVIAL_FRACTION else "MISSED"
                shown = scaffold.figure_against(frac, TARGET_TRIVIAL_FRACTION, 2)
                lines.append(
                    f"target {w}x{h}: {best['backend']} runs at {shown} of the trivial "
                    f"design's cycle rate (>= {TARGET_TRIVIAL_FRACTION}; {how}): {verdict}"
                )
    pysim = by.get(("pysim", "follow_target", 160, 120))
    if pysim:
        verdict = "met" if pysim["ms_per_frame"] <= TARGET_PYSIM_MS_160 else "MISSED"
        ms = scaffold.figure_against(pysim["ms_per_frame"], TARGET_PYSIM_MS_160, 0)
        lines.append(f"target 160x120: pysim {ms} ms <= {TARGET_PYSIM_MS_160:.0f} ms: {verdict}")
    return lines


def run(args):
    names = [n.strip() for n in args.backends.split(",") if n.strip()]
    for n in names:
        if n not in BACKEND_NAMES:
            raise UsageError(f"unknown backend {n!r}; choose from {', '.join(BACKEND_NAMES)}")
    if not names:
        raise UsageError(f"--backends is empty; give some of {', '.join(BACKEND_NAMES)}")
    names = list(dict.fromkeys(names))  # each backend once
    sizes = parse_resolutions(args.resolutions)
    if args.pysim_frames < 1:
        raise UsageError(f"--pysim-frames must be at least 1, got {args.pysim_frames}")
    if args.pysim_max_pixels < 0:
        raise UsageError(f"--pysim-max-pixels must be >= 0, got {args.pysim_max_pixels}")
    if args.seed < 0:
        raise UsageError(f"--seed must be >= 0, got {args.seed}")
    for w, h in sizes:  # every resolution checked before the table starts
        try:
            FollowTargetParams(width=w, height=h)
        except (TypeError, ValueError) as exc:
            raise UsageError(f"resolution {w}x{h}: {exc}") from None
    published = published_files(args.published) if args.published else None

    results, paired, notes = [], [], []
    header = (
        f"{'backend':<22} {'size':>9} {'frames':>6} {'ms/frame':>10} {'cpu ms':>9} "
        f"{'C++ loop':>9} {'python us':>10} {'Mcycles/s':>10} "
        f"{'build s':>8}"
    )
    print(
        "ms/frame: process_frame(RGB888 frame) as users call it; C++ loop: its frame loop "
        "alone (packing included); python us: the rest of the call"
    )
    print(header)
    print("-" * len(header))
    for w, h in sizes:
        try:
            params = FollowTargetParams(width=w, height=h)
        except (TypeError, ValueError) as exc:
            raise UsageError(f"resolution {w}x{h}: {exc}") from None
        frames = bench_frames(w, h, args.frames, args.seed)
        cases = [(n, "follow_target") for n in names]
        if not args.no_trivial:
            cases += [(n, "passthrough") for n in names if n in COMPILED_BACKENDS]
        for name, design in cases:
            case_frames = frames
            if name == "pysim":
                if w * h > args.pysim_max_pixels:
                    notes.append(
                        f"pysim skipped at {w}x{h} (about {w * h / 19200:.0f} s a frame); "
                        f"raise --pysim-max-pixels to include it"
                    )
                    continue
                case_frames = frames[: args.pysim_frames]
            min_seconds = 0.0 if name == "pysim" else args.min_seconds
            try:
                r = run_one(name, params, case_frames, design, min_seconds)
            except BackendError as exc:
                raise UsageError(f"the {name} backend cannot run here: {exc}") from None
            results.append(r)
            print(_format_row(r), flush=True)
        if not args.no_trivial:
            for name in names:
                if name in COMPILED_BACKENDS:
                    try:
                        pair = run_paired(name, params, frames, args.min_seconds)
                    except BackendError as exc:
                        raise UsageError(f"the {name} backend cannot run here: {exc}") from None
                    paired.append(pair)
                    left_out = (
                        f", {pair['preempted']} preempted pairs left out"
                        if pair["preempted"]
                        else ""
                    )
                    if pair["clock"] == "cpu":
                        left_out = (
                            "; every pair waited for a core: both timed by their thread's CPU time"
                        )
                    print(
                        f"{name} {w}x{h}: FollowTarget at {pair['fraction']:.2f} of the trivial "
                        f"design's cycle rate (alternating frames, {pair['frames']} each"
                        f"{left_out})",
                        flush=True,
                    )
    published_row = None
    if published is not None:
        name = next((n for n in COMPILED_BACKENDS if n in names), COMPILED_BACKENDS[0])
        frames = bench_frames(160, 120, args.frames, args.seed)
        try:
            published_row = run_published(published, name, frames, args.min_seconds)
        except BackendError as exc:
            raise UsageError(f"the published RTL cannot run here: {exc}") from None
        r = published_row
        print(
            f"published RTL on Verilator 160x120: {r['published_ms']:.3f} ms/frame; {name} "
            f"process_frame(RGB888) {r['ours_ms']:.3f} ms/frame (alternating frames, "
            f"{r['frames']} each)",
            flush=True,
        )
        ratio = scaffold.figure_against(r["ratio"], PUBLISHED_TARGET_RATIO, 2)
        notes.append(
            f"target 160x120: {name} process_frame(RGB888) {ratio}x as fast as the "
            f"published RTL (>= {PUBLISHED_TARGET_RATIO}x): "
            f"{'met' if r['ratio'] >= PUBLISHED_TARGET_RATIO else 'MISSED'}"
        )
    for line in notes + summary(results, paired):
        print(line)
    return {
        "results": results,
        "paired": paired,
        "notes": notes,
        "published": published_row,
        "summary": summary(results, paired),
    }


main = scaffold.command(run, __doc__, name="design", options=_options, frames=30, min_seconds=1.0)
