"""The LIDAR's scan in the viewer: a recorded corridor run read back, the last revolution's
returns as points on the 2D map and, at the scan plane's height, in the 3D view."""

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz.lidar import SCANS3D
from fpga_robotics.viz.readback import read_rrd
from fpga_robotics.viz.sensors import MAP_SENSORS


@pytest.fixture(scope="module")
def corridor_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "corridor.rrd"
    s = load_scenario("corridor", ["sim.duration=0.5", "sim.clock_hz=1000000"])
    rec = open_recorder(f"save:{path}", default_path=str(path))
    result = run_scenario(s, backend="cxxrtl", recorder=rec)
    rec.close()
    return result, read_rrd(str(path))


def test_the_scan_is_drawn_in_2d_and_3d(corridor_run):
    result, data = corridor_run
    flat = data.entities[f"{MAP_SENSORS}/lidar/points"]
    deep = data.entities[f"{SCANS3D}/lidar"]
    # From the frame after the first revolution (0.18 s, 30 fps: frame 6) on.
    assert deep.frames[0] == flat.frames[0] == 6
    p2 = np.asarray(flat.values["Points2D:positions"][-1])
    p3 = np.asarray(deep.values["Points3D:positions"][-1])
    # Every returned sample of a revolution (a few hundred of its 363 or 364).
    n = round(
        result.trajectory["lidar.valid_fraction"][-1] * result.trajectory["lidar.samples"][-1]
    )
    assert len(p2) == len(p3) == n > 300
    assert np.allclose(p3[:, 2], 0.2)  # the mount's height
    assert np.allclose(p3[:, :2] * [1, -1], p2, atol=1e-5)  # the map's y axis is flipped
    # Each point is on a wall of the 6 x 1 m corridor or on the cabinet (x 2.2..2.8, y >= 0.8),
    # within the noise (1% of the range: up to 5.5 m to the far wall x = 6).
    x, y = p3[:, 0], p3[:, 1]
    on_wall = (
        (np.abs(y) < 0.05) | (np.abs(y - 1.0) < 0.05) | (np.abs(x) < 0.05) | (np.abs(x - 6) < 0.3)
    )
    on_cabinet = (x > 2.15) & (x < 2.85) & (y > 0.75)
    assert (on_wall | on_cabinet).all()
