"""OpenCV images (a camera, a video, image files, ROS bag images) as the design's frames."""

import cv2
import numpy as np

__all__ = ["to_design_rgb"]


def to_design_rgb(bgr, width, height):
    """An OpenCV image (BGR, grey or BGRA; 8 or 16 bits) as RGB888 at ``width`` x ``height``."""
    if bgr.ndim == 2:
        bgr = cv2.cvtColor(bgr, cv2.COLOR_GRAY2BGR)
    elif bgr.shape[2] == 4:
        bgr = cv2.cvtColor(bgr, cv2.COLOR_BGRA2BGR)
    if bgr.dtype != np.uint8:  # 16-bit images: keep the top 8 bits
        bgr = (bgr >> 8).astype(np.uint8) if bgr.dtype == np.uint16 else bgr.astype(np.uint8)
    if bgr.shape[:2] != (height, width):
        bgr = cv2.resize(bgr, (width, height), interpolation=cv2.INTER_LINEAR)
    return np.ascontiguousarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
