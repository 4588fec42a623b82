"""A closed-loop run's recording holds the frames the design saw and made, bit for bit.

The gateware runs on the compiled backend; every frame's camera image and the design's
filtered output are kept as the loop hands them over, and the recording is read back from
the saved .rrd (``viz.readback.images``) and compared with them.
"""

import numpy as np
import pytest

from fpga_robotics.loop.compressed import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.frames import rgb444_to_rgb888
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import images, read_rrd

pytestmark = pytest.mark.timeout(600)  # a first build of the compiled model included


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    path = tmp_path_factory.mktemp("lossless") / "run.rrd"
    scenario = load_scenario("follow_person", ["sim.duration=1"])
    seen = []

    def keep(record):  # copies: the loop may reuse its arrays
        seen.append((record.frame, np.array(record.camera_rgb), np.array(record.result.filtered)))

    with open_recorder(f"save:{path}", default_path=str(path)) as rec:
        run_scenario(scenario, backend="cxxrtl", recorder=rec, on_frame=keep)
    return read_rrd(str(path)), seen


def test_camera_and_filtered_frames_read_back_bit_for_bit(run):
    data, seen = run
    assert len(seen) == 30  # 1 s at 30 frames/s
    camera, filtered = images(data, P.CAMERA_RAW), images(data, P.CAMERA_FILTERED)
    assert sorted(camera) == sorted(filtered) == [frame for frame, _, _ in seen]
    for frame, rgb, packed in seen:
        assert camera[frame].shape == (120, 160, 3)
        np.testing.assert_array_equal(camera[frame], rgb, err_msg=f"camera, frame {frame}")
        np.testing.assert_array_equal(
            filtered[frame], rgb444_to_rgb888(packed), err_msg=f"filtered, frame {frame}"
        )
    # The target is in view: the filtered frames are not blank (a blank frame proves little).
    assert all(np.count_nonzero(packed) > 100 for _, _, packed in seen)


def test_frames_are_png_at_most_half_their_raw_size(run):
    data, _ = run
    raw_bytes = 160 * 120 * 3
    for path in (P.CAMERA_RAW, P.CAMERA_FILTERED):
        values = data.entities[path].values
        assert {t for row in values["EncodedImage:media_type"] for t in row} == {"image/png"}
        sizes = [len(row[0]) for row in values["EncodedImage:blob"]]
        assert max(sizes) < raw_bytes / 2, (path, max(sizes))
