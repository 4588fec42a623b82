"""One LIDAR sample as a design receives it: the fields of the RPLIDAR's 5-byte packet, packed
from bit 0 up (``SAMPLE_FIELDS``). Plain Python (no Amaranth import): the gateware builds its
``data.StructLayout`` from these widths (``hw/nearest_obstacle.py``), the host packs samples
with ``pack_sample``.
"""

__all__ = ["SAMPLE_BITS", "SAMPLE_FIELDS", "pack_sample", "unpack_sample"]

#: name -> width, from bit 0 up: the angle clockwise in 1/64 degree, the distance in 1/4 mm
#: (0: no valid return), the return's quality, the start of a new revolution.
SAMPLE_FIELDS = {"angle_q6": 15, "distance_q2": 16, "quality": 6, "start": 1}
SAMPLE_BITS = sum(SAMPLE_FIELDS.values())


def pack_sample(sample):
    """The payload of ``sample`` (anything with the fields' attributes) as an int."""
    value, shift = 0, 0
    for name, width in SAMPLE_FIELDS.items():
        field = int(getattr(sample, name))
        if not 0 <= field < 1 << width:
            raise ValueError(f"{name} = {field} does not fit {width} bits")
        value |= field << shift
        shift += width
    return value


def unpack_sample(value):
    """``{field: int}`` of a packed payload."""
    out, shift = {}, 0
    for name, width in SAMPLE_FIELDS.items():
        out[name] = (value >> shift) & ((1 << width) - 1)
        shift += width
    return out
