"""LIDAR connectors: an RPLIDAR A1 class 2D scanner on the robot (``sim.world.lidar``), its
samples reaching the design at their real instants, in one of two bindings:

- ``kind = "lidar"``: a stream, ``valid`` and ``payload`` (``angle_q6`` 15 bits,
  ``distance_q2`` 16, ``quality`` 6, ``start`` 1, from bit 0 up: ``hw.lidar_sample``). Each
  sample's payload is set and ``valid`` pulses high for one cycle at the first edge at or
  after the instant the sample is taken; there is no back-pressure (a sensor does not wait).
- ``kind = "lidar_uart"``: the sensor's own serial protocol on one pin ``rx`` (idle high),
  8N1 at ``baud``: the standard scan's response descriptor from the start, then each
  sample's 5-byte packet as soon as it is taken, or when the line is free if it is still
  sending (at the A1's 2000 samples/s and 115200 baud the 50 bits of a packet take 434 us of
  the 500 us between samples, so the line keeps up).

The world is sampled at each physics step's start for the samples taken during the step
(the robot moves about 1 mm in a 1/240 s step).
"""

import math
from typing import ClassVar

import numpy as np

from fpga_robotics.hw.lidar_sample import SAMPLE_BITS, pack_sample
from fpga_robotics.loop.connectors.base import (
    Connector,
    ConnectorError,
    Pin,
    check_numbers,
    refuse_above_ceiling,
    refuse_unknown_keys,
    register,
)
from fpga_robotics.sim.world.lidar import (
    DESCRIPTOR,
    FULL_TURN_Q6,
    MAX_RANGE_M,
    LidarParams,
    Revolution,
    Scan,
    packet_bytes,
    uart_levels,
)

__all__ = ["LidarConnector", "LidarUartConnector"]

#: The bits of a sample's packet on the line: 5 bytes, each with a start and a stop bit.
PACKET_BITS = 50

#: key -> (lower bound, upper bound, unit, lower bound excluded[, why the upper bound]) of
#: the scenario table.
_KEYS = {
    "scan_hz": (1.0, 15.0, "Hz", False),
    "sample_rate": (100.0, 8000.0, "samples/s", False),
    "min_range": (0.0, 1.0, "m", False),
    "max_range": (
        0.5,
        MAX_RANGE_M,
        "m",
        False,
        " (a sample's distance_q2, 16 bits of mm x 4, carries at most 16.38 m)",
    ),
    "noise_frac": (0.0, 0.2, "", False),
    "dark_return": (0.0, 1.0, "", False),
    "max_incidence_deg": (0.0, 90.0, "degrees", True),
    "quality": (1.0, 63.0, "", False),
    "baud": (1200.0, 4_000_000.0, "baud", False),
}


def _lowest_rate(params):
    """The least ``sample_rate`` the table allows at its ``scan_hz``."""
    return max(_KEYS["sample_rate"][0], 10 * params.scan_hz)


def _or_at_most(key, most, lowest):
    """``", or KEY at most MOST"`` when that is an allowed value (at least ``lowest``)."""
    return f", or {key} at most {most:g}" if most >= lowest else ""


class _LidarBase(Connector):
    """What both bindings share: the keys, the scan, and what is reported of it."""

    #: Keys of ``_KEYS`` the binding has no use for: refused, as unknown keys are.
    unused_keys: ClassVar[tuple] = ()

    def __init__(self, name, mount, params, *, world, rng):
        super().__init__(name, mount, params, world=world, rng=rng)
        self.scan = Scan(params, rng)
        self._reset()

    def _reset(self):
        self.next_index = 0  # the next sample to take
        self.current = []  # (LidarSample, world x, world y) of the revolution under way
        self.last_revolution = []  # the last complete one
        self.revolutions = 0

    @classmethod
    def parse(cls, table, where):
        defaults = LidarParams()
        keys = {key: bounds for key, bounds in _KEYS.items() if key not in cls.unused_keys}
        refuse_unknown_keys(table, keys, where, cls.kind)
        values = check_numbers(table, _KEYS, defaults, where)
        if not values["min_range"] < values["max_range"]:
            raise ConnectorError(
                f"{where}.max_range must be greater than min_range "
                f"({values['min_range']:g} m), got {values['max_range']:g}"
            )
        if values["sample_rate"] < values["scan_hz"] * 10:
            raise ConnectorError(
                f"{where}.sample_rate must be at least 10 samples a revolution "
                f"({10 * values['scan_hz']:g} at scan_hz = {values['scan_hz']:g}), "
                f"got {values['sample_rate']:g}"
            )
        for key in ("quality", "baud"):
            if values[key] != int(values[key]):
                raise ConnectorError(f"{where}.{key} must be a whole number, got {values[key]!r}")
            values[key] = int(values[key])
        return LidarParams(**values)

    @classmethod
    def check_run(cls, params, mount, where, sim, room):
        refuse_above_ceiling(mount, where, room)

    def sensor_pose(self):
        """``(x, y, heading)`` of the sensor in the world now."""
        return self.mount.world_pose(*self.world.robot_pose())

    def take(self, t_end):
        """The samples taken before ``t_end`` not yet taken, from the world as it is now."""
        first = self.next_index
        last = self.scan.first_at(t_end)
        if last <= first:
            return []
        x, y, heading = self.sensor_pose()
        samples = self.scan.samples(
            self.world, first, last - first, x, y, heading, self.mount.height
        )
        self.next_index = last
        for s in samples:
            if s.start and self.current:
                self.last_revolution, self.current = self.current, []
                self.revolutions += 1
            a = heading - math.radians(s.angle_deg)
            self.current.append((s, x + s.distance_m * math.cos(a), y + s.distance_m * math.sin(a)))
        return samples

    def revolution_ranges(self):
        """The last complete revolution: ``(angles in degrees clockwise, ranges in m (0: no
        return), qualities)`` as arrays."""
        rev = [s for s, _, _ in self.last_revolution]
        return (
            np.array([s.angle_deg for s in rev]),
            np.array([s.distance_m for s in rev]),
            np.array([s.quality for s in rev]),
        )

    def revolution(self):
        """The last complete revolution as a ``Revolution`` (None before the first)."""
        if not self.last_revolution:
            return None
        p = self.params
        first = self.last_revolution[0][0].index
        _, ranges, qualities = self.revolution_ranges()
        return Revolution(
            start_time=self.scan.instant(first),
            first_deg=float(first * p.step % FULL_TURN_Q6) / 64.0,
            step_deg=float(p.step) / 64.0,
            ranges=tuple(float(r) for r in ranges),
            qualities=tuple(int(q) for q in qualities),
            time_increment=1.0 / p.sample_rate,
            scan_time=1.0 / p.scan_hz,
            range_min=p.min_range,
            range_max=p.max_range,
            mount_forward=self.mount.forward,
            mount_left=self.mount.left,
            mount_height=self.mount.height,
            mount_yaw_deg=math.degrees(self.mount.yaw),
        )

    def measurement(self):
        """The last complete revolution: the nearest return (``nearest_m``, its bearing
        ``nearest_deg`` clockwise from the sensor's forward), the fraction of samples that
        returned (``valid_fraction``) and its number of samples; empty before the first."""
        if not self.last_revolution:
            return {}
        angles, ranges, _ = self.revolution_ranges()
        ok = ranges > 0
        out = {"samples": float(len(ranges)), "valid_fraction": float(ok.mean())}
        if ok.any():
            k = int(np.argmin(np.where(ok, ranges, np.inf)))
            out["nearest_m"] = float(ranges[k])
            out["nearest_deg"] = float(angles[k])
        else:
            out["nearest_m"] = out["nearest_deg"] = math.nan
        return out

    def map_overlay(self):
        """The last revolution's returns, where they hit (world x, y), at the scan plane's
        height for the 3D view, and the revolution itself (for a bag's LaserScan)."""
        pts = tuple((px, py) for s, px, py in self.last_revolution if s.distance_q2)
        return {
            "points": pts,
            "states": (1,) * len(pts),
            "height": self.mount.height,
            "scan": self.revolution(),
        }


@register
class LidarConnector(_LidarBase):
    """The stream binding: ``valid`` (1 bit) and ``payload`` (38 bits) into the design."""

    kind = "lidar"
    pins: ClassVar[dict] = {"valid": Pin("in", 1), "payload": Pin("in", SAMPLE_BITS)}
    unused_keys = ("baud",)  # the serial link's (lidar_uart)

    @classmethod
    def check_run(cls, params, mount, where, sim, room):
        super().check_run(params, mount, where, sim, room)
        # valid is high for one edge a sample: a slower clock delays the samples more and
        # more, without bound.
        if sim.clock_hz < 2 * params.sample_rate:
            raise ConnectorError(
                f"{where}: {params.sample_rate:g} samples/s need two clock edges a sample: "
                f"sim.clock_hz at least {2 * params.sample_rate:g}"
                f"{_or_at_most('sample_rate', sim.clock_hz / 2, _lowest_rate(params))} "
                f"(sim.clock_hz is {sim.clock_hz:g})"
            )

    def start(self, io):
        self._reset()
        self._last_edge = io.cycle - 1  # no pulse yet
        io.poke("valid", 0)

    def before_step(self, io, t, dt):
        for s in self.take(t + dt):
            # One cycle of valid each; a clock slower than two edges a sample delays them.
            edge = max(io.edge_at(self.scan.instant(s.index)), io.cycle + 1, self._last_edge + 2)
            io.schedule(edge, "payload", pack_sample(s))
            io.schedule(edge, "valid", 1)
            io.schedule(edge + 1, "valid", 0)
            self._last_edge = edge


@register
class LidarUartConnector(_LidarBase):
    """The serial binding: the sensor's TX into the design's ``rx`` (1 bit, idle high)."""

    kind = "lidar_uart"
    pins: ClassVar[dict] = {"rx": Pin("in", 1)}

    @classmethod
    def parse(cls, table, where):
        params = super().parse(table, where)
        # A sensor has no unbounded buffer: a link slower than its samples would deliver
        # them later and later.
        if params.baud < PACKET_BITS * params.sample_rate:
            raise ConnectorError(
                f"{where}: {params.sample_rate:g} samples/s of {PACKET_BITS} bits (5 bytes "
                f"8N1) need baud at least {PACKET_BITS * params.sample_rate:g}"
                f"{_or_at_most('sample_rate', params.baud / PACKET_BITS, _lowest_rate(params))} "
                f"(baud is {params.baud})"
            )
        return params

    @classmethod
    def check_run(cls, params, mount, where, sim, room):
        super().check_run(params, mount, where, sim, room)
        if sim.clock_hz < params.baud:
            lowest_baud = PACKET_BITS * params.sample_rate
            raise ConnectorError(
                f"{where}: {params.baud} baud needs a clock edge a bit: sim.clock_hz at least "
                f"{params.baud}{_or_at_most('baud', math.floor(sim.clock_hz), lowest_baud)} "
                f"(sim.clock_hz is {sim.clock_hz:g})"
            )

    def start(self, io):
        self._reset()
        io.poke("rx", 1)
        self._level = 1
        self._last_edge = io.cycle
        self._free_at = 0.0  # the line is free from this time on (s)
        self._send(io, DESCRIPTOR, io.time_of(io.cycle))

    def _send(self, io, data, t):
        """Schedule ``data``'s bits from ``t`` (or when the line is free)."""
        begin = max(t, self._free_at)
        bit = 1.0 / self.params.baud
        for k, level in enumerate(uart_levels(data)):
            if level == self._level:
                continue
            edge = max(io.edge_at(begin + k * bit), io.cycle + 1, self._last_edge + 1)
            io.schedule(edge, "rx", level)
            self._level, self._last_edge = level, edge
        self._free_at = begin + len(data) * 10 * bit

    def before_step(self, io, t, dt):
        for s in self.take(t + dt):
            self._send(io, packet_bytes(s), self.scan.instant(s.index))
