"""The OV7670 sensor model's parameters: defaults, limits and where each default comes from.

A scenario sets them in ``[camera.ov7670]`` (``fpga_robotics.scenario`` checks them against
``PARAMS``); ``OV7670Params`` holds a checked set.
"""

from dataclasses import dataclass, fields

from .bayer import BAYER_ORDERS
from .gamma import GAMMA_CURVES

__all__ = ["PARAMS", "OV7670Params"]

#: name -> (default, kind, limits, unit, source). kind: "float", "int", "bool", "choice",
#: "pair" (two ints lo < hi); limits: (lo, hi) or the choices.
PARAMS = {
    "sensitivity": (
        1.2,
        "float",
        (0.01, 1000.0),
        "full scales",
        (
            "model choice: signal of a white (radiance 1) surface exposed a whole frame at gain 1; "
            "puts the shipped rooms at about half a frame of exposure, as an indoor scene at 30 fps"
        ),
    ),
    "aec": (True, "bool", None, "", "COM8[0] and COM8[2] (AEC, AGC) on at power-on"),
    "aec_window": (
        (0x63, 0x75),
        "pair",
        (0, 255),
        "8-bit luminance",
        "AEB 0x25 = 0x63, AEW 0x24 = 0x75 (stable operating region)",
    ),
    "aec_fast_zone": (
        (0x40, 0xD0),
        "pair",
        (0, 255),
        "8-bit luminance",
        "VPT 0x26 = 0xD4 (control zone {VPT[3:0],0} .. {VPT[7:4],0})",
    ),
    "max_gain": (32.0, "float", (1.0, 128.0), "", "COM9[6:4] = 100 (0x4A at power-on): 32x"),
    "exposure": (
        0.5,
        "float",
        (1 / 510, 1.0),
        "of a frame",
        "start (or, with aec = false, fixed) exposure time; 1/510: one row",
    ),
    "gain": (1.0, "float", (1.0, 128.0), "", "start (or fixed) analogue gain"),
    "settle_frames": (
        30,
        "int",
        (0, 1000),
        "frames",
        "frames of the first view before the run starts (the camera was on)",
    ),
    "awb": (True, "bool", None, "", "COM8[1] (AWB) on at power-on"),
    "awb_speed": (
        0.25,
        "float",
        (0.001, 1.0),
        "per frame",
        "model choice (a register sets it; no figure in the datasheet)",
    ),
    "gamma": (
        "default",
        "choice",
        tuple(GAMMA_CURVES),
        "",
        "GAM1..15 and SLOP at power-on; 'driver': the Linux driver's values",
    ),
    "noise": (True, "bool", None, "", "shot and read noise on"),
    "snr_db": (46.0, "float", (10.0, 80.0), "dB", "datasheet key specifications: S/N 46 dB"),
    "dynamic_range_db": (
        52.0,
        "float",
        (10.0, 100.0),
        "dB",
        "datasheet key specifications: dynamic range 52 dB",
    ),
    "bayer": (
        "BGGR",
        "choice",
        tuple(BAYER_ORDERS) + ("off",),
        "",
        "the raw output's first lines B G B G ..., G R G R ...",
    ),
    "motion_blur": (True, "bool", None, "", "smear from the robot's turn rate over the exposure"),
    "input_gamma": (
        1.0,
        "float",
        (0.1, 5.0),
        "",
        ("the renderer's 8-bit values are linear in light (1.0); 2.2 for an sRGB renderer"),
    ),
}


@dataclass(frozen=True)
class OV7670Params:
    sensitivity: float = PARAMS["sensitivity"][0]
    aec: bool = PARAMS["aec"][0]
    aec_window: tuple = PARAMS["aec_window"][0]
    aec_fast_zone: tuple = PARAMS["aec_fast_zone"][0]
    max_gain: float = PARAMS["max_gain"][0]
    exposure: float = PARAMS["exposure"][0]
    gain: float = PARAMS["gain"][0]
    settle_frames: int = PARAMS["settle_frames"][0]
    awb: bool = PARAMS["awb"][0]
    awb_speed: float = PARAMS["awb_speed"][0]
    gamma: str = PARAMS["gamma"][0]
    noise: bool = PARAMS["noise"][0]
    snr_db: float = PARAMS["snr_db"][0]
    dynamic_range_db: float = PARAMS["dynamic_range_db"][0]
    bayer: str = PARAMS["bayer"][0]
    motion_blur: bool = PARAMS["motion_blur"][0]
    input_gamma: float = PARAMS["input_gamma"][0]

    @classmethod
    def from_dict(cls, values):
        """From a checked ``{name: value}`` (missing names take their defaults)."""
        known = {f.name for f in fields(cls)}
        return cls(
            **{k: tuple(v) if isinstance(v, list) else v for k, v in values.items() if k in known}
        )
