"""``fpga-robotics bench foreign``: the exported ``follow_target`` run as a
foreign Verilog design (through a stream port map) against the built-in verilator backend,
milliseconds per frame on the same frames. Both build once into the cache; the first run
compiles for a minute or so.
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


def _ms_per_frame(backend, frames, repeats):
    backend.process_frame(frames[0])  # warm-up
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for frame in frames:
            backend.process_frame(frame)
        best = min(best, (time.perf_counter() - t0) / len(frames))
    return best * 1e3


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
        ms_builtin = _ms_per_frame(builtin, frames, args.repeats)
        ms_foreign = _ms_per_frame(foreign, frames, args.repeats)
    finally:
        builtin.close()
        foreign.close()
    print(f"160x120, {args.frames} frames, best of {args.repeats}:")
    print(f"  verilator (built-in)          {ms_builtin:7.3f} ms/frame")
    print(f"  foreign follow_target (stream) {ms_foreign:6.3f} ms/frame  "
          f"({ms_foreign / ms_builtin:.2f}x the built-in)")
    return {"builtin_ms": ms_builtin, "foreign_ms": ms_foreign,
            "foreign_over_builtin": ms_foreign / ms_builtin}


main = scaffold.command(run, __doc__, name="foreign", repeats=3, frames=20)
