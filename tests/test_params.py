"""FollowTargetParams: the contract's defaults, scaling, and clear validation errors."""

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams


def test_defaults_at_160x120():
    p = FollowTargetParams()
    assert (p.width, p.height) == (160, 120)
    assert (p.margin_x, p.margin_y) == (16, 8)
    assert (p.window_width, p.window_height, p.bin_width) == (128, 104, 16)
    assert p.min_pixels == 128
    assert p.proximity_thresholds == (128, 256, 512, 1024, 2048, 4096, 6144)
    assert p.base_dps == (0, 400, 300, 200, 150, 100, -100, -150)
    assert (p.kp_num, p.kp_shift, p.max_dps, p.lost_frames, p.search_dps) == (3, 0, 512, 15, 250)
    assert p.x_bits == 8  # centroid_x is 8 bits at 160x120 (docs/contract.md, Ports)
    # The knobs of the published design, at this design's choices.
    assert (
        p.found_rule,
        p.group_column_offset,
        p.motor_law,
        p.lost_motion,
        p.search_side_from,
        p.centred_search_side,
    ) == ("ge", 0, "p_control", "hold", "centroid", "right")
    assert p.steer_dps == (125, 175, 225, 275)


@pytest.mark.parametrize("w,h,scale,mx,my", [(320, 240, 4, 32, 16), (640, 480, 16, 64, 32)])
def test_defaults_scale_with_the_frame_area(w, h, scale, mx, my):
    p = FollowTargetParams(width=w, height=h)
    assert p.area_scale == scale
    assert (p.margin_x, p.margin_y) == (mx, my)
    assert p.min_pixels == 128 * scale
    assert p.proximity_thresholds[-1] == 6144 * scale


def test_small_geometries_keep_the_160x120_thresholds():
    p = FollowTargetParams(width=40, height=30)
    assert p.area_scale == 1 and p.min_pixels == 128


def test_replace_recomputes_geometry_defaults_but_keeps_explicit_values():
    p = FollowTargetParams(kp_num=5).replace(width=320, height=240)
    assert p.kp_num == 5 and p.margin_x == 32 and p.min_pixels == 512
    assert p.replace(min_pixels=7).min_pixels == 7


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"width": 164}, "divisible by 8"),
        ({"margin_x": 80}, "leaves no window"),
        ({"diff_min": 16}, "diff_min must be <= 15"),
        ({"diff_min": -1}, "diff_min must be >= 0"),
        ({"min_pixels": 0}, "min_pixels must be >= 1"),
        ({"proximity_thresholds": (1, 2, 3)}, "needs 7 values"),
        ({"proximity_thresholds": (7, 6, 5, 4, 3, 2, 1)}, "non-decreasing"),
        ({"proximity_thresholds": (-1, 2, 3, 4, 5, 6, 7)}, ">= 0"),
        ({"base_dps": (0, 1, 2)}, "needs 8 values"),
        ({"base_dps": (0, 1, 2, 3, 4, 5, 6, 40000)}, "base_dps[7] must be <= 32767"),
        ({"max_dps": 1 << 15}, "max_dps must be <= 32767"),
        ({"kp_shift": 16}, "kp_shift must be <= 15"),
        ({"lost_frames": 0}, "lost_frames must be >= 1"),
        ({"search_dps": -(1 << 15)}, "search_dps must be >= -32767"),
        ({"found_rule": "gte"}, "found_rule must be one of ge, gt; got 'gte'"),
        ({"group_column_offset": 2}, "group_column_offset must be <= 1"),
        ({"group_column_offset": -1}, "group_column_offset must be >= 0"),
        ({"motor_law": "P"}, "motor_law must be one of p_control, table"),
        ({"steer_dps": (1, 2, 3)}, "steer_dps needs 4 values"),
        ({"steer_dps": (1, 2, 3, -4)}, "steer_dps[3] must be >= 0"),
        ({"steer_dps": (1, 2, 1 << 15, 4)}, "steer_dps[2] must be <= 32767"),
        ({"lost_motion": "coast"}, "lost_motion must be one of hold, drive"),
        ({"lost_motion": "drive"}, "lost_motion='drive' needs motor_law='table'"),
        ({"search_side_from": "led"}, "search_side_from must be one of centroid, leds"),
        ({"centred_search_side": "centre"}, "centred_search_side must be one of right, left"),
        ({"sx_bits": 0}, "sx_bits must be >= 1"),
        ({"sx_bits": 23}, "sx_bits must be <= 22"),  # the full width at 160x120
    ],
)
def test_bad_values_raise_clear_errors(kwargs, message):
    with pytest.raises(ValueError) as info:
        FollowTargetParams(**kwargs)
    assert message in str(info.value)


def test_wrong_types_raise_type_error():
    with pytest.raises(TypeError, match="width must be an int"):
        FollowTargetParams(width=160.0)
    with pytest.raises(TypeError, match="kp_num must be an int"):
        FollowTargetParams(kp_num=True)
    with pytest.raises(TypeError, match="group_column_offset must be an int"):
        FollowTargetParams(group_column_offset=True)
    with pytest.raises(TypeError, match="found_rule must be a string, one of ge, gt"):
        FollowTargetParams(found_rule=1)
    with pytest.raises(TypeError, match=r"steer_dps\[0\] must be an int"):
        FollowTargetParams(steer_dps=(1.5, 2, 3, 4))
    with pytest.raises(TypeError, match="sx_bits must be an int"):
        FollowTargetParams(sx_bits=17.0)


def test_numpy_integers_are_accepted_and_stored_as_int():
    p = FollowTargetParams(
        width=np.int64(320),
        height=np.uint16(240),
        kp_num=np.int32(2),
        base_dps=tuple(np.arange(8, dtype=np.int16)),
    )
    assert (p.width, p.height, p.kp_num) == (320, 240, 2)
    assert all(type(v) is int for v in (p.width, p.height, p.kp_num, *p.base_dps))
    assert p == FollowTargetParams(width=320, height=240, kp_num=2, base_dps=tuple(range(8)))


def test_the_knobs_are_independent_of_the_motor_law_where_they_can_be():
    # The search side from the LEDs and the table law without "drive" are valid with the
    # other law; "drive" needs the table (it steers by the last LED code).
    FollowTargetParams(search_side_from="leds", centred_search_side="left")
    FollowTargetParams(motor_law="table")
    FollowTargetParams(motor_law="table", lost_motion="drive", steer_dps=(0, 0, 0, 0))
    assert FollowTargetParams(motor_law="table").motor_uses_leds
    assert FollowTargetParams(search_side_from="leds").motor_uses_leds
    assert not FollowTargetParams().motor_uses_leds


def test_replace_keeps_the_knobs():
    p = FollowTargetParams.published().replace(kp_num=2)
    assert p == FollowTargetParams.published(kp_num=2)


def test_sx_bits_narrows_the_column_sum_and_defaults_to_the_full_width():
    # SX of a window that matches everywhere: 128 * 104 pixels, columns up to 159 at 160x120.
    p = FollowTargetParams()
    assert p.sx_bits is None
    assert p.sum_x_bits == p.full_sum_x_bits == (128 * 104 * 159).bit_length() == 22
    assert FollowTargetParams(sx_bits=17).sum_x_bits == 17
    assert FollowTargetParams(sx_bits=22) != p  # the same width, but an explicit value
    assert FollowTargetParams(width=640, height=480).full_sum_x_bits == 28
    assert FollowTargetParams(sx_bits=17).replace(kp_num=2).sx_bits == 17
