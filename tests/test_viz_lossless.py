"""A closed-loop run's recording holds the frames the design received and made, bit for bit.

The gateware runs on the compiled backend; every frame's camera image and the design's
filtered output are kept as the loop hands them over, and the recording is read back from
the saved .rrd (``viz.readback.images``) and compared with them. By the hardware contract
(docs/contract.md) the design receives each channel's top four bits (``c >> 4``), shown as
``c << 4``; with ``camera="rgb888"`` the full 8-bit render is kept instead.
"""

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.frames import rgb444_to_rgb888
from fpga_robotics.viz import ViewerError, open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.images import decode_image, encode_rgb444
from fpga_robotics.viz.readback import images, read_rrd

pytestmark = pytest.mark.timeout(600)  # a first build of the compiled model included

RAW_BYTES = 160 * 120 * 3  # one 160x120 RGB888 frame, uncompressed
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_header(data):
    """``(bit depth, colour type)`` from a PNG's IHDR (colour type 2 RGB, 3 palette)."""
    data = bytes(data)
    assert data[:8] == PNG_SIGNATURE and data[12:16] == b"IHDR"
    return data[24], data[25]


@pytest.fixture(scope="module", params=["rgb444", "rgb888"])
def run(request, tmp_path_factory):
    path = tmp_path_factory.mktemp("lossless") / "run.rrd"
    scenario = load_scenario("follow_person", ["sim.duration=1"])
    seen = []

    def keep(record):  # copies: the loop may reuse its arrays
        seen.append((record.frame, np.array(record.camera_rgb), np.array(record.result.filtered)))

    with open_recorder(f"save:{path}", default_path=str(path), camera=request.param) as rec:
        run_scenario(scenario, backend="cxxrtl", recorder=rec, on_frame=keep)
    return request.param, read_rrd(str(path)), seen


def test_camera_and_filtered_frames_read_back_bit_for_bit(run):
    camera_format, data, seen = run
    assert len(seen) == 30  # 1 s at 30 frames/s
    camera, filtered = images(data, P.CAMERA_RAW), images(data, P.CAMERA_FILTERED)
    assert sorted(camera) == sorted(filtered) == [frame for frame, _, _ in seen]
    for frame, rgb, packed in seen:
        assert camera[frame].shape == (120, 160, 3)
        if camera_format == "rgb444":
            # What the design received: each channel's top four bits, nothing else.
            np.testing.assert_array_equal(camera[frame] >> 4, rgb >> 4, err_msg=f"frame {frame}")
            np.testing.assert_array_equal(camera[frame] & 0x0F, 0, err_msg=f"frame {frame}")
        else:
            np.testing.assert_array_equal(camera[frame], rgb, err_msg=f"camera, frame {frame}")
        np.testing.assert_array_equal(
            filtered[frame], rgb444_to_rgb888(packed), err_msg=f"filtered, frame {frame}"
        )
    # The target is in view: the filtered frames are not blank (a blank frame proves little).
    assert all(np.count_nonzero(packed) > 100 for _, _, packed in seen)
    # The sensor noise is in the render: the 8-bit frame's low bits are not all the same.
    assert all(len(np.unique(rgb & 0x0F)) > 8 for _, rgb, _ in seen)


def test_frames_are_png_and_the_file_a_fifth_of_raw(run):
    camera_format, data, seen = run
    for path in (P.CAMERA_RAW, P.CAMERA_FILTERED):
        values = data.entities[path].values
        assert {t for row in values["EncodedImage:media_type"] for t in row} == {"image/png"}
    blobs = {
        path: [row[0] for row in data.entities[path].values["EncodedImage:blob"]]
        for path in (P.CAMERA_RAW, P.CAMERA_FILTERED)
    }
    # The filtered frame and the RGB444 camera frame hold a few dozen colours: palettes.
    assert {png_header(b)[1] for b in blobs[P.CAMERA_FILTERED]} == {3}
    assert max(len(b) for b in blobs[P.CAMERA_FILTERED]) < RAW_BYTES / 20
    if camera_format == "rgb444":
        assert {png_header(b)[1] for b in blobs[P.CAMERA_RAW]} == {3}
        assert max(len(b) for b in blobs[P.CAMERA_RAW]) < RAW_BYTES / 10
        # The whole recording: at most a fifth of its two frames a frame, uncompressed.
        assert data.size_bytes < len(seen) * 2 * RAW_BYTES / 5
    else:
        assert {png_header(b)[1] for b in blobs[P.CAMERA_RAW]} == {2}  # 8-bit RGB
        assert max(len(b) for b in blobs[P.CAMERA_RAW]) < RAW_BYTES / 2


def packed_rgb444(h, w, colours, seed):
    """A packed RGB444 frame of ``colours`` distinct 12-bit values, each used at least once."""
    rng = np.random.default_rng(seed)
    palette = rng.choice(4096, size=colours, replace=False).astype(np.uint16)
    frame = palette[rng.integers(0, colours, h * w)]
    frame[:colours] = palette  # every colour present
    return frame.reshape(h, w)


@pytest.mark.parametrize(
    ("colours", "colour_type"), [(2, 3), (16, 3), (17, 3), (256, 3), (257, 2), (4096, 2)]
)
def test_rgb444_png_is_exact_for_any_number_of_colours(colours, colour_type):
    # Palettes up to 256 colours, an RGB PNG above; always 8 bits a sample (the viewer
    # refuses a stream whose bit depth changes).
    packed = packed_rgb444(96, 128, colours, seed=colours)
    kind, data = encode_rgb444(packed, None)
    assert kind == "png"
    assert png_header(data) == (8, colour_type)
    np.testing.assert_array_equal(decode_image(data), rgb444_to_rgb888(packed))


def test_rgb444_above_160x120_is_jpeg_and_raw_on_request():
    packed = packed_rgb444(480, 640, 40, seed=1)
    kind, data = encode_rgb444(packed, None)
    assert kind == "jpeg" and bytes(data[:2]) == b"\xff\xd8"
    kind, data = encode_rgb444(packed, 0)
    assert kind == "raw"
    np.testing.assert_array_equal(data, rgb444_to_rgb888(packed))


def test_an_unknown_camera_format_is_refused_before_any_file(tmp_path):
    path = tmp_path / "x.rrd"
    with pytest.raises(ViewerError, match="rgb444, rgb888"):
        open_recorder(f"save:{path}", default_path=str(path), camera="rgb565")
    assert list(tmp_path.iterdir()) == []
