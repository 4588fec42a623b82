"""``fpga-robotics bench foreign``: the exported ``follow_target`` run as a
foreign Verilog design (through a stream port map) against the built-in verilator backend,
milliseconds per frame on the same frames, taken in alternation (each frame through one, then
the other, taking turns at going first) and timed by the thread's CPU time, so that both see
the same machine. Both build once into the cache; the first run compiles for a minute or so.
"""

import sys
import tempfile
import time
from pathlib import Path

from fpga_robotics.bench import scaffold
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.backends import get_backend
from fpga_robotics.sim.backends.foreign import ForeignVerilatorBackend
from fpga_robotics.sim.backends.port_map import follow_target_port_map
from fpga_robotics.sim.camera import synthetic

__all__ = ["main"]


def _alternating_ms(backends, frames, repeats):
    """Median CPU milliseconds a frame of each backend: ``repeats`` passes over ``frames``,
    each frame through both in turn."""
    times = [[] for _ in backends]
    for backend in backends:
        backend.process_frame(frames[0])  # warm-up
    with scaffold.gc_paused():
        for n in range(repeats * len(frames)):
            frame = frames[n % len(frames)]
            order = range(len(backends)) if n % 2 == 0 else reversed(range(len(backends)))
            for i in order:
                with scaffold.stopwatch(time.thread_time) as t:
                    backends[i].process_frame(frame)
                times[i].append(t.cpu * 1e3)
    return [scaffold.Spread.of(t).median for t in times]


def run(args):
    params = FollowTargetParams(width=160, height=120)
    frames = synthetic.scenario("sweep", 160, 120, n_frames=args.frames, rng=1).frames

    def tell(text):
        print(f"{text} ...", file=sys.stderr, flush=True)

    with tempfile.TemporaryDirectory(prefix="fr-foreign-bench-") as tmp:
        verilog, ports = Path(tmp) / "follow_target.v", Path(tmp) / "ports.toml"
        verilog.write_text(generate_verilog(params))
        ports.write_text(follow_target_port_map(params))
        foreign = ForeignVerilatorBackend(params, files=[verilog], port_map=ports, on_build=tell)
    builtin = get_backend("verilator", params, on_build=tell)
    try:
        ms_builtin, ms_foreign = _alternating_ms((builtin, foreign), frames, args.repeats)
    finally:
        builtin.close()
        foreign.close()
    print(
        f"160x120, {args.frames} frames x {args.repeats} passes in alternation; median CPU "
        f"time a frame:"
    )
    print(f"  verilator (built-in)          {ms_builtin:7.3f} ms/frame")
    print(
        f"  foreign follow_target (stream) {ms_foreign:6.3f} ms/frame  "
        f"({ms_foreign / ms_builtin:.2f}x the built-in)"
    )
    return {
        "builtin_cpu_ms": ms_builtin,
        "foreign_cpu_ms": ms_foreign,
        "foreign_over_builtin": ms_foreign / ms_builtin,
    }


main = scaffold.command(run, __doc__, name="foreign", repeats=3, frames=20)
