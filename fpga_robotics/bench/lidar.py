"""``fpga-robotics bench lidar``: what a LIDAR revolution costs in the closed loop, against a
camera frame of FollowTarget, and the serial binding's design cycles per second.

Three closed-loop runs of ``--duration`` simulated seconds each, taking turns ``--repeats``
times (the machine is shared; alternating lets all three see the same periods), timed by the
process's CPU time: ``corridor`` (CorridorFollow on the LIDAR's sample stream, real clock),
``follow_person`` at 160x120 (FollowTarget, compressed timing: its frames) and
``corridor_uart`` (the same design behind a UART, on the LIDAR's serial bytes). Printed: the
CPU milliseconds per LIDAR revolution (5.5 a second) and per camera frame (30 a second), their
ratio, and the design clock cycles each real-clock run simulated per CPU second (and per
millisecond, as a time ``--calibrate`` turns into a multiple of ``bench calibrate``'s frame).
"""

import statistics

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

__all__ = ["main", "measure"]

_RUNS = {
    "lidar_stream": "corridor",
    "camera_frame": "follow_person",
    "lidar_uart": "corridor_uart",
}


def measure(backend, duration, repeats):
    """``{run: [(cpu_s, summary), ...]}`` of the three runs, in turns."""

    def load(key, seconds):
        extra = ['camera.resolution="160x120"'] if key == "camera_frame" else []
        return load_scenario(_RUNS[key], [f"sim.duration={seconds}", *extra])

    scenarios = {key: load(key, duration) for key in _RUNS}
    for key in _RUNS:  # each design built (or found in the cache) before timing
        run_scenario(load(key, 0.1), backend=backend)
    out = {key: [] for key in scenarios}
    for _ in range(repeats):
        for key, s in scenarios.items():
            with scaffold.gc_paused(), scaffold.stopwatch() as t:
                result = run_scenario(s, backend=backend)
            out[key].append((t.cpu, result.summary))
    return out


def _options(parser):
    parser.add_argument(
        "--duration",
        type=float,
        default=2.0,
        help="simulated seconds of each run (default 2: 11 revolutions, 60 frames)",
    )
    parser.add_argument(
        "--backend",
        default="cxxrtl",
        choices=("cxxrtl", "verilator", "pysim"),
        help="design simulator of the three runs (default cxxrtl)",
    )


def _check(args):
    if not 0.5 <= args.duration <= 600:
        raise UsageError(
            f"--duration must be 0.5..600 s (at least 2 revolutions), got {args.duration}"
        )


def run(args):
    runs = measure(args.backend, args.duration, args.repeats)
    revolutions = args.duration * 5.5
    figures = {"duration_s": args.duration, "backend": args.backend}
    rev_ms = [1000 * cpu / revolutions for cpu, _ in runs["lidar_stream"]]
    frame_ms = [1000 * cpu / s["frames"] for cpu, s in runs["camera_frame"]]
    ratios = [r / f for r, f in zip(rev_ms, frame_ms, strict=True)]
    figures["revolution_ms"] = scaffold.Spread.of(rev_ms)
    figures["frame_ms"] = scaffold.Spread.of(frame_ms)
    figures["revolution_over_frame"] = statistics.median(ratios)
    print(
        f"{args.duration:g} s runs on {args.backend}, CPU time, median (min-max) of "
        f"{args.repeats} turns"
    )
    print(f"  LIDAR revolution, stream binding (corridor):   {figures['revolution_ms']:.1f} ms")
    print(f"  camera frame 160x120, FollowTarget:            {figures['frame_ms']:.1f} ms")
    print(f"  revolution / frame: {figures['revolution_over_frame']:.2f} (median of the turns)")
    for key, what in (("lidar_stream", "stream"), ("lidar_uart", "UART")):
        rates = [s["sim_cycles"] / cpu for cpu, s in runs[key]]
        figures[f"{key}_mcycles_per_cpu_s"] = scaffold.Spread.of(r / 1e6 for r in rates)
        figures[f"{key}_ms_per_mcycle"] = scaffold.Spread.of(1e9 / r for r in rates)
        print(
            f"  {what:6s} binding, real clock at {runs[key][0][1]['clock_hz'] / 1e6:g} MHz: "
            f"{figures[f'{key}_mcycles_per_cpu_s']:.2f} Mcycles per CPU second"
        )
    return figures


main = scaffold.command(run, __doc__, name="lidar", options=_options, check=_check, repeats=3)
