"""The robot's world: a top-down pymunk simulation in metres and seconds.

The robot is a dynamic disc driven by pymunk's control-body idiom: a kinematic control body
moves at the twist the wheels ask for, and a ``PivotJoint`` and a ``GearJoint`` (no position
correction, ``max_bias = 0``) pull the robot towards that velocity with at most the
robot's traction force and torque. The robot's velocity is never written directly, so walls,
furniture and people stop it. People are kinematic bodies on scripted paths (a person with a
``yield_gap`` pauses their script rather than step closer than that to the robot); walls and
furniture are static shapes. The robot's contacts, from pymunk collision handlers, are
gathered into collision episodes per kind of body, each with its fault (``collisions``).
"""

import math

import numpy as np
import pymunk

from ..camera.scene import CameraPose, Cylinder, Scene
from ..records import PersonState, WorldMap
from .collisions import AT_FAULT_SPEED, CollisionLog, MotionHistory, closing_speeds
from .config import WorldConfigError, parse_world_config, start_name
from .lighting import SCHEDULE_SLACK, LightingSchedule
from .motors import DriveMotors
from .people import PersonPath, person_bands
from .robots import G
from .room import add_static_shapes, map_data, scene_walls
from .sanity import segment_distance
from .terrain import TerrainMap, slope_pitch, slope_roll
from .uncertainty import MotorUncertainty

__all__ = [
    "AT_FAULT_SPEED",
    "MAX_SUBSTEP",
    "MAX_TARGET_SPEED",
    "World",
    "check_seed",
    "is_removal_event",
    "removal_event",
]


def removal_event(name):
    """The event a piece of furniture leaving the room (``present_until``) gives."""
    return f"furniture {name!r} removed"


def is_removal_event(text):
    """Whether an event text is a ``removal_event``."""
    return text.startswith("furniture ") and text.endswith(" removed")


#: ``step(dt)`` splits longer steps into equal sub-steps no longer than this, s.
MAX_SUBSTEP = 0.01

#: Fastest a person may be driven by hand (``World.set_target_velocity``), m/s: a run.
MAX_TARGET_SPEED = 3.0

_ROBOT, _WALL, _FURNITURE, _PERSON = 1, 2, 3, 4
_KINDS = ("person", "wall", "furniture")
_FRICTION = 0.5


def _terrain_event(patch):
    """The event of the robot's centre coming onto ``patch`` (None: off every patch)."""
    return f"terrain: on {patch.name!r}" if patch is not None else "terrain: off the patches"


def _speed(v):
    """A speed with two decimals, never "-0.00"."""
    return f"{round(v, 2) + 0.0:.2f}"


class _Person:
    __slots__ = (
        "bands",
        "body",
        "config",
        "facing",
        "offset",
        "path",
        "shape",
        "teleop",
        "waited",
        "walked",
    )

    def __init__(self, config, path, body, shape):
        self.config = config
        self.path = path
        self.body = body
        self.shape = shape
        self.bands = person_bands(config)
        #: Time spent waiting for the robot, s: the script runs this much behind the clock.
        self.waited = 0.0
        #: Where a hand-driven person (``World.set_target_velocity``) was moved off the
        #: script, m: added to the script's position from then on.
        self.offset = (0.0, 0.0)
        #: ``(vx, vy)`` m/s while the person is driven by hand, else None.
        self.teleop = None
        #: Distance walked (m) and the direction of the last step (rad): a 3D renderer's gait.
        self.walked = 0.0
        self.facing = _first_facing(config.waypoints)


def _first_facing(waypoints):
    """The direction from the first waypoint to the next different one (0 if none)."""
    x0, y0 = waypoints[0]
    for x, y in waypoints[1:]:
        if (x, y) != (x0, y0):
            return math.atan2(y - y0, x - x0)
    return 0.0


def check_seed(seed):
    """``ValueError`` unless ``seed`` is a whole number 0 or more (a bool, a float or a
    string would run another seed than the one asked for)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")


class World:
    """A room with a robot and walking people, advanced in fixed steps.

    Build it with ``World.from_config(cfg, seed)``; see docs/scenarios.md for ``cfg``.

    Parameters
    ----------
    config : WorldConfig
        A validated configuration (``config.parse_world_config``).
    seed : int
        Fixes every random choice (people's speed jitter).

    Attributes
    ----------
    time : float
        Simulated time, s.
    robot_spec : RobotSpec
        The robot's geometry, mass and motor power.
    motors : DriveMotors
        The wheel motors (``set_wheel_dps`` is forwarded to them).
    """

    def __init__(self, config, seed=0):
        check_seed(seed)
        self.config = config
        self.seed = int(seed)
        self.time = 0.0
        self._time_error = 0.0  # Kahan compensation: many small steps add up exactly
        self.robot_spec = spec = config.robot.spec
        self.motors = DriveMotors(spec)
        self.lighting = LightingSchedule(config.lighting)

        self.terrain = TerrainMap(config.room.terrain, config.room.width, config.room.depth)
        #: The floor markings (``markings.FloorLine``), in file order.
        self.floor_lines = tuple(config.room.lines)
        painted = [t for t in config.room.terrain if t.color is not None]
        self._painted = TerrainMap(painted, config.room.width, config.room.depth)
        # The camera draws the painted patches, then the markings over them.
        self._floor_patches = tuple((t.polygon, t.color) for t in painted) + tuple(
            (tuple(poly), line.color) for line in self.floor_lines for poly in line.polygons()
        )
        self._patch = None  # the terrain patch under the robot's centre
        self._traction = 1.0  # the factor the joints' forces are set to
        self._downhill_cache = {}  # id(patch) -> gravity's downhill force on the robot
        # Motor gain, noise and slips: a stream of their own (None for the ideal robot), so
        # that they never shift the people's randomness.
        self.uncertainty = (
            MotorUncertainty(config.robot.uncertainty, self.seed)
            if config.robot.uncertainty
            else None
        )

        self.space = space = pymunk.Space()
        space.gravity = (0.0, 0.0)
        space.iterations = 10
        # Pymunk lets shapes overlap by `collision_slop` before it pushes them apart; its
        # default (0.1) is meant for pixel units and would let the robot sink 10 cm into a
        # wall here. 1 mm: walls and furniture stay solid.
        space.collision_slop = 0.001

        # The robot and its control body (pymunk's tank example idiom).
        self.robot_body = body = pymunk.Body(spec.mass, spec.moment)
        body.position = config.robot.start
        body.angle = config.robot.heading
        self.robot_shape = shape = pymunk.Circle(body, spec.body_radius)
        shape.collision_type = _ROBOT
        shape.friction = _FRICTION
        shape.elasticity = 0.0
        self.control_body = control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        control.position = config.robot.start
        control.angle = config.robot.heading
        pivot = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
        pivot.max_bias = 0.0  # velocity control only: never pull towards a position
        pivot.max_force = spec.traction_force
        gear = pymunk.GearJoint(control, body, 0.0, 1.0)
        gear.max_bias = 0.0
        gear.max_force = spec.traction_torque
        self._pivot, self._gear = pivot, gear
        self._robot_speed = 0.0  # the body's speed after the last sub-step, m/s
        self._robot_turn = 0.0  # and its turn rate's size, rad/s
        space.add(body, shape, control, pivot, gear)
        self._patch = self.terrain.at(*config.robot.start) if self.terrain else None

        self._names = add_static_shapes(
            space, config.room, wall_type=_WALL, furniture_type=_FURNITURE, friction=_FRICTION
        )
        self._furniture_shapes = {
            name: shape for shape, (kind, name) in self._names.items() if kind == "furniture"
        }
        self._removed = set()
        # (time, name) of the furniture that leaves the room, earliest first.
        self._removals = sorted(
            (f.present_until, f.name) for f in config.room.furniture if f.present_until is not None
        )
        self.people = []
        # One generator per person, so a person's jitter does not depend on the others or on
        # the order in which their paths are queried.
        streams = np.random.SeedSequence(self.seed).spawn(len(config.people))
        for pc, stream in zip(config.people, streams):
            path = PersonPath(pc, np.random.default_rng(stream))
            pbody = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
            pbody.position = path.position(0.0)
            pshape = pymunk.Circle(pbody, pc.radius)
            pshape.collision_type = _PERSON
            pshape.friction = _FRICTION
            pshape.elasticity = 0.0
            space.add(pbody, pshape)
            self._names[pshape] = ("person", pc.name)
            self.people.append(_Person(pc, path, pbody, pshape))
        self._target = next((p for p in self.people if p.config.target), None)

        for hit in space.shape_query(shape):
            kind, name = self._names[hit.shape]
            what = f"{kind} {name!r}" if name else kind
            if kind == "person":  # where they stand at t = 0: their first waypoint
                what += f" (at [{hit.shape.body.position.x:g}, {hit.shape.body.position.y:g}])"
            x, y = config.robot.start
            default = config.robot.default_start
            raise WorldConfigError(
                f"{start_name(default)} [{x:g}, {y:g}] overlaps the {what}"
                + ("; set robot.start to a place clear of it" if default else "")
            )

        self._collisions = CollisionLog(_KINDS)
        self._history = MotionHistory()
        self._now = 0.0  # the end of the physics step under way: when its contacts happen
        #: ``(time_s, reason)`` once the robot has tipped over, else None.
        self.tipped = None
        self._motor_v = 0.0  # the motors' forward speed at the last sub-step, m/s
        # Where the robot's own driving alone would have taken its centre, and at what speed
        # (``driven_position``): motion it drove, not pushes by others.
        self._driven_xy = tuple(config.robot.start)
        self._driven_v = 0.0
        self._events = []
        if self._patch is not None:  # the log says where the robot starts, as it changes
            self._events.append(_terrain_event(self._patch))
        for ctype in (_WALL, _FURNITURE, _PERSON):
            space.on_collision(
                _ROBOT,
                ctype,
                begin=self._on_begin,
                post_solve=self._on_post_solve,
                separate=self._on_separate,
            )

        self._static_walls = scene_walls(config.room)
        self._world_map = self._build_map()

    def _build_map(self):
        room = self.config.room
        # Terrain on the map: a patch's colour, or a pale blue for one not drawn on the floor.
        return WorldMap(
            *map_data(room, self._removed),
            terrain=[list(t.polygon) for t in room.terrain],
            terrain_colors=[
                tuple(round(c * 255) for c in (t.color or (0.55, 0.7, 0.9))) for t in room.terrain
            ],
            lines=[
                [tuple(p) for p in line.points] + ([tuple(line.points[0])] if line.closed else [])
                for line in self.floor_lines
            ],
            line_widths=[line.width for line in self.floor_lines],
            line_colors=[tuple(round(c * 255) for c in line.color) for line in self.floor_lines],
        )

    @classmethod
    def from_config(cls, cfg=None, seed=0):
        """Validate ``cfg`` (sections ``room``, ``robot``, ``people``, ``lighting``) and build
        the world; raises ``WorldConfigError`` naming the offending key."""
        return cls(parse_world_config(cfg), seed)

    # -- physics ------------------------------------------------------------------------

    def _on_begin(self, arbiter, space, data):
        other = arbiter.shapes[1]
        kind, name = self._names[other]
        if not self._collisions.begin(kind, name, other, self._now):
            return  # still touching, or touching again within the episode gap
        if kind != "person":
            self._events.append(
                f"collision with {kind} {name!r}" if name else f"collision with {kind}"
            )
            return
        robot_c, person_c = self._closing_speeds(other)
        fault = robot_c > AT_FAULT_SPEED and robot_c > person_c
        if fault:
            self._collisions.record_fault(kind)
        verdict = "the robot's fault" if fault else "not the robot's fault"
        self._events.append(
            f"collision with person {name!r} (robot closing {_speed(robot_c)} "
            f"m/s, person {_speed(person_c)} m/s: {verdict})"
        )

    def _closing_speeds(self, person_shape):
        """The robot's and the person's speeds towards each other at a first touch, m/s,
        averaged over ``collisions.FAULT_WINDOW``. The robot's is what its own driving
        closed (``driven_position``): its body's closing, but no more (a robot shoved into
        the person closed only what it drove)."""
        robot_xy = tuple(self.robot_body.position)
        people_xy = [tuple(p.body.position) for p in self.people]
        i = next(i for i, p in enumerate(self.people) if p.shape is person_shape)
        towards = (people_xy[i][0] - robot_xy[0], people_xy[i][1] - robot_xy[1])
        robot_v, driven_v, people_v = self._history.mean_velocities(
            self._now, robot_xy, self._driven_xy, people_xy
        )
        robot_c, person_c = closing_speeds(robot_v, people_v[i], towards)
        driven_c, _ = closing_speeds(driven_v, people_v[i], towards)
        return min(robot_c, driven_c), person_c

    def _on_post_solve(self, arbiter, space, data):
        kind, _ = self._names[arbiter.shapes[1]]
        self._collisions.impulse(kind, arbiter.total_impulse.length)

    def _on_separate(self, arbiter, space, data):
        other = arbiter.shapes[1]
        hit = self._names.get(other)
        if hit is not None:  # None: the space is being torn down
            self._collisions.separate(hit[0], hit[1], other, self._now)

    def step(self, dt):
        """Advance the world by ``dt`` seconds (split into sub-steps of at most
        ``MAX_SUBSTEP``)."""
        if not dt > 0 or not math.isfinite(dt):
            raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
        n = max(1, math.ceil(dt / MAX_SUBSTEP - 1e-9))
        h = dt / n
        for _ in range(n):
            self._substep(h)

    def _substep(self, h):
        spec = self.robot_spec
        body = self.robot_body
        rx, ry = body.position  # unchanged until space.step (one read: pymunk's are slow)
        wl, wr = self.motors.step(h)
        drive_v = spec.wheel_radius * (wl + wr) * 0.5  # the motors' speed, before the noise
        if self.uncertainty is not None:
            wl, wr, slip = self.uncertainty.step(h, wl, wr, self.time)
            if self.uncertainty.events:
                self._events += self.uncertainty.drain_events()
            if self.terrain or slip != self._traction:
                self._apply_terrain(slip, rx, ry)
        elif self.terrain:
            self._apply_terrain(1.0, rx, ry)
        if self.tipped is None:
            # The body follows the motors' ramp (the speed noise is the wheels' jitter, not
            # a push) at most as fast as the traction in force lets it.
            most = self._traction_accel()
            accel = max(-most, min(most, (drive_v - self._motor_v) / h))
            # On a ramp, facing uphill, gravity leans the centre of mass back over the rear
            # support as a forward acceleration does, and the floor holds it with g cos.
            pitch = slope_pitch(self._patch, body.angle)
            load, limit = abs(accel + G * math.sin(pitch)), spec.tip_accel * math.cos(pitch)
            # Across the slope gravity leans it sideways, no harder than the traction holds
            # it there (sliding sideways, the floor pushes back with the traction alone).
            roll = slope_roll(self._patch, body.angle)
            side = min(G * abs(math.sin(roll)), most)
            side_limit = spec.tip_accel_sideways * math.cos(roll)
            if load > limit:
                slope = f" on a {math.degrees(pitch):+.1f} deg slope" if pitch else ""
                self._tip(
                    f"longitudinal acceleration {accel:.2f} m/s^2{slope} "
                    f"({load:.2f} m/s^2 with gravity) > {limit:.2f} m/s^2"
                    if pitch
                    else f"longitudinal acceleration {abs(accel):.2f} m/s^2 > {limit:.2f} m/s^2"
                )
            elif side > side_limit:
                self._tip(
                    f"on its {'right' if roll > 0 else 'left'} side: rolled "
                    f"{math.degrees(abs(roll)):.1f} deg across a slope, sideways load "
                    f"{side:.2f} m/s^2 > {side_limit:.2f} m/s^2"
                )
        self._motor_v = drive_v
        r = spec.wheel_radius
        v = r * (wl + wr) * 0.5
        w = r * (wr - wl) / spec.wheel_separation
        a = body.angle
        control = self.control_body
        control.velocity = (v * math.cos(a), v * math.sin(a))
        control.angular_velocity = w
        driven_x, driven_y = self._driven_xy
        step = self._traction_accel() * h
        self._driven_v += max(-step, min(step, v - self._driven_v))
        self._driven_xy = (
            driven_x + self._driven_v * h * math.cos(a),
            driven_y + self._driven_v * h * math.sin(a),
        )
        t1 = self._advance_time(h)
        before = []  # the people's positions at the start of the sub-step
        for person in self.people:
            if person.teleop is not None:  # driven by hand: the script waits, the offset grows
                person.waited += h
                sx, sy = person.path.position(t1 - person.waited)
                person.offset = self._driven_offset(person, sx, sy, h)
            else:
                sx, sy = person.path.position(t1 - person.waited)
            x, y = sx + person.offset[0], sy + person.offset[1]
            px, py = person.body.position
            before.append((px, py))
            gap = person.config.yield_gap
            if gap > 0.0 and person.teleop is None:
                # Wait (the script pauses) rather than step closer to the robot than the gap.
                ahead = math.hypot(x - rx, y - ry)
                if (
                    ahead < math.hypot(px - rx, py - ry)
                    and ahead - person.config.radius - spec.body_radius < gap
                ):
                    person.waited += h
                    x, y = px, py
            # Arrive exactly on the script; the velocity lets contacts push the robot.
            person.body.velocity = ((x - px) / h, (y - py) / h)
            step = math.hypot(x - px, y - py)
            if step > 0.0:
                person.walked += step
                person.facing = math.atan2(y - py, x - px)
        self._history.record(self.time, (rx, ry), (driven_x, driven_y), before)
        downhill = self.robot_body.force.length / spec.mass  # pymunk clears it in the step
        self._now = t1
        self.space.step(h)
        self._limit_robot_speed(self._top_speed(abs(v), downhill, h), abs(w))
        self.time = t1
        if self._removals and self._removals[0][0] <= t1 + SCHEDULE_SLACK:
            self._remove_due()

    def _top_speed(self, wheel_speed, downhill, h):
        """The fastest the robot's body can move after the sub-step of ``h`` s just taken,
        m/s: its wheels' speed plus the fastest of the people touching it in that step (a
        person pushes it at most at their own speed; one elsewhere in the room does not push
        it at all), or its speed before plus what a slope's gravity (``downhill``, m/s^2)
        adds in ``h`` (the traction only pulls it towards the wheels' speed). Rigid people
        squeezing it against another body would otherwise shoot it out at any speed."""
        pushers = [0.0]

        def touching(arbiter):
            a, b = arbiter.shapes
            other = b if a is self.robot_shape else a
            if self._names.get(other, ("",))[0] == "person":
                pushers.append(other.body.velocity.length)

        self.robot_body.each_arbiter(touching)
        return max(wheel_speed + max(pushers), self._robot_speed + downhill * h)

    def _limit_robot_speed(self, top_speed, wheel_turn):
        """Slow the robot's body (the velocity the next step moves it at) to ``top_speed``,
        and its turn to ``wheel_turn`` (rad/s) plus what the friction of its contacts can
        give it: a rim spun by a wall or a person turns no faster than it slides past it
        (or keeps the turn it had: the traction only pulls it towards the wheels'). People
        squeezing it would otherwise spin it at any rate."""
        body = self.robot_body
        speed = body.velocity.length
        if speed > top_speed:
            body.velocity = body.velocity * (top_speed / speed)
        self._robot_speed = min(speed, top_speed)
        slides = [0.0]

        def slide(arbiter):
            a, b = arbiter.shapes
            other = b if a is self.robot_shape else a
            rel = other.body.velocity - body.velocity
            n = arbiter.normal
            slides.append(abs(rel.y * n.x - rel.x * n.y))  # along the rim

        body.each_arbiter(slide)
        top_turn = max(wheel_turn + max(slides) / self.robot_spec.body_radius, self._robot_turn)
        turn = body.angular_velocity
        if abs(turn) > top_turn:
            body.angular_velocity = math.copysign(top_turn, turn)
        self._robot_turn = min(abs(turn), top_turn)

    def _driven_offset(self, person, sx, sy, h):
        """A hand-driven person's offset after a sub-step: the person is kinematic, so
        nothing in the physics stops them; each axis stops where it would take them into a
        wall or furniture, so they slide along it."""
        ox, oy = person.offset
        vx, vy = person.teleop
        if self._person_fits(sx + ox + vx * h, sy + oy, person, sx + ox, sy + oy):
            ox += vx * h
        if self._person_fits(sx + ox, sy + oy + vy * h, person, sx + ox, sy + oy):
            oy += vy * h
        return ox, oy

    def _person_fits(self, x, y, person, old_x, old_y):
        """Whether ``person`` may step to ``(x, y)`` from ``(old_x, old_y)``: clear of the
        walls and furniture there, or already overlapping them (so that they can get out)."""
        return self._clear_of_room(x, y, person.config.radius) or not self._clear_of_room(
            old_x, old_y, person.config.radius
        )

    def _clear_of_room(self, x, y, radius):
        room = self.config.room
        if not (radius <= x <= room.width - radius and radius <= y <= room.depth - radius):
            return False
        return all(
            segment_distance((x, y), (x, y), f.corners()) >= radius
            for f in self.present_furniture()
        )

    def _remove_due(self):
        """Take the furniture whose ``present_until`` has come out of the physics, the
        camera's scene and the map."""
        while self._removals and self._removals[0][0] <= self.time + SCHEDULE_SLACK:
            _, name = self._removals.pop(0)
            shape = self._furniture_shapes[name]
            self._collisions.separate("furniture", name, shape, self.time)
            self.space.remove(shape)
            self._removed.add(name)
            self._events.append(removal_event(name))
        self._static_walls = scene_walls(self.config.room, self._removed)
        self._world_map = self._build_map()

    def _apply_terrain(self, slip, x, y):
        """The patch under the robot at ``(x, y)``: its traction factor (times a slip's) on
        the drive's joints, and gravity's downhill component on the body (pymunk clears it
        each step)."""
        patch = self.terrain.at(x, y) if self.terrain else None
        if patch is not self._patch:
            self._patch = patch
            self._events.append(_terrain_event(patch))
        factor = slip * (patch.friction if patch is not None else 1.0)
        if factor != self._traction:
            self._traction = factor
            self._pivot.max_force = self.robot_spec.traction_force * factor
            self._gear.max_force = self.robot_spec.traction_torque * factor
        if patch is not None and patch.slope > 0.0:
            self.robot_body.force = self._downhill(patch)

    def _downhill(self, patch):
        force = self._downhill_cache.get(id(patch))
        if force is None:
            force = self._downhill_cache[id(patch)] = patch.downhill_force(self.robot_spec.mass, G)
        return force

    def terrain_under_robot(self):
        """The terrain patch under the robot's centre (``terrain.TerrainPatch``), or None."""
        return self._patch

    def camera_pitch(self, heading=None):
        """The extra pitch the slope under the robot gives a camera on it facing ``heading``
        (rad, world; default the robot's own), rad (positive looks up): a camera facing
        across the slope does not pitch, one facing downhill looks down."""
        return slope_pitch(self._patch, self.robot_body.angle if heading is None else heading)

    def _advance_time(self, h):
        y = h - self._time_error
        t = self.time + y
        self._time_error = (t - self.time) - y
        return t

    def set_target_velocity(self, velocity):
        """Drive the target person by hand (as one drags a person in Gazebo): ``(vx, vy)``
        in m/s in the world frame from the next step on, its script paused; None hands it
        back to its script, which goes on from where the person was left. The person stops
        (slides) at walls and furniture. Raises ``ValueError`` when there is no target or
        the speed is not finite or above ``MAX_TARGET_SPEED``."""
        if self._target is None:
            raise ValueError("the world has no target person to drive")
        if velocity is not None:
            vx, vy = (float(v) for v in velocity)
            if not math.hypot(vx, vy) <= MAX_TARGET_SPEED:  # NaN fails too
                raise ValueError(
                    f"target speed must be at most {MAX_TARGET_SPEED:g} m/s, got {velocity!r}"
                )
            velocity = (vx, vy)
        self._target.teleop = velocity

    # -- motors -------------------------------------------------------------------------

    def set_wheel_dps(self, left_dps, right_dps):
        """Wheel speed targets in degrees per second (the design's SET_MOTOR_DPS values).
        A jump of either wheel's speed beyond ``robot_spec.tip_step_dps`` (when the spec has
        a ``motor_step_response``) tips the robot over, unless the traction in force cannot
        push the body at ``tip_accel``; a tipped robot's wheels stay still."""
        if self.tipped is not None:
            return
        spec = self.robot_spec
        limit = spec.tip_step_dps
        if limit is not None and self._traction_accel() > spec.tip_accel:
            # The motors clamp a command to max_wheel_dps: they jump by the clamped change.
            top = spec.max_wheel_dps

            def clamped(dps):
                return max(-top, min(top, dps))

            old_l, old_r = self.motors.command_dps
            jump = max(
                abs(clamped(left_dps) - clamped(old_l)), abs(clamped(right_dps) - clamped(old_r))
            )
            if jump > limit:
                self._tip(f"wheel command jumped {jump:g} DPS > {limit:.0f} DPS")
                return
        self.motors.set_wheel_dps(left_dps, right_dps)

    def _traction_accel(self):
        """The largest acceleration the wheels can give the body now, m/s^2: the robot's
        traction times the floor's (a terrain patch's friction, a slip's factor)."""
        return self.robot_spec.traction_force * self._traction / self.robot_spec.mass

    def _tip(self, reason):
        """The robot falls: its wheels stop (the body is braked by the drive's traction)."""
        self.tipped = (self.time, reason)
        self._events.append(f"tipped over: {reason}")
        self.motors.set_wheel_dps(0.0, 0.0)
        self.motors.left.speed = self.motors.right.speed = 0.0

    def driven_position(self):
        """``(x, y)``, m: where the robot's own driving alone would have taken its centre
        from its start: the wheels' speed along the body's heading, reached no faster than
        the traction allows (as the body follows them when nothing else touches it). The
        body's motion beyond it is others' doing: a push, a squeeze, a slope."""
        return self._driven_xy

    def commanded_twist(self):
        """``(v, w)`` of the current DPS command by the real kinematics."""
        return self.motors.commanded_twist()

    def wheel_speeds(self):
        """The motors' current wheel speeds ``(left, right)``, rad/s (after ramp and clamp)."""
        return self.motors.wheel_speeds()

    # -- state --------------------------------------------------------------------------

    def robot_pose(self):
        """``(x, y, heading)``: m, m, rad in [-pi, pi)."""
        body = self.robot_body
        x, y = body.position
        heading = (body.angle + math.pi) % (2 * math.pi) - math.pi
        return float(x), float(y), heading

    def robot_velocity(self):
        """Measured ``(v, w)``: forward speed (m/s) and turn rate (rad/s) of the body."""
        body = self.robot_body
        vx, vy = body.velocity
        a = body.angle
        return vx * math.cos(a) + vy * math.sin(a), body.angular_velocity

    def camera_pose(self):
        """The robot's camera as ``sim.scene.CameraPose`` (mount from ``robot_spec``)."""
        spec = self.robot_spec
        x, y, heading = self.robot_pose()
        return CameraPose(
            x=x + spec.camera_forward * math.cos(heading),
            y=y + spec.camera_forward * math.sin(heading),
            heading=heading,
            height=spec.camera_height,
            tilt=spec.camera_tilt + self.camera_pitch(),
        )

    def people_states(self):
        """Every person's position, as ``records.PersonState``."""
        states = []
        for p in self.people:
            x, y = p.body.position
            states.append(
                PersonState(p.config.name, float(x), float(y), p.config.radius, p.config.target)
            )
        return states

    def target_position(self):
        """``(x, y)`` of the target person, or None if there is none."""
        if self._target is None:
            return None
        x, y = self._target.body.position
        return float(x), float(y)

    def lighting_at(self, t=None):
        """``sim.scene.Lighting`` at ``t`` (default: now)."""
        return self.lighting.at(self.time if t is None else t)

    def scene(self):
        """What the camera sees now, as ``sim.scene.Scene``."""
        room = self.config.room
        cylinders = []
        for p in self.people:
            x, y = p.body.position
            vx, vy = p.body.velocity
            cylinders.append(
                Cylinder(
                    x=float(x),
                    y=float(y),
                    radius=p.config.radius,
                    bands=p.bands,
                    facing=p.facing,
                    speed=math.hypot(vx, vy),
                    walked=p.walked,
                )
            )
        return Scene(
            walls=self._static_walls,
            cylinders=tuple(cylinders),
            floor_color=tuple(room.floor_color),
            ceiling_color=tuple(room.ceiling_color),
            ceiling_height=room.height,
            lighting=self.lighting.at(self.time),
            floor_patches=self._floor_patches,
        )

    def world_map(self):
        """Geometry for the viewer's top-down map (``records.WorldMap``); a new map after
        furniture has left (``present_until``)."""
        return self._world_map

    def present_furniture(self):
        """The furniture still in the room (``config.FurnitureConfig``), in file order."""
        return [f for f in self.config.room.furniture if f.name not in self._removed]

    def furniture_contacts(self, name):
        """Collision episodes of the robot with the furniture item ``name`` since the start."""
        if name not in self._furniture_shapes:
            raise ValueError(f"no furniture named {name!r}")
        return self._collisions.episodes_with("furniture", name)

    def floor_color_at(self, x, y):
        """The albedo ``(r, g, b)`` of the floor at ``(x, y)``: the last marking that covers
        the point, else the last painted terrain patch that holds it, else the floor's."""
        for line in reversed(self.floor_lines):
            x0, y0, x1, y1 = line.bounds
            if x0 <= x <= x1 and y0 <= y <= y1 and line.covers(x, y):
                return line.color
        patch = self._painted.at(x, y) if self._painted else None
        return tuple(patch.color) if patch is not None else tuple(self.config.room.floor_color)

    def floor_colors_at(self, x, y):
        """``floor_color_at`` for arrays of points: an ``(n, 3)`` float array."""
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        out = np.empty((x.size, 3))
        for i in range(x.size):
            patch = self._painted.at(x[i], y[i]) if self._painted else None
            out[i] = patch.color if patch is not None else self.config.room.floor_color
        for line in self.floor_lines:  # in file order: a later line paints over
            x0, y0, x1, y1 = line.bounds
            near = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
            if near.any():
                idx = np.flatnonzero(near)
                out[idx[line.covers(x[idx], y[idx])]] = line.color
        return out

    def drain_events(self):
        """Events since the last call, e.g. ``"collision with wall"``, ``"furniture 'box'
        removed"``."""
        events, self._events = self._events, []
        return events

    def collision_counts(self):
        """Robot collision episodes since the start, per kind: ``{"person", "wall",
        "furniture"}`` (``collisions.EPISODE_GAP`` joins contacts with one body)."""
        return self._collisions.episodes()

    def collision_summary(self):
        """Per kind: ``{"episodes", "contact_s", "max_impulse_ns"}``: collision episodes, the
        time spent touching (s) and the largest contact impulse of one physics step (N s)."""
        return self._collisions.summary(self.time)

    def at_fault_collisions(self):
        """Collision episodes with a person that were the robot's fault: it closed the gap
        faster than the person, and faster than ``AT_FAULT_SPEED``."""
        return self._collisions.at_fault("person")
