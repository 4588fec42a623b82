"""A 2D scanning LIDAR of the RPLIDAR A1 class: what it measures in the world, sample by
sample, and the bytes of its serial protocol.

The head spins at ``scan_hz`` revolutions a second and takes ``sample_rate`` samples a second
at a fixed period (RPLIDAR A1 datasheet: 5.5 Hz typical scan, 2000 samples/s in standard scan
mode, so about one sample a degree; 0.15 to 12 m). Sample ``i`` (counted from the start of the
scan, world time 0) is taken at ``i / sample_rate`` s, its angle is where the head points
then: ``angle_q6 = floor(i * 23040 * scan_hz / sample_rate) mod 23040`` (1/64 degree, 360
degrees = 23040), measured clockwise seen from above from the sensor's forward, as the
RPLIDAR's angles are; the first sample of each revolution carries the start flag.

The world (``cast``): each sample is a ray in the horizontal plane at the mount's height: the
room's walls, the furniture at least that tall (its footprint's sides), people (upright
circles) at least that tall; the nearest one met. A return needs light back: the signal is
the surface's luminance (albedo, 0..1) times the cosine of the angle of incidence. Below
``dark_return`` nothing returns; from there up to twice ``dark_return`` a return is as likely
as the signal is above the threshold (a linear fade); beyond ``max_incidence_deg`` nothing
returns (glancing). No return, or a surface outside ``min_range..max_range``, is what the
RPLIDAR reports as an invalid sample: distance 0, quality 0. A return carries Gaussian range
noise of ``noise_frac`` of the range (the datasheet's accuracy, 1% of range up to 3 m) and
the quality ``quality`` (one value for every return here; the part's follows the return's
strength).

The protocol (Slamtec's interface protocol, ``SCAN`` request ``A5 20``): the answer starts
with the response descriptor ``A5 5A 05 00 00 40 81`` (5-byte answers, repeated, type 0x81),
then one 5-byte packet a sample: byte 0 ``quality << 2 | !S << 1 | S`` (S: start of a new
scan), byte 1 ``angle_q6[6:0] << 1 | 1`` (the check bit C), byte 2 ``angle_q6[14:7]``,
bytes 3-4 ``distance_q2`` little endian (distance in mm times 4). On the wire: 8N1 at 115200
baud, least significant bit first.
"""

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

__all__ = [
    "DESCRIPTOR",
    "FULL_TURN_Q6",
    "MAX_RANGE_M",
    "LidarParams",
    "LidarSample",
    "Revolution",
    "Scan",
    "cast",
    "decode_packets",
    "packet_bytes",
    "sample_angles",
    "uart_levels",
]

#: 360 degrees in the protocol's angle unit (1/64 degree).
FULL_TURN_Q6 = 360 * 64
#: The farthest ``max_range``: a sample's ``distance_q2`` is 16 bits of mm x 4, at most
#: 16383.75 mm (the A1 reaches 12 m; longer-range parts use other packet formats).
MAX_RANGE_M = 16.38
#: The SCAN request's response descriptor: start flags A5 5A, length 5 with send mode 1
#: (multiple responses) in its top two bits (0x40000005, little endian), data type 0x81.
DESCRIPTOR = bytes((0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81))


@dataclass(frozen=True)
class LidarParams:
    """The sensor's physics and link (defaults: an RPLIDAR A1 in standard scan mode)."""

    scan_hz: float = 5.5  # revolutions a second (datasheet: 5.5 Hz typical)
    sample_rate: float = 2000.0  # samples a second (datasheet: 2000 standard, 8000 express)
    min_range: float = 0.15  # m
    max_range: float = 12.0  # m
    noise_frac: float = 0.01  # Gaussian range noise, standard deviation / range
    dark_return: float = 0.06  # signal (luminance x cos incidence) below which nothing returns
    max_incidence_deg: float = 80.0  # a more glancing ray gets no return
    quality: int = 15  # the quality of a good return (6 bits)
    baud: int = 115200  # the serial link (8N1)

    @property
    def step(self):
        """The head's turn from one sample to the next, in q6 units, exactly."""
        return Fraction(FULL_TURN_Q6) * Fraction(self.scan_hz) / Fraction(self.sample_rate)

    @property
    def samples_per_rev(self):
        return self.sample_rate / self.scan_hz


@dataclass(frozen=True)
class LidarSample:
    """One sample as the sensor reports it."""

    index: int  # counted from the start of the scan
    angle_q6: int  # clockwise from the sensor's forward, 1/64 degree
    distance_q2: int  # mm x 4; 0: no valid return
    quality: int  # 0..63; 0 with distance 0
    start: bool  # the first sample of a revolution

    @property
    def angle_deg(self):
        return self.angle_q6 / 64.0

    @property
    def distance_m(self):
        return self.distance_q2 / 4000.0


@dataclass(frozen=True)
class Revolution:
    """One whole revolution as a ``sensor_msgs/LaserScan`` carries it (the angles still
    clockwise, as the sensor's)."""

    start_time: float  # world time of its first sample, s
    first_deg: float  # the exact angle of its first sample, clockwise
    step_deg: float  # the head's turn from one sample to the next
    ranges: tuple  # m, one a sample; 0: no return
    qualities: tuple
    time_increment: float  # s between samples
    scan_time: float  # s a revolution
    range_min: float
    range_max: float
    # Where the sensor sits on the robot: m ahead of and left of its centre, m above the
    # floor, and its forward's turn from the robot's heading (degrees, counter-clockwise).
    mount_forward: float = 0.0
    mount_left: float = 0.0
    mount_height: float = 0.0
    mount_yaw_deg: float = 0.0


def sample_angles(params, first, count):
    """``(angle_q6, exact angle in degrees, start)`` of samples ``first .. first+count-1``
    as numpy arrays (exact rational arithmetic, so the start flags fall right)."""
    step = params.step
    idx = range(first, first + count)
    turns = [i * step for i in idx]
    q6 = np.array([math.floor(n) % FULL_TURN_Q6 for n in turns], dtype=np.int64)
    exact = np.array([float(n % FULL_TURN_Q6) / 64.0 for n in turns])
    start = np.array(
        [
            i == 0 or math.floor(n / FULL_TURN_Q6) > math.floor((n - step) / FULL_TURN_Q6)
            for i, n in zip(idx, turns)
        ],
        dtype=bool,
    )
    return q6, exact, start


def _luminance(color):
    r, g, b = color
    return 0.299 * r + 0.587 * g + 0.114 * b


def _surfaces(world, x, y, height):
    """Segments ``(p0 (S,2), p1 (S,2), luminance (S,))`` and circles ``(centre (C,2),
    radius (C,), luminance (C,))`` the scan plane at ``height`` meets, relative to (x, y)."""
    room = world.config.room
    w, d = room.width, room.depth
    corners = [(0.0, 0.0), (w, 0.0), (w, d), (0.0, d)]
    p0, p1, lum = [], [], []
    wall = _luminance(room.wall_color)
    for i in range(4):
        p0.append(corners[i])
        p1.append(corners[(i + 1) % 4])
        lum.append(wall)
    for item in world.present_furniture():
        if item.height < height:
            continue  # under the scan plane
        pts = item.corners()
        for i in range(4):
            p0.append(pts[i])
            p1.append(pts[(i + 1) % 4])
            lum.append(_luminance(item.color))
    centres, radii, clum = [], [], []
    for person in world.people:
        cfg = person.config
        if cfg.height < height:
            continue
        px, py = person.body.position
        centres.append((float(px), float(py)))
        radii.append(cfg.radius)
        # The legs below the waist, the shirt above.
        clum.append(
            _luminance(cfg.trousers_color if height < 0.5 * cfg.height else cfg.shirt_color)
        )
    origin = np.array([x, y])
    seg = (
        np.asarray(p0, dtype=float).reshape(-1, 2) - origin,
        np.asarray(p1, dtype=float).reshape(-1, 2) - origin,
        np.asarray(lum, dtype=float),
    )
    circ = (
        np.asarray(centres, dtype=float).reshape(-1, 2) - origin,
        np.asarray(radii, dtype=float),
        np.asarray(clum, dtype=float),
    )
    return seg, circ


def cast(world, x, y, directions, height):
    """Rays from ``(x, y)`` at ``height`` along world ``directions`` (rad, an array): the
    distance to the nearest surface met (inf: none), the cosine of the angle of incidence
    there and the surface's luminance, each an array like ``directions``."""
    directions = np.asarray(directions, dtype=float)
    d = np.stack([np.cos(directions), np.sin(directions)], axis=-1)  # (R, 2)
    (a, b, seg_lum), (centres, radii, circ_lum) = _surfaces(world, x, y, height)
    n = len(directions)
    best = np.full(n, np.inf)
    cos_inc = np.zeros(n)
    lum = np.zeros(n)
    if len(a):
        e = b - a  # (S, 2)
        denom = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]  # cross(d, e)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (a[None, :, 0] * e[None, :, 1] - a[None, :, 1] * e[None, :, 0]) / denom
            u = (a[None, :, 0] * d[:, None, 1] - a[None, :, 1] * d[:, None, 0]) / denom
        ok = (denom != 0) & (t > 0) & (u >= 0) & (u <= 1)
        t = np.where(ok, t, np.inf)
        k = np.argmin(t, axis=1)
        rows = np.arange(n)
        best = t[rows, k]
        normal = np.stack([-e[:, 1], e[:, 0]], axis=-1) / np.hypot(e[:, 0], e[:, 1])[:, None]
        cos_inc = np.abs(np.sum(d * normal[k], axis=1))
        lum = seg_lum[k]
    if len(centres):
        bb = d @ centres.T  # (R, C)
        disc = bb**2 - (np.sum(centres**2, axis=1) - radii**2)[None, :]
        with np.errstate(invalid="ignore"):
            t = bb - np.sqrt(disc)
        t = np.where((disc >= 0) & (t > 0), t, np.inf)
        k = np.argmin(t, axis=1)
        rows = np.arange(n)
        tc = t[rows, k]
        nearer = tc < best
        if nearer.any():
            hit = d[nearer] * tc[nearer, None] - centres[k[nearer]]
            normal = hit / radii[k[nearer], None]
            cos_inc[nearer] = np.abs(np.sum(d[nearer] * normal, axis=1))
            lum[nearer] = circ_lum[k[nearer]]
            best = np.where(nearer, tc, best)
    return best, cos_inc, lum


class Scan:
    """The sensor's samples in order (``samples(first, count, pose)``), drawing its noise
    and dropouts from ``rng``: the same seed gives the same scan."""

    def __init__(self, params, rng):
        self.params = params
        self.rng = rng

    def instant(self, index):
        """World time (s) of sample ``index``."""
        return index / self.params.sample_rate

    def first_at(self, t):
        """The first sample index taken at or after ``t``."""
        return max(0, math.ceil(t * self.params.sample_rate - 1e-9))

    def samples(self, world, first, count, x, y, heading, height):
        """Samples ``first .. first+count-1`` from a sensor at ``(x, y, heading)`` (the world
        as it is now): a list of ``LidarSample``."""
        if count <= 0:
            return []
        p = self.params
        q6, exact, start = sample_angles(p, first, count)
        directions = heading - np.radians(exact)  # clockwise angles
        dist, cos_inc, lum = cast(world, x, y, directions, height)
        # Always draw both numbers for every sample: the stream does not depend on the hits.
        noise = self.rng.standard_normal(count)
        chance = self.rng.random(count)
        signal = lum * cos_inc
        fade = np.clip((signal - p.dark_return) / max(p.dark_return, 1e-12), 0.0, 1.0)
        returned = (
            np.isfinite(dist)
            & (dist >= p.min_range)
            & (dist <= p.max_range)
            & (cos_inc >= math.cos(math.radians(p.max_incidence_deg)))
            & (chance < fade)
        )
        measured = np.maximum(0.0, dist * (1.0 + p.noise_frac * noise))
        out = []
        for j in range(count):
            if returned[j]:
                # Noise can carry a return near MAX_RANGE_M past what 16 bits hold.
                d_q2 = min(0xFFFF, max(1, round(float(measured[j]) * 4000.0)))
                quality = p.quality
            else:
                d_q2, quality = 0, 0
            out.append(LidarSample(first + j, int(q6[j]), d_q2, quality, bool(start[j])))
        return out


def packet_bytes(sample):
    """The 5 bytes of one sample in the standard scan's answer."""
    s = 1 if sample.start else 0
    return bytes(
        (
            (sample.quality & 0x3F) << 2 | (1 - s) << 1 | s,
            (sample.angle_q6 & 0x7F) << 1 | 1,
            (sample.angle_q6 >> 7) & 0xFF,
            sample.distance_q2 & 0xFF,
            (sample.distance_q2 >> 8) & 0xFF,
        )
    )


def decode_packets(data):
    """The samples ``(angle_q6, distance_q2, quality, start)`` of a standard scan's answer
    (the descriptor first), checking its framing: a ``ValueError`` for a wrong descriptor or
    a packet whose S/!S or check bit is wrong."""
    data = bytes(data)
    if data[:7] != DESCRIPTOR:
        raise ValueError(f"not a scan response descriptor: {data[:7].hex(' ')}")
    body = data[7:]
    if len(body) % 5:
        raise ValueError(f"{len(body)} bytes after the descriptor: not whole 5-byte packets")
    out = []
    for k in range(0, len(body), 5):
        b = body[k : k + 5]
        s, not_s = b[0] & 1, (b[0] >> 1) & 1
        if s == not_s or not b[1] & 1:
            raise ValueError(f"packet {k // 5}: bad framing {b.hex(' ')}")
        out.append(((b[1] >> 1) | (b[2] << 7), b[3] | (b[4] << 8), b[0] >> 2, bool(s)))
    return out


def uart_levels(data):
    """The line's levels, one per bit time, for ``data`` sent 8N1 back to back: per byte a
    start bit 0, the 8 data bits least significant first, a stop bit 1."""
    levels = []
    for byte in bytes(data):
        levels.append(0)
        levels.extend((byte >> i) & 1 for i in range(8))
        levels.append(1)
    return levels
