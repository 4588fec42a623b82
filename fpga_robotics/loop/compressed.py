"""The closed loop: CameraConnector → design → MotorConnector, stepped on a fixed clock.

Timing. Physics advances in fixed steps of ``sim.physics_dt``. Frame ``k`` is captured at
``k / fps`` (rounded to the nearest physics step): the world's scene at that instant is
rendered, the design processes it with the colour select in force, and its wheel command
(DPS) takes effect ``sim.actuation_delay`` seconds later (rounded to a step), the previous
command staying in force until then. A robot that tips over ends the run at the frame that
reports it (``RunResult``, summary ``ended_early``). Everything is a function of the scenario
and the seed: ``run_compressed`` keeps no global state and can be called many times in one
process.
"""

import math
import time
from dataclasses import dataclass, field

import numpy as np

from fpga_robotics.checks.envelopes import envelope_geometry, envelope_metrics, lit_strip_frames
from fpga_robotics.checks.reach import mean_distance_floor
from fpga_robotics.checks.sensor_metrics import obstacle_metrics
from fpga_robotics.checks.summary import (
    DESIGN_OUTPUTS,
    compute_metrics,
    evaluate_checks,
    rounded,
    verdict,
)
from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.hw.pixel import color_select_value
from fpga_robotics.loop.bindings import check_bindings
from fpga_robotics.loop.camera_rig import CameraRig
from fpga_robotics.loop.connectors import CameraConnector, MotorConnector, in_view
from fpga_robotics.loop.connectors.camera import ExposureDrift, make_sensor
from fpga_robotics.loop.pin_channel import PIN_CHANNEL_BACKENDS
from fpga_robotics.loop.shadow import ShadowComparison, divergence_event
from fpga_robotics.ros.controls import apply_inputs
from fpga_robotics.sim.backends import fastest_backend_name, get_backend
from fpga_robotics.sim.camera.raster import focal_length, silhouette_columns
from fpga_robotics.sim.records import FrameRecord
from fpga_robotics.sim.world import World, dps_to_twist, is_removal_event

__all__ = [
    "TRAJECTORY_FIELDS",
    "ClosedLoop",
    "RunResult",
    "extra_output_stats",
    "frame_count",
    "make_backend",
    "run_compressed",
    "run_loop",
]

#: Per-frame arrays of ``RunResult.trajectory`` (one entry per camera frame, at capture time).
TRAJECTORY_FIELDS = (
    "t",
    "x",
    "y",
    "heading",
    "driven_x",
    "driven_y",
    "v",
    "w",
    "cmd_v",
    "cmd_w",
    "found",
    "proximity",
    "centroid_x",
    "centroid_leds",
    "motor_left",
    "motor_right",
    "color_sel",
    "target_x",
    "target_y",
    "target_distance",
    "target_in_view",
    "target_column",
    "target_left",
    "target_right",
    "target_hidden",
    "camera_tilt",
)


@dataclass(eq=False)
class RunResult:
    """What one closed-loop run produced.

    Attributes
    ----------
    summary : dict
        JSON-ready: run identity, timing, metrics, ``checks`` and ``verdict``.
    trajectory : dict of numpy arrays
        ``TRAJECTORY_FIELDS``, one value per camera frame (NaN where there is no target, and
        in every frame of a design output the design lacks: ``summary["absent_outputs"]``).
    events : list of (frame, time_s, text)

    A robot that tips over ends the run at the frame that reports it (``World.tipped``):
    the trajectory holds the frames done, ``summary["frames"]`` counts them,
    ``summary["sim_time_s"]`` is the time reached and ``summary["ended_early"]`` says why
    (None for a run to its end).
    """

    summary: dict
    trajectory: dict
    events: list = field(default_factory=list)

    @property
    def passed(self):
        return self.summary["verdict"] == "pass"


def make_backend(name, params, *, on_build=None):
    """A ``DesignBackend`` by name ("auto" = the fastest available compiled one);
    ``on_build(text)`` is told before a compiled model is built (not found in the cache)."""
    if name == "auto":
        name = fastest_backend_name()
    return get_backend(name, params, on_build=on_build)


def extra_output_stats(column, exact):
    """``{"last", "min", "max"}`` (None where no row holds a value) of an extra output from
    ``exact`` (row -> int), its rows of the trajectory ``column``: the column is float64,
    which rounds an output of more than 53 bits."""
    values = [value for k, value in sorted(exact.items()) if k < len(column)]
    if not values:
        return {"last": None, "min": None, "max": None}
    return {"last": values[-1], "min": min(values), "max": max(values)}


def frame_count(duration_steps, frame_period, physics_dt):
    """How many camera frames a run of ``duration_steps`` physics steps captures: frame ``k``
    is captured at step ``round(k * frame_period / physics_dt)``, which must fall inside the
    run. Computed directly (a run may be long), starting just below the answer."""
    ratio = frame_period / physics_dt
    n = max(0, math.ceil((duration_steps - 0.5) / ratio) - 1)
    while round(n * frame_period / physics_dt) < duration_steps:  # the capture step's formula
        n += 1
    return n


class _DesignEvents:
    """Turns the design's per-frame outputs into events: found, lost, search started."""

    def __init__(self, lost_frames):
        self.lost_frames = lost_frames
        self.found = False
        self.misses = 0  # consecutive frames without the target (as the motor controller counts)

    def update(self, found):
        events = []
        if found:
            if not self.found:
                events.append("target found")
            self.misses = 0
        else:
            if self.found:
                events.append("target lost")
            self.misses += 1
            # The controller holds its command until the count reaches lost_frames, then
            # turns in place towards the side it last saw the target on.
            if self.misses == self.lost_frames:
                events.append("search started")
        self.found = found
        return events


class ClosedLoop:
    """One closed-loop run, as the steps a reader can follow: ``build`` the world, the camera
    and the motor connector; for each frame ``advance_physics`` to its capture instant,
    ``capture`` the camera image, ``process`` it in the design and schedule the command,
    ``measure`` the robot and the target, ``record`` the frame; then ``finish_physics`` and
    ``summarise``. ``run()`` does all of it. Built by ``run_scenario``; see its parameters."""

    def __init__(
        self,
        scenario,
        *,
        seed=None,
        design,
        recorder=None,
        on_frame=None,
        shadow=None,
        shadow_label="shadow",
        controls=None,
    ):
        self.scenario = scenario
        self.seed = scenario.seed if seed is None else int(seed)
        self.design = design
        self.recorder = recorder
        self.on_frame = on_frame
        self.want_records = recorder is not None or on_frame is not None

        cam, sim = scenario.camera, scenario.sim
        self.world = World.from_config(scenario.world, self.seed)
        self.camera = self._build_camera(cam, self.world.robot_spec)
        self.motors = MotorConnector(self.world)
        self.dt = sim.physics_dt
        self.period = cam.frame_period
        self.total_steps = max(1, round(sim.duration / self.dt))
        self.n_frames = frame_count(self.total_steps, self.period, self.dt)
        self.step = 0  # physics steps done
        self.frames_done = 0
        self.ended_early = None  # why the run stopped before its end (a tip-over), else None
        self.traj = _empty_trajectory(self.n_frames)
        self.absent = set()  # DESIGN_OUTPUTS the design does not produce
        self.exact_extra = {}  # extra output -> {row: int}, for the summary
        self.events = []  # (frame, time_s, text)
        self.cycles = 0  # design clock edges simulated
        self.design_events = _DesignEvents(scenario.params.lost_frames)
        self.target_radius = next(
            (p.radius for p in self.world.people_states() if p.is_target), 0.0
        )
        self.target_height = next((p.height for p in self.world.config.people if p.target), 0.0)
        self.color = self.scheduled_color = scenario.color_at(0.0)
        self.color_code = color_select_value(self.color)
        # Live control inputs (fpga_robotics.ros.controls), asked once per frame.
        self.controls = controls
        # A second design on the same frames, never driving the robot (fpga_robotics.loop.shadow).
        self.shadow = shadow
        self.comparison = ShadowComparison(shadow_label) if shadow is not None else None
        check_bindings(scenario)  # as the command line does, before it builds the design
        # Further cameras and pan servos ([[robot.sensors]] cameras, [[robot.actuators]]
        # servos); None without any, and then nothing below changes.
        self.rig = CameraRig.build(scenario, self.world, self.seed, TOPS.get(scenario.top))
        # On a clocked backend the further cameras' channels run on the design too.
        clocked = getattr(design, "name", None) in PIN_CHANNEL_BACKENDS
        if self.rig is not None and sim.timing == "compressed" and clocked:
            self.rig.run_channels_on(design.name, scenario, TOPS[scenario.top])

    def _build_camera(self, cam, spec):
        """The camera on the robot; mount values the scenario leaves unset are the robot's."""
        return CameraConnector(
            cam.width,
            cam.height,
            cam.hfov,
            mount_height=cam.mount_height if cam.mount_height is not None else spec.camera_height,
            mount_forward=(
                cam.mount_forward if cam.mount_forward is not None else spec.camera_forward
            ),
            tilt=cam.tilt if cam.tilt is not None else spec.camera_tilt,
            noise_std=cam.noise_std,
            renderer=cam.renderer,
            render3d=cam.render3d,
            # A stream of its own, so that camera noise never shifts the world's randomness.
            rng=np.random.default_rng([self.seed, 0xCA3E]),
            yaw_offset=cam.yaw_offset,
            # camera.exposure_drift: a stream of its own too, one step per frame.
            drift=(
                ExposureDrift(
                    cam.exposure_drift, cam.frame_period, np.random.default_rng([self.seed, 0xD41F])
                )
                if cam.exposure_drift > 0
                else None
            ),
            # camera.sensor = "ov7670": the sensor model, blurred by the robot's turn rate.
            sensor=make_sensor(cam, self.seed),
            turn_rate=self.camera_turn_rate,
        )

    def restored(self):
        """Called once a checkpoint's state is in place (fpga_robotics.loop.checkpoint): what
        the state refers to of the loop itself is bound again."""
        self.camera.turn_rate = self.camera_turn_rate

    def camera_turn_rate(self):
        """The robot's turn rate now, rad/s (the sensor model's motion blur)."""
        return self.world.robot_velocity()[1]

    # The steps of one frame ----------------------------------------------------------------

    def advance_physics(self, to_step):
        """Step the world up to ``to_step``, applying each motor command when it is due."""
        rig = self.rig
        while self.step < to_step:
            self.motors.apply_due(self.step)
            if rig is not None:
                rig.before_step(self.step, self.world)
            self.world.step(self.dt)
            if rig is not None:
                rig.after_step(self.dt)
            self.step += 1
        self.motors.apply_due(self.step)  # commands that take effect at this very instant
        if rig is not None:  # captures at this very instant, before the row samples them
            rig.before_step(self.step, self.world)

    def capture(self, t):
        """The camera image at time ``t``, with the events since the last frame."""
        # On a ramp the camera pitches with the robot (sim/world/terrain.py).
        pose = self.camera.pose(self.world.robot_pose(), self.world.camera_pitch)
        self.scene, self.pose = self.world.scene(), pose  # kept for the viewer's 3D world
        rgb = self.camera.capture(self.scene, pose)
        events = list(self.world.drain_events())
        new_color = self.scenario.color_at(t)
        if new_color != self.scheduled_color:  # a live colour holds until the next change
            events.append(f"colour select changed to {new_color}")
            self.scheduled_color = new_color
            self.set_color(new_color)
        return pose, rgb, events

    def set_color(self, color):
        self.color, self.color_code = color, color_select_value(color)

    def apply_controls(self, k, t):
        """The live control inputs due at frame ``k``, applied; returns their events."""
        if self.controls is None:
            return []
        return apply_inputs(self, self.controls.inputs_for(k, t))

    def process(self, k, rgb):
        """Frame ``k`` through the design; its wheel command acts after the actuation delay."""
        result = self.design.process_frame(rgb, self.color_code)
        apply_step = round((k * self.period + self.scenario.sim.actuation_delay) / self.dt)
        self.motors.schedule(apply_step, _dps(result.motor_left), _dps(result.motor_right))
        self.motors.apply_due(self.step)  # a zero delay acts now
        return result

    def process_shadow(self, k, t, rgb, result):
        """Frame ``k`` through the shadow design; returns its result and events."""
        if self.shadow is None:
            return None, []
        shadow_result = self.shadow.process_frame(rgb, self.color_code)
        first = self.comparison.first_divergence is None
        differ = self.comparison.compare(k, t, result, shadow_result)
        events = []
        if differ and first:
            events.append(divergence_event(self.comparison.label, differ, result, shadow_result))
        return shadow_result, events

    def measure(self, k, t, pose, result):
        """Fill trajectory row ``k``; return the target's distance and visibility."""
        measured = self.measure_world(k, t, pose)
        self.store_outputs(k, result)
        return measured

    def measure_world(self, k, t, pose):
        """Row ``k``'s robot and target fields at time ``t``; returns the target's distance
        (None without a target) and whether it is in the camera's view."""
        rx, ry, heading = self.world.robot_pose()
        v, w = self.world.robot_velocity()
        cmd_v, cmd_w = self.world.commanded_twist()
        target = self.world.target_position()
        if target is not None:
            tx, ty = target
            dist = math.hypot(tx - rx, ty - ry)
            visible = in_view(
                pose, self.scenario.camera, tx, ty, self.target_radius, self.target_height
            )
            column = target_column(pose, self.scenario.camera, tx, ty)
            edges = target_silhouette(pose, self.scenario.camera, tx, ty, self.target_radius)
            hidden = visible and target_hidden(pose, self.world, self.scenario.camera)
        else:
            tx = ty = dist = column = math.nan
            edges = (math.nan, math.nan)
            visible = hidden = False
        row = self.traj
        row["t"][k], row["x"][k], row["y"][k], row["heading"][k] = t, rx, ry, heading
        row["driven_x"][k], row["driven_y"][k] = self.world.driven_position()
        row["v"][k], row["w"][k], row["cmd_v"][k], row["cmd_w"][k] = v, w, cmd_v, cmd_w
        row["color_sel"][k] = self.color_code
        row["target_x"][k], row["target_y"][k] = tx, ty
        row["target_distance"][k], row["target_in_view"][k] = dist, visible
        row["target_column"][k] = column
        row["target_left"][k], row["target_right"][k] = edges
        row["target_hidden"][k] = hidden
        row["camera_tilt"][k] = pose.tilt  # the mount's tilt plus the slope's pitch
        return (None if target is None else dist), visible

    def store_outputs(self, k, result):
        """Row ``k``'s design outputs from ``result`` (a ``FrameResult``), its extra outputs
        in columns ``design.<name>``."""
        if result.cycles is not None:
            self.cycles += result.cycles
        for name in DESIGN_OUTPUTS:  # an absent one (None) drives its wheel at 0 DPS
            value = getattr(result, name)
            if value is None:
                self.absent.add(name)  # stored as 0 here, NaN once the run is done (summary.py)
            else:
                self.traj[name][k] = value
        for name, value in (result.extra or {}).items():
            self.traj.setdefault(f"design.{name}", np.full(self.n_frames, np.nan))[k] = value
            self.exact_extra.setdefault(name, {})[k] = int(value)

    def record(self, k, t, rgb, result, distance, visible, events, shadow_result=None, **extra):
        """Hand the frame to the viewer and the ``on_frame`` callback; ``extra`` are more
        ``FrameRecord`` fields (``sensors``, ``design_extra``)."""
        row = self.traj
        # The twist this frame's wheel command means (as a bag's /cmd_vel), not the one in
        # force at its capture (the trajectory's cmd_v), which lags it by the actuation delay.
        spec = self.world.robot_spec
        cmd_v, cmd_w = dps_to_twist(
            _dps(result.motor_left),
            _dps(result.motor_right),
            spec.wheel_radius,
            spec.wheel_separation,
        )
        record = FrameRecord(
            frame=k,
            sim_time=t,
            camera_rgb=rgb,
            color_sel=self.color_code,
            result=result,
            robot_x=row["x"][k],
            robot_y=row["y"][k],
            robot_heading=row["heading"][k],
            robot_v=row["v"][k],
            robot_w=row["w"][k],
            cmd_v=cmd_v,
            cmd_w=cmd_w,
            camera_hfov=self.scenario.camera.hfov,
            people=self.world.people_states(),
            target_distance=distance,
            target_in_view=visible,
            events=events,
            shadow_result=shadow_result,
            scene=self.scene,
            camera_pose=self.pose,
            robot_radius=self.world.robot_spec.body_radius,
            **extra,
        )
        if self.recorder is not None:
            update = getattr(self.recorder, "update_furniture", None)
            if update is not None and any(map(is_removal_event, events)):
                update(self.world.world_map(), k, t)  # drawn without it from now on
            self.recorder.log_frame(record)
        if self.on_frame is not None:
            self.on_frame(record)

    def run_frame(self, k):
        self.advance_physics(round(k * self.period / self.dt))
        t = self.step * self.dt
        pose, rgb, events = self.capture(t)
        events += self.apply_controls(k, t)
        result = self.process(k, rgb)
        shadow_result, shadow_events = self.process_shadow(k, t, rgb, result)
        if result.found is not None:  # a design without `found` has no found/lost events
            events += self.design_events.update(bool(result.found))
        events += shadow_events
        # A command that acts at once (no actuation delay) may tip the robot: this frame's.
        events += self.world.drain_events()
        distance, visible = self.measure(k, t, pose, result)
        extra = {"design_extra": result.extra} if result.extra else {}
        if self.rig is not None:
            self.rig.sample(k, self.n_frames, self.world)
            if self.want_records:
                extra.update(cameras=self.rig.views(), sensors=self.rig.readings(self.world))
        self.events += [(k, round(t, 6), e) for e in events]
        self.frames_done = k + 1
        if self.want_records:
            self.record(k, t, rgb, result, distance, visible, events, shadow_result, **extra)

    def tipped_over(self):
        """Whether the robot has tipped over; if so the run ends (``ended_early``)."""
        if self.world.tipped is None:
            return False
        if self.ended_early is None:
            self.ended_early = f"tipped over at {self.step * self.dt:.2f} s"
        return True

    def finish_physics(self):
        """Physics after the last frame, to the end of the run or until the robot tips over
        (then the time reached is the tip's step)."""
        while self.step < self.total_steps and not self.tipped_over():
            self.advance_physics(self.step + 1)
        tail = list(self.world.drain_events())
        self.events += [(self.frames_done, round(self.step * self.dt, 6), e) for e in tail]

    # The whole run -------------------------------------------------------------------------

    def run(self, *, progress=None, realtime=False, start=0):
        """Run the frames from ``start`` on (a loop restored from a checkpoint taken before
        frame ``start``: fpga_robotics.loop.checkpoint) and finish the run."""
        if self.recorder is not None:
            self.recorder.log_world_map(self.world.world_map())
        wall_start = time.perf_counter()
        cpu_start = time.process_time()
        for k in range(start, self.n_frames):
            self.run_frame(k)
            if progress is not None:
                progress(k + 1, self.n_frames)
            if self.tipped_over():  # the frame that reported it is the last
                break
            if realtime:
                ahead = (self.step * self.dt + self.period) - (time.perf_counter() - wall_start)
                if ahead > 0:
                    time.sleep(ahead)
        if self.ended_early is None:
            self.finish_physics()
        return self.finish_run(wall_start, cpu_start)

    def finish_run(self, wall_start, cpu_start):
        """The ``RunResult`` once the frames and the physics after them are done."""
        self.after_frames()
        if self.rig is not None:  # "<servo>.angle_deg", "<camera>.turret_found" ...
            self.traj.update(self.rig.columns)
        if self.ended_early is not None:  # the trajectory holds the frames done, every field alike
            self.traj = {name: a[: self.frames_done] for name, a in self.traj.items()}
        for name in self.absent:
            self.traj[name] = np.full(len(self.traj[name]), np.nan)
        # The time a user held the run paused (live controls) is not the run's speed.
        wall = time.perf_counter() - wall_start - getattr(self.controls, "paused_s", 0.0)
        cpu = time.process_time() - cpu_start
        return RunResult(
            summary=self.summarise(wall, cpu), trajectory=self.traj, events=self.events
        )

    def after_frames(self):
        """Called once the frames (and the physics after them) are done."""

    def extra_metrics(self):
        """Metrics beyond ``compute_metrics``: whether following resumed after an obstacle
        left (fpga_robotics.checks.sensor_metrics), and the behaviour envelopes
        (fpga_robotics.checks.envelopes)."""
        geometry = envelope_geometry(self.scenario, self.world.config, self.camera)
        rig = self.rig.metrics(self.frames_done) if self.rig is not None else {}
        return {
            **obstacle_metrics(self.traj, self.events, self.period),
            **envelope_metrics(self.traj, self.scenario.params, geometry),
            **mean_distance_floor(self.traj, self.world.config.robot),
            **rig,
        }

    def timing_summary(self, wall):
        """How the design's clock related to world time, and how fast it was simulated."""
        return {
            "timing": "compressed",
            "clock_hz": None,
            "sim_cycles": self.cycles,
            "cycles_per_wall_s": round(self.cycles / wall) if wall > 0 else None,
        }

    def summarise(self, wall, cpu):
        scenario, cam, sim = self.scenario, self.scenario.camera, self.scenario.sim
        n_frames, dt = self.frames_done, self.dt
        sim_time = self.step * dt  # the end of the run, or the tip-over that ended it
        metrics = compute_metrics(
            self.traj,
            self.events,
            self.world.collision_counts(),
            self.period,
            at_fault_collisions=self.world.at_fault_collisions(),
            collision_summary=self.world.collision_summary(),
            width=cam.width,
            absent=self.absent,
            margin_x=scenario.params.margin_x,
            camera_mount=self.camera.mount,
            lit_strip=lit_strip_frames(
                self.traj, envelope_geometry(scenario, self.world.config, self.camera)
            ),
        )
        metrics.update(self.extra_metrics())
        # The last, smallest and largest value of each output no connector reads.
        extra = {
            name: extra_output_stats(self.traj[f"design.{name}"], self.exact_extra.get(name, {}))
            for name in (c.removeprefix("design.") for c in self.traj if c.startswith("design."))
        }
        # On the unrounded metrics; a registered check of a design of one's own reads its
        # outputs as the summary has them.
        checks = evaluate_checks(scenario.checks, {**metrics, "extra_outputs": extra})
        shadow = {"shadow": self.comparison.summary()} if self.comparison is not None else {}
        return {
            "scenario": scenario.name,
            "backend": self.design.name,
            "resolution": f"{cam.width}x{cam.height}",
            "seed": self.seed,
            "color": scenario.color_initial,
            "overrides": list(scenario.overrides),
            "fps": cam.fps,
            "physics_dt_s": dt,
            "actuation_delay_s": sim.actuation_delay,
            "sim_time_s": round(sim_time, 6),
            "frames": n_frames,
            "ended_early": self.ended_early,
            "wall_time_s": round(wall, 4),
            "ms_per_frame": round(1000.0 * wall / max(1, n_frames), 4),
            "realtime_factor": round(sim_time / wall, 3) if wall > 0 else None,
            # CPU time of this process: the cost per frame on a machine busy with other work.
            "cpu_ms_per_frame": round(1000.0 * cpu / max(1, n_frames), 4),
            **self.timing_summary(wall),
            **rounded(metrics),
            "events": len(self.events),
            "verdict": verdict(checks),
            "checks": checks,
            **shadow,
            **({"extra_outputs": extra} if extra else {}),
        }


def target_column(pose, cam, x, y):
    """The image column (pixels, 0 = left edge) of the centre of a person at ``(x, y)`` seen
    by a camera at ``pose``: ``W/2 - f tan(bearing)``, ``f = (W/2) / tan(hfov/2)`` (image
    right is the camera's right; sim/camera/raster.py). NaN when the centre is outside the field of
    view."""
    bearing = math.atan2(y - pose.y, x - pose.x) - pose.heading
    bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
    if abs(bearing) >= cam.hfov / 2:
        return math.nan
    return cam.width / 2 - focal_length(cam.width, cam.hfov) * math.tan(bearing)


def target_silhouette(pose, cam, x, y, radius):
    """``(left, right)``: the image columns (continuous pixels) of the edges of the silhouette
    of a person of ``radius`` at ``(x, y)`` seen by a camera at ``pose`` (an edge beyond the
    camera's side: -inf or +inf); NaN with the person's centre behind the camera."""
    bearing = math.atan2(y - pose.y, x - pose.x) - pose.heading
    bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
    if abs(bearing) >= math.pi / 2:
        return math.nan, math.nan
    distance = math.hypot(x - pose.x, y - pose.y)
    return silhouette_columns(distance, bearing, radius, cam.width, cam.hfov)


def target_hidden(pose, world, cam):
    """Whether furniture, a divider or another person hides part of the target from a camera
    at ``pose`` in ``world``: in a ray across the target's silhouette (one per image column
    it covers), something stands nearer than the target's surface and tall enough to cover
    the lowest of its bands seen past it. The target's pixel count and centroid are then not
    the whole silhouette's."""
    target = next(p for p in world.people if p.config.target)
    tx, ty = target.body.position
    radius = target.config.radius
    dx, dy = tx - pose.x, ty - pose.y
    distance = math.hypot(dx, dy)
    if distance <= radius:
        return False
    half = math.asin(radius / distance)
    rays = max(3, math.ceil(2 * half * focal_length(cam.width, cam.hfov)))
    offsets = (np.arange(rays) + 0.5) / rays * 2 * half - half  # inside the tangents
    angles = math.atan2(dy, dx) + offsets
    ux, uy = np.cos(angles), np.sin(angles)
    surface = distance * np.cos(offsets) - np.sqrt(
        np.maximum(0.0, radius**2 - (distance * np.sin(offsets)) ** 2)
    )
    lowest = min(band.z0 for band in target.bands)
    nearest = []  # per obstacle: (depth along each ray, inf where missed), its height
    for wall in world.scene().walls:
        if wall.kind == "room":
            continue  # the room's walls stand behind everyone in it
        ex, ey = wall.x1 - wall.x0, wall.y1 - wall.y0
        qx, qy = wall.x0 - pose.x, wall.y0 - pose.y
        with np.errstate(divide="ignore", invalid="ignore"):
            denom = ux * ey - uy * ex
            t = (qx * ey - qy * ex) / denom
            along = (qx * uy - qy * ux) / denom
        hit = (denom != 0) & (along >= 0) & (along <= 1) & (t > 0)
        nearest.append((np.where(hit, t, np.inf), wall.height))
    for person in world.people:
        if person is target:
            continue
        px, py = person.body.position
        qx, qy = pose.x - px, pose.y - py
        b = ux * qx + uy * qy
        disc = b * b - (qx * qx + qy * qy - person.config.radius**2)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        hit = (disc >= 0) & (t > 0)
        nearest.append((np.where(hit, t, np.inf), max(band.z1 for band in person.bands)))
    for depth, height in nearest:
        # The ray from the camera to the target's lowest band at its surface passes under
        # the obstacle's top where the obstacle stands.
        sight = pose.height + (lowest - pose.height) * depth / surface
        if np.any((depth < surface) & (sight < height)):
            return True
    return False


def _dps(command):
    """A wheel command as the motors take it: an absent one (None) is 0 DPS."""
    return 0 if command is None else command


def _empty_trajectory(n_frames):
    traj = {name: np.zeros(n_frames) for name in TRAJECTORY_FIELDS}
    for name in ("found", "target_in_view", "target_hidden"):
        traj[name] = np.zeros(n_frames, bool)
    for name in (
        "proximity",
        "centroid_x",
        "centroid_leds",
        "motor_left",
        "motor_right",
        "color_sel",
    ):
        traj[name] = np.zeros(n_frames, np.int64)
    return traj


def run_compressed(
    scenario,
    *,
    seed=None,
    backend="auto",
    recorder=None,
    progress=None,
    realtime=False,
    on_frame=None,
    shadow=None,
    shadow_label="shadow",
    controls=None,
):
    """``run_scenario`` (fpga_robotics.loop.timings) in compressed timing."""

    def build(design):
        if design.params != scenario.params:
            raise ValueError("the backend was built for other parameters than the scenario's")
        return ClosedLoop(
            scenario,
            seed=seed,
            design=design,
            recorder=recorder,
            on_frame=on_frame,
            shadow=shadow,
            shadow_label=shadow_label,
            controls=controls,
        )

    if isinstance(backend, str) and scenario.top not in TOPS:
        # A backend name opens FollowTarget; run_scenario opens a design of one's own.
        raise ValueError("a design of one's own runs on a ready backend (loop.pin_frames)")
    shadow_params = getattr(shadow, "params", None)
    camera = (scenario.camera.width, scenario.camera.height)
    if shadow_params is not None and (shadow_params.width, shadow_params.height) != camera:
        # Found here, not at the first frame as a frame of the wrong shape for the shadow.
        raise ValueError(
            f"the shadow backend is {shadow_params.width}x{shadow_params.height}, the "
            f"scenario's camera {camera[0]}x{camera[1]}: build the shadow for the scenario's "
            f"resolution"
        )
    return run_loop(
        backend,
        lambda name: make_backend(name, scenario.params),
        build,
        shadow=shadow,
        progress=progress,
        realtime=realtime,
    )


def run_loop(backend, open_backend, build_loop, *, shadow=None, progress=None, realtime=False):
    """Run a loop on ``backend``: a ready design (the caller keeps it) or a name, opened
    with ``open_backend(name)`` and closed after. The design and the ``shadow`` are reset,
    ``build_loop(design)`` makes the loop, which runs to its ``RunResult``."""
    owns_backend = isinstance(backend, str)
    design = open_backend(backend) if owns_backend else backend
    try:
        design.reset()
        if shadow is not None:
            shadow.reset()
        loop = build_loop(design)
        try:
            return loop.run(progress=progress, realtime=realtime)
        finally:
            if getattr(loop, "rig", None) is not None:
                loop.rig.close()
    finally:
        if owns_backend:
            design.close()
