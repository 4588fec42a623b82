"""``FollowTargetSafe``: ``FollowTarget`` with an HC-SR04 obstacle interlock on its wheels."""

from amaranth import Module, Mux
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .params import FollowTargetParams
from .sensor_params import DISTANCE_BITS, InterlockParams, UltrasoundParams
from .top import FollowTarget, follow_target_signature
from .ultrasound import UltrasoundDriver
from .validate import CheckedArguments

__all__ = ["FollowTargetSafe", "InterlockParams", "follow_target_safe_signature"]


def follow_target_safe_signature(ft_params):
    """``follow_target``'s ports plus the ultrasound pins and the interlock's outputs."""
    members = dict(follow_target_signature(ft_params).members)
    members.update(
        {
            "us_trig": Out(1),
            "us_echo": In(1),
            "distance_mm": Out(DISTANCE_BITS),
            "obstacle": Out(1),
        }
    )
    return wiring.Signature(members)


class FollowTargetSafe(CheckedArguments, wiring.Component):
    """``FollowTarget`` (unchanged, as a submodule) whose wheels an obstacle interlock stops
    (Verilog module ``follow_target_safe``).

    The ``UltrasoundDriver`` measures on ``us_trig``/``us_echo``. On each ``measured`` strobe
    (high after edge ``m``) the interlock decides, and ``obstacle`` shows it after edge
    ``m + 1``:

    - a measurement (not ``no_echo``) with ``distance_mm < stop_mm`` sets ``obstacle``;
    - ``no_echo``, or ``distance_mm >= resume_mm``, clears it;
    - a distance in ``stop_mm .. resume_mm - 1`` keeps it (hysteresis).

    (With ``release_on_far`` False, the seeded bug, only ``no_echo`` clears it.)

    While ``obstacle`` is high ``motor_left`` and ``motor_right`` are 0 (from the cycle it
    rises in); otherwise they are ``FollowTarget``'s, which keeps tracking and steering
    throughout. ``obstacle`` is 0 after reset. Every other port is ``follow_target``'s,
    unchanged.

    Parameters
    ----------
    ft_params : FollowTargetParams, optional
    us_params : UltrasoundParams, optional
    interlock_params : InterlockParams, optional

    Members
    -------
    (every member of ``FollowTarget``)
    us_trig : ``Out(1)``
        HC-SR04 TRIG (``UltrasoundDriver.trig``).
    us_echo : ``In(1)``
        HC-SR04 ECHO.
    distance_mm : ``Out(16)``
        The driver's last distance (65535 after "no echo").
    obstacle : ``Out(1)``
        The interlock holds the wheels at 0.
    """

    #: Which ports the HC-SR04 connector's pins are (the camera and the wheels bind by name).
    connectors = {"ultrasound": {"trig": "us_trig", "echo": "us_echo"}}  # noqa: RUF012

    @staticmethod
    def check_arguments(ft_params=None, us_params=None, interlock_params=None):
        for name, value, cls in (
            ("ft_params", ft_params, FollowTargetParams),
            ("us_params", us_params, UltrasoundParams),
            ("interlock_params", interlock_params, InterlockParams),
        ):
            if value is not None and not isinstance(value, cls):
                raise TypeError(f"{name} must be a {cls.__name__}, not {value!r}")

    def __init__(self, ft_params=None, us_params=None, interlock_params=None):
        ft_params = FollowTargetParams() if ft_params is None else ft_params
        us_params = UltrasoundParams() if us_params is None else us_params
        interlock_params = InterlockParams() if interlock_params is None else interlock_params
        self.params = ft_params
        self.us_params = us_params
        self.interlock_params = interlock_params
        self.follow_target = FollowTarget(ft_params)
        self.ultrasound = UltrasoundDriver(us_params)
        super().__init__(follow_target_safe_signature(ft_params))

    def elaborate(self, platform):
        m = Module()
        ip = self.interlock_params
        m.submodules.follow_target = ft = self.follow_target
        m.submodules.ultrasound = us = self.ultrasound

        wiring.connect(m, wiring.flipped(self.pixels), ft.pixels)
        wiring.connect(m, ft.filtered, wiring.flipped(self.filtered))
        m.d.comb += [
            ft.color_sel.eq(self.color_sel),
            self.frame_done.eq(ft.frame_done),
            self.found.eq(ft.found),
            self.proximity.eq(ft.proximity),
            self.centroid_x.eq(ft.centroid_x),
            self.centroid_leds.eq(ft.centroid_leds),
            self.us_trig.eq(us.trig),
            us.echo.eq(self.us_echo),
            self.distance_mm.eq(us.distance_mm),
        ]

        far = us.distance_mm >= ip.resume_mm
        release = (us.no_echo | far) if ip.release_on_far else (us.no_echo & far)
        with m.If(us.measured):
            with m.If(~us.no_echo & (us.distance_mm < ip.stop_mm)):
                m.d.sync += self.obstacle.eq(1)
            with m.Elif(release):
                m.d.sync += self.obstacle.eq(0)
        m.d.comb += [
            self.motor_left.eq(Mux(self.obstacle, 0, ft.motor_left)),
            self.motor_right.eq(Mux(self.obstacle, 0, ft.motor_right)),
        ]
        return m
