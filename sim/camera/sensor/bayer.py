"""Bayer mosaic and the camera's simple (bilinear) demosaic.

The OV7670's colour filter array repeats a 2x2 tile; its raw output starts with a line of
B G B G ... then G R G R ... (BGGR). ``mosaic`` keeps, at each pixel, the one channel its filter
passes; ``demosaic`` fills in the two missing channels of each pixel with the mean of the nearest
pixels of that colour (bilinear interpolation), which is what leaves coloured fringes on sharp
edges: next to a dark/bright edge a pixel borrows one colour from across the edge and not the
others.

Bilinear interpolation is the 3x3 convolution of each colour's sparse plane (zeros where the
filter is another colour): red and blue with ``[[1,2,1],[2,4,2],[1,2,1]] / 4``, green with
``[[0,1,0],[1,4,1],[0,1,0]] / 4``; at a pixel of that colour it returns the sample itself. It
runs as OpenCV's Bayer conversion on the integer ADC codes (rounded to whole codes); the
outermost rows and columns, which lack neighbours on one side, repeat the interpolated values of
their inner neighbours. (On the chip the output window is cut from a slightly larger array, so
its edge pixels have real neighbours.)
"""

import cv2
import numpy as np

__all__ = ["BAYER_ORDERS", "bayer_channels", "demosaic", "mosaic"]

#: Tile orders: the filter colours of the 2x2 tile read row by row (R=0, G=1, B=2).
BAYER_ORDERS = {
    "BGGR": (2, 1, 1, 0),
    "RGGB": (0, 1, 1, 2),
    "GBRG": (1, 2, 0, 1),
    "GRBG": (1, 0, 2, 1),
}

#: OpenCV's name for each tile order (OpenCV names the tile starting at row 1, column 1).
_CV_CODES = {
    "BGGR": cv2.COLOR_BayerRG2RGB,
    "RGGB": cv2.COLOR_BayerBG2RGB,
    "GBRG": cv2.COLOR_BayerGR2RGB,
    "GRBG": cv2.COLOR_BayerGB2RGB,
}


def bayer_channels(height, width, order="BGGR"):
    """(height, width) uint8: the colour (0 R, 1 G, 2 B) each pixel's filter passes."""
    tile = np.array(BAYER_ORDERS[order], dtype=np.uint8).reshape(2, 2)
    return np.tile(tile, (-(-height // 2), -(-width // 2)))[:height, :width].copy()


def mosaic(rgb, channels):
    """The raw mosaic (H, W) of an (H, W, 3) image: each pixel keeps its filter's channel."""
    return np.take_along_axis(rgb, channels[..., None].astype(np.intp), axis=2)[..., 0]


def demosaic(codes, order="BGGR", out=None):
    """Bilinear demosaic of the integer mosaic ``codes`` (H, W) uint16 to (H, W, 3) uint16."""
    return cv2.cvtColor(codes, _CV_CODES[order], dst=out)
