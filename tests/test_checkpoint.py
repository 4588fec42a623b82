"""World checkpoints: a run restored at a middle frame and continued is bit-identical to the
uninterrupted run, on every shipped scenario in compressed timing."""

import pytest
from run_equality import assert_same_run

from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.compressed import ClosedLoop
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario, shipped_scenarios
from fpga_robotics.sim.backends.model import ModelBackend

COMPRESSED = [n for n in shipped_scenarios() if load_scenario(n).sim.timing == "compressed"]


@pytest.mark.parametrize("name", COMPRESSED)
def test_restored_run_is_the_uninterrupted_run(name):
    s = load_scenario(name, ["sim.duration=2.5"])
    full = run_scenario(s, backend="model")

    # The same run, stopped at a middle frame to take a checkpoint, then run on.
    seen = []  # the images the design saw, with the colour select
    with ModelBackend(s.params) as design:
        design.reset()
        loop = ClosedLoop(
            s, design=design, on_frame=lambda r: seen.append((r.camera_rgb, r.color_sel))
        )
        middle = loop.n_frames // 2
        for k in range(middle):
            loop.run_frame(k)
        saved = checkpoint.take(loop)
        assert saved.frame == middle
        assert_same_run(loop.run(start=middle), full)

    # A loop that has run elsewhere (another design, its own frames), restored, with a design
    # brought to frame `middle` on the recorded images, continues exactly as the full run.
    with ModelBackend(s.params) as other, ModelBackend(s.params) as design:
        other.reset()
        resumed = ClosedLoop(s, design=other)
        for k in range(3):
            resumed.run_frame(k)
        checkpoint.restore(resumed, saved)
        design.reset()
        for rgb, color in seen[:middle]:
            design.process_frame(rgb, color)
        resumed.design = design
        assert_same_run(resumed.run(start=middle), full)
    # The checkpoint is left as it was: a second restore gives the same run again.
    with ModelBackend(s.params) as design:
        design.reset()
        again = ClosedLoop(s, design=design)
        checkpoint.restore(again, saved)
        for rgb, color in seen[:middle]:
            design.process_frame(rgb, color)
        assert_same_run(again.run(start=middle), full)
