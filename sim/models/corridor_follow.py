"""Python model of ``CorridorFollow`` (no Amaranth), written from its control law in
docs/lidar.md: each revolution's nearest return (``nearest_obstacle``) to a wheel command."""

from fpga_robotics.hw.lidar_params import CorridorParams, NearestParams
from fpga_robotics.sim.models.nearest_obstacle import nearest_per_revolution

__all__ = ["corridor_commands", "wheel_command"]


def wheel_command(params, found, nearest_mm, bearing_deg):
    """``(left, right)`` DPS for one revolution's nearest return at ``bearing_deg`` clockwise."""
    p = params
    if not found:
        return p.base_dps, p.base_dps
    bearing = bearing_deg % 360 if p.clockwise else (-bearing_deg) % 360
    off_ahead = min(bearing, 360 - bearing)
    right = bearing < 180
    if nearest_mm < p.stop_mm and off_ahead < p.front_deg:
        turn = (-p.turn_dps, p.turn_dps)  # in place, to the left
        return turn if right else turn[::-1]
    if nearest_mm < p.keep_mm and off_ahead <= p.side_deg:
        steer = (p.base_dps - p.steer_dps, p.base_dps + p.steer_dps)  # to the left
        return steer if right else steer[::-1]
    return p.base_dps, p.base_dps


def corridor_commands(samples, corridor=None, nearest=None):
    """The command after each revolution that ``samples`` ((angle_q6, distance_q2, quality,
    start) each) end, one per sample with ``start`` set."""
    corridor = CorridorParams() if corridor is None else corridor
    return [
        wheel_command(corridor, found, mm, q6 / 64)
        for found, mm, q6 in nearest_per_revolution(
            samples, NearestParams() if nearest is None else nearest
        )
    ]
