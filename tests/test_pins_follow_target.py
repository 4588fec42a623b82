"""``FollowTarget`` on the pin backends, its frames streamed with blanking, equals the numpy
golden model (``ModelBackend`` on the same frames) frame by frame: the per-frame outputs
after ``frame_done``, the motors ``motor_latency`` edges later, and the filtered frame, over
sequences that lose the target long enough for the motors to search and find it again
(state across frames). pysim at a small geometry, the compiled backends there and at
160x120 with the real-clock timing of a 50 MHz clock at 30 fps.
"""

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.pins import (
    PixelTiming,
    follow_target_source,
    get_pin_backend,
    real_clock_timing,
)

SMALL = FollowTargetParams(
    width=20,
    height=12,
    min_pixels=6,
    proximity_thresholds=(6, 12, 20, 30, 45, 60, 80),
    lost_frames=2,
    search_dps=-120,
)
RESULTS = ("found", "proximity", "centroid_x", "centroid_leds")


def frames_for(params, seed):
    """A target crossing, then lost for lost_frames + 1 frames (search), then found again."""
    w, h = params.width, params.height
    rng = np.random.default_rng(seed)
    frames = [
        synthetic.blob_frame(w, h, "red", cx=w * x, cy=h / 2, radius=h / 4, rng=rng)
        for x in (0.25, 0.5, 0.8)
    ]
    frames += [
        synthetic.blob_frame(w, h, "green", radius=h / 4, rng=rng)
        for _ in range(params.lost_frames + 1)
    ]
    frames.append(synthetic.blob_frame(w, h, "red", cx=w * 0.3, cy=h * 0.4, radius=h / 3, rng=rng))
    return frames


def pin_frame(pins, params, packed, timing):
    """Stream one frame; the per-frame outputs at frame_done and the motors after the
    motor latency, as the frame backends report them. Bounded by a watchdog."""
    w, h = params.width, params.height
    pins.stream_frame(packed, timing)
    pins.watch(["frame_done"])
    deadline = timing.last_edge(w, h) + params.result_latency + 64
    while True:
        stop = pins.run(deadline - pins.cycle)
        assert stop.port == "frame_done", f"no frame_done by edge {deadline}"
        if stop.value:
            break
    # frame_done comes result_latency edges after the edge that samples the last pixel.
    assert stop.cycle == timing.last_edge(w, h) + params.result_latency
    got = {name: pins.peek(name) for name in RESULTS}
    pins.watch([])
    pins.run(params.motor_latency)
    got["motor_left"], got["motor_right"] = pins.peek("motor_left"), pins.peek("motor_right")
    return got


def expected(result):
    return {
        "found": int(result.found),
        "proximity": result.proximity,
        "centroid_x": result.centroid_x,
        "centroid_leds": result.centroid_leds,
        "motor_left": result.motor_left,
        "motor_right": result.motor_right,
    }


def check_sequence(name, params, frames, timing_of):
    w, h = params.width, params.height
    with get_pin_backend(name, follow_target_source(params)) as pins, ModelBackend(params) as model:
        pins.poke("color_sel", 4)
        searched = False
        for i, frame in enumerate(frames):
            want = model.process_frame(frame, "red")
            got = pin_frame(pins, params, to_rgb444(frame, w, h), timing_of(pins.cycle))
            assert got == expected(want), f"{name} frame {i}"
            # The frame's filtered stream ends filter_latency edges after its last pixel.
            pins.run(params.filter_latency + 1)
            np.testing.assert_array_equal(
                pins.filtered_frame(), want.filtered, err_msg=f"{name} frame {i}"
            )
            searched |= not want.found and want.motor_left == -want.motor_right != 0
        assert searched  # the sequence did reach the motors' search


@pytest.mark.parametrize(
    "name", ["pysim", "cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)]
)
def test_small_geometry_with_sparse_pixels(name):
    # Pixels every 3rd edge, 9 idle edges after a line, frames 50 edges apart.
    frames = frames_for(SMALL, 1)
    check_sequence(
        name,
        SMALL,
        frames,
        lambda cycle: PixelTiming(start=cycle + 50, line_period=3 * 20 + 9, pixel_period=3),
    )


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_160x120_in_real_clock_time(name):
    params = FollowTargetParams(lost_frames=2)
    frames = frames_for(params, 2)
    frame_cycles = round(50e6 / 30)
    # Each frame at its capture edge: the next multiple of the frame period.
    check_sequence(
        name,
        params,
        frames,
        lambda cycle: real_clock_timing(
            160, 120, 30, 50e6, (cycle // frame_cycles + 1) * frame_cycles
        ),
    )
