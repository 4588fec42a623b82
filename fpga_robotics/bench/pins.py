"""``fpga-robotics bench pins``: simulated clock cycles per wall second of the pin backends
in real-clock time.

The design is ``FollowTarget`` with a one-flip-flop echo beside it (``ping`` in, ``pong``
out, one cycle later): the stand-in for a peripheral driver's pin traffic. The run is the
closed loop's pattern: per physics step, ``run`` up to the step's last edge, handling each
``Stop``. Frames of seeded synthetic pixels are streamed at their capture edges
(``frame_index * clock_hz / fps``) with the OV7670-like line spread of
``real_clock_timing``; ``ping`` toggles every ``--toggle-every`` cycles (a scheduled input)
and ``pong``, ``motor_left`` and ``motor_right`` are watched (a ``Stop`` per toggle and per
wheel change). Each backend's figure is the median of ``--repeats`` runs; in the same run the
frame backend of the same simulator processes the same frames back to back (no blanking),
over as many cycles after each run, for the ratio of the pin path to the frame path.
"""

import contextlib
import math
import statistics
import time

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.bench import scaffold
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.top import FollowTarget, follow_target_signature
from fpga_robotics.sim.backends import BackendError, get_backend
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.camera.synthetic import blob_frame
from fpga_robotics.sim.pins import (
    FILTERED_PORTS,
    PIXEL_PORTS,
    PinDesignSource,
    PinError,
    get_pin_backend,
    real_clock_timing,
)

__all__ = ["EchoedFollowTarget", "benchmark", "main"]

BACKENDS = ("cxxrtl", "verilator", "pysim")
#: pysim runs a few tens of thousands of edges a second: a short stretch of simulated time.
PYSIM_SECONDS = 0.002


class EchoedFollowTarget(wiring.Component):
    """``FollowTarget`` plus ``pong``, a registered copy of ``ping``."""

    def __init__(self, params):
        self.params = params
        members = dict(follow_target_signature(params).members)
        members.update(ping=In(1), pong=Out(1))
        super().__init__(wiring.Signature(members))

    def elaborate(self, platform):
        m = Module()
        m.submodules.follow = follow = FollowTarget(self.params)
        for name, member in follow.signature.members.items():
            if name in ("pixels", "filtered"):
                continue
            if member.flow == In:
                m.d.comb += getattr(follow, name).eq(getattr(self, name))
            else:
                m.d.comb += getattr(self, name).eq(getattr(follow, name))
        wiring.connect(m, wiring.flipped(self.pixels), follow.pixels)
        wiring.connect(m, follow.filtered, wiring.flipped(self.filtered))
        m.d.sync += self.pong.eq(self.ping)
        return m


def bench_source(params):
    return PinDesignSource(
        lambda: EchoedFollowTarget(params),
        f"echoed_follow_target_{params.width}x{params.height}",
        pixels=PIXEL_PORTS,
        filtered=FILTERED_PORTS,
        frame_size=(params.width, params.height),
    )


def bench_frames(params, count, seed=0):
    w, h = params.width, params.height
    return [
        to_rgb444(
            blob_frame(
                w, h, "red", cx=w * (0.2 + 0.6 * (i % 7) / 6), cy=h / 2, radius=h / 5, rng=seed + i
            ),
            w,
            h,
        )
        for i in range(count)
    ]


def run_once(pins, frames, *, seconds, clock_hz, fps, step_s, toggle_every):
    """One benchmark run on a fresh reset: returns (wall seconds, cycles, stops, frames)."""
    params_w, params_h = frames[0].shape[1], frames[0].shape[0]
    pins.reset()
    pins.poke("color_sel", 4)
    pins.watch(["pong", "motor_left", "motor_right"])
    total = round(seconds * clock_hz)
    step = max(1, round(step_s * clock_hz))
    frame_cycles = clock_hz / fps
    next_frame, next_toggle, ping, stops, streamed = 0, toggle_every, 0, 0, 0
    start = time.perf_counter()
    while pins.cycle < total:
        target = min(total, pins.cycle + step)
        while next_toggle <= target:  # the connector schedules its pin changes ahead
            ping ^= 1
            pins.schedule(next_toggle, "ping", ping)
            next_toggle += toggle_every
        capture = round(next_frame * frame_cycles) + 1
        if capture <= target and not pins.frame_pending:
            timing = real_clock_timing(
                params_w, params_h, fps, clock_hz, max(capture, pins.cycle + 1)
            )
            pins.stream_frame(frames[next_frame % len(frames)], timing)
            next_frame += 1
            streamed += 1
        while pins.cycle < target:
            stop = pins.run(target - pins.cycle)
            if stop.port is not None:
                stops += 1
    wall = time.perf_counter() - start
    return wall, pins.cycle, stops, streamed


def frame_path_once(backend, frames, cycles):
    """The frame backend on ``frames`` back to back (cycling) until ``cycles`` have run:
    simulated cycles per wall second."""
    backend.reset()
    done, i = 0, 0
    start = time.perf_counter()
    while done < cycles:
        done += backend.process_frame(frames[i % len(frames)], "red").cycles
        i += 1
    return done / (time.perf_counter() - start)


def benchmark(
    name, params, *, seconds, repeats, clock_hz, fps, step_s, toggle_every, seed=0, frame_path=True
):
    """Pin backend ``name``'s runs and, with ``frame_path``, the frame backend of the same
    simulator over as many cycles after each run (so that the machine's load of the moment
    weighs on both alike). Returns ``(pin rates, frame rates, runs)``, rates in cycles/s."""
    frames = bench_frames(params, 8, seed)
    pin_rates, frame_rates, runs = [], [], []
    with contextlib.ExitStack() as stack:
        pins = stack.enter_context(get_pin_backend(name, bench_source(params)))
        backend = stack.enter_context(get_backend(name, params)) if frame_path else None
        for _ in range(repeats):
            run = run_once(
                pins,
                frames,
                seconds=seconds,
                clock_hz=clock_hz,
                fps=fps,
                step_s=step_s,
                toggle_every=toggle_every,
            )
            runs.append(run)
            pin_rates.append(run[1] / run[0])
            if backend is not None:
                frame_rates.append(frame_path_once(backend, frames, run[1]))
    return pin_rates, frame_rates, runs


def _options(parser):
    scaffold.add_follow_target_design(parser)
    parser.add_argument(
        "--backends",
        default=",".join(BACKENDS),
        help=f"comma-separated (default {','.join(BACKENDS)})",
    )
    parser.add_argument(
        "--resolution",
        default="160x120",
        type=lambda text: scaffold.parse_size(text, "--resolution"),
    )
    parser.add_argument(
        "--seconds",
        type=float,
        default=1.0,
        help="simulated seconds per compiled run (default 1, at most 60)",
    )
    parser.add_argument(
        "--pysim-seconds",
        type=float,
        default=PYSIM_SECONDS,
        help=f"simulated seconds per pysim run (default {PYSIM_SECONDS}, at most 0.1)",
    )
    parser.add_argument("--clock-hz", type=float, default=50e6)
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument(
        "--step",
        type=float,
        default=1 / 240,
        help="physics step in seconds: one run() target (default 1/240)",
    )
    parser.add_argument(
        "--toggle-every",
        type=int,
        default=5000,
        help="cycles between toggles of the echoed pin (default 5000)",
    )


#: ``--OPTION``: (least, most) of its value; finite, more than the least (a run of none is no
#: figure), at most the most (bounding the run: seconds x clock are the cycles simulated).
_BOUNDS = {
    "seconds": (0, 60),
    "pysim_seconds": (0, 0.1),  # pysim runs some 40 000 cycles a second: 0.1 s is minutes
    "step": (0, 1),
    "clock_hz": (0, 1e9),
}


def _check(args):
    scaffold.check_follow_target_design(args, "pins")
    names = [n for n in args.backends.split(",") if n]
    unknown = sorted(set(names) - set(BACKENDS))
    if unknown:
        raise UsageError(
            f"unknown backend(s) {', '.join(unknown)}; choose from {', '.join(BACKENDS)}"
        )
    if not names:
        raise UsageError(f"--backends is empty; give some of {', '.join(BACKENDS)}")
    args.backends = list(dict.fromkeys(names))  # each backend once
    if args.toggle_every < 1:
        raise UsageError(f"--toggle-every must be positive, got {args.toggle_every}")
    for key, (least, most) in _BOUNDS.items():
        value = getattr(args, key)
        if not (math.isfinite(value) and least < value <= most):
            option = "--" + key.replace("_", "-")
            raise UsageError(
                f"{option} must be more than {least:g} and at most {most:g}, got {value:g}"
            )


def run(args):
    width, height = args.resolution
    try:
        params = FollowTargetParams(width=width, height=height)
    except ValueError as exc:
        raise UsageError(f"--resolution: {exc}") from None
    try:
        timing = real_clock_timing(width, height, args.fps, args.clock_hz, 1)
    except PinError as exc:
        raise UsageError(str(exc)) from None
    print(
        f"FollowTarget {width}x{height} + echoed pin, {args.clock_hz / 1e6:g} MHz, "
        f"{args.fps:g} fps: line_period {timing.line_period}, pixel_period "
        f"{timing.pixel_period}, ping toggled every {args.toggle_every} cycles, "
        f"physics step {args.step * 1e3:.3g} ms, median of {args.repeats} runs"
    )
    figures = []
    for name in args.backends:
        seconds = args.pysim_seconds if name == "pysim" else args.seconds
        try:
            pin_rates, frame_rates, runs = benchmark(
                name,
                params,
                seconds=seconds,
                repeats=args.repeats,
                clock_hz=args.clock_hz,
                fps=args.fps,
                step_s=args.step,
                toggle_every=args.toggle_every,
                frame_path=name != "pysim",
            )
        except (PinError, BackendError) as exc:
            print(f"{name}: not available ({exc})")
            continue
        _, cycles, stops, streamed = runs[0]
        row = {"backend": name, "pins_mcycles_per_s": statistics.median(pin_rates) / 1e6}
        line = (
            f"{name:9s} pins: {statistics.median(pin_rates) / 1e6:8.2f} Mcycles/s "
            f"({cycles:,} cycles, {streamed} frames, {stops} stops a run)"
        )
        if frame_rates:
            ratios = [p / f for p, f in zip(pin_rates, frame_rates, strict=True)]
            row.update(
                frame_mcycles_per_s=statistics.median(frame_rates) / 1e6,
                pins_over_frame=statistics.median(ratios),
            )
            line += (
                f"; frame path {statistics.median(frame_rates) / 1e6:.2f} Mcycles/s, "
                f"pins/frame {statistics.median(ratios):.2f} (median of the runs' ratios)"
            )
        print(line)
        figures.append(row)
    return {"backends": figures}


main = scaffold.command(run, __doc__, name="pins", options=_options, check=_check, repeats=5)
