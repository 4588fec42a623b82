"""Motion blur: the image moving sideways while the pixels integrate light.

A robot turning at ``w`` rad/s sweeps the image sideways by ``w * f`` pixels a second (``f`` the
focal length in pixels; exact at the image centre, ``f / cos^2`` of the angle off-axis, which
the model ignores); during an exposure of ``t`` seconds that is a smear ``L = |w| * t * f``
pixels long. Each output pixel is the time average of the scene over the exposure: the
piecewise-constant input image convolved with a box ``L`` pixels wide centred on the pixel
(the frame stands for the middle of its exposure). Box weight of input pixel ``j`` off the
centre: the overlap of ``[j - 1/2, j + 1/2]`` with ``[-L/2, L/2]``, divided by ``L``.
"""

import math

import cv2
import numpy as np

__all__ = ["MIN_BLUR_PIXELS", "blur_length", "box_kernel", "motion_blur"]

#: Smears shorter than this many pixels are not drawn (they change no pixel by a level).
MIN_BLUR_PIXELS = 0.05


def blur_length(turn_rate, exposure_s, focal_px):
    """Length in pixels of the sideways smear: ``|turn_rate| * exposure_s * focal_px``."""
    return abs(turn_rate) * exposure_s * focal_px


def box_kernel(length):
    """The 1-D weights (odd length, sum 1) of a box ``length`` pixels wide centred on a pixel."""
    length = max(float(length), 1e-9)
    half = math.ceil(length / 2 - 0.5)
    j = np.arange(-half, half + 1, dtype=np.float64)
    overlap = np.minimum(j + 0.5, length / 2) - np.maximum(j - 0.5, -length / 2)
    return (np.clip(overlap, 0, None) / length).astype(np.float32)


def motion_blur(image, length, out=None):
    """``image`` (H, W[, C], float32) smeared sideways by ``length`` pixels (see the module)."""
    if length < MIN_BLUR_PIXELS:
        if out is None:
            return image
        out[...] = image
        return out
    kernel = box_kernel(length)[None, :]
    # Mirrored borders: the scene beyond the image edge continues like the edge.
    return cv2.filter2D(image, -1, kernel, dst=out, borderType=cv2.BORDER_REFLECT_101)
