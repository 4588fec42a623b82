"""The pin unit judge's stimulus: seeded random inputs, and a camera design's pixel stream as
frames of random pixels in raster order (first and last flags where the camera sets them)."""

from fpga_robotics.mutation.pin_judge import pin_stimulus, streams_frames
from fpga_robotics.sim.pins.base import Port

FIRST, LAST = 1 << 12, 1 << 13

PORTS = {
    "pixels__valid": Port("pixels__valid", 1, "in", False),
    "pixels__payload": Port("pixels__payload", 14, "in", False),
    "color_sel": Port("color_sel", 3, "in", False),
    "bump": Port("bump", 1, "in", False),
    "mutsel": Port("mutsel", 4, "in", False),
    "motor_left": Port("motor_left", 16, "out", True),
}


def _of(stimulus, name):
    return [(edge, value) for edge, port, value in stimulus if port == name]


def test_frames_of_4x3_in_raster_order():
    stimulus = pin_stimulus(PORTS, 40, seed=3, frame=(4, 3))
    # A frame is 12 pixels from edge 1, then a line (4 edges) without: the next at edge 17,
    # the third at 33, cut at edge 40.
    assert _of(stimulus, "pixels__valid") == [(1, 1), (13, 0), (17, 1), (29, 0), (33, 1)]
    payload = _of(stimulus, "pixels__payload")
    assert [e for e, _ in payload] == [*range(1, 13), *range(17, 29), *range(33, 41)]
    for start in (1, 17, 33):
        flags = {e - start: v & (FIRST | LAST) for e, v in payload if start <= e < start + 12}
        # first on the frame's first pixel, last on each line's last (x = 3).
        assert flags == {k: (FIRST if k == 0 else 0) | (LAST if k % 4 == 3 else 0) for k in flags}
    # Random RGB444 pixels, not one value.
    assert len({v & 0xFFF for _, v in payload}) > 20
    # The other inputs are random as before; mutsel never changes; outputs are not driven.
    assert _of(stimulus, "bump") and _of(stimulus, "color_sel")
    assert not _of(stimulus, "mutsel") and not _of(stimulus, "motor_left")
    assert stimulus == sorted(stimulus)


def test_without_a_frame_size_or_a_stream_every_input_is_random():
    assert streams_frames(PORTS)
    plain = {k: v for k, v in PORTS.items() if k != "pixels__valid"}
    assert not streams_frames(plain)
    # The same seed: the same changes, frame or not, where there is no stream.
    assert pin_stimulus(plain, 200, seed=1, frame=(4, 3)) == pin_stimulus(plain, 200, seed=1)
    random_valid = _of(pin_stimulus(PORTS, 400, seed=1), "pixels__valid")
    assert len(random_valid) > 10  # about 1 edge in 8, at random
