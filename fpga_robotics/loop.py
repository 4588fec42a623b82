"""The closed loop: SimCamera → design → SimMotors, stepped on a fixed clock.

Timing. Physics advances in fixed steps of ``sim.physics_dt``. Frame ``k`` is captured at
``k / fps`` (rounded to the nearest physics step): the world's scene at that instant is
rendered, the design processes it with the colour select in force, and its wheel command
(DPS) takes effect ``sim.actuation_delay`` seconds later (rounded to a step), the previous
command staying in force until then. Everything is a function of the scenario and the seed:
``run_scenario`` keeps no global state and can be called many times in one process.
"""

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .hw.pixel import color_select_value
from .sim.records import FrameRecord
from .sim_camera import SimCamera, in_view
from .sim_motors import SimMotors
from .summary import compute_metrics, evaluate_checks, verdict

__all__ = ["TRAJECTORY_FIELDS", "RunResult", "make_backend", "run_scenario"]

#: Per-frame arrays of ``RunResult.trajectory`` (one entry per camera frame, at capture time).
TRAJECTORY_FIELDS = (
    "t", "x", "y", "heading", "v", "w", "cmd_v", "cmd_w",
    "found", "proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right",
    "color_sel", "target_x", "target_y", "target_distance", "target_in_view",
)


@dataclass(eq=False)
class RunResult:
    """What one closed-loop run produced.

    Attributes
    ----------
    summary : dict
        JSON-ready: run identity, timing, metrics, ``checks`` and ``verdict``.
    trajectory : dict of numpy arrays
        ``TRAJECTORY_FIELDS``, one value per camera frame (NaN where there is no target).
    events : list of (frame, time_s, text)
    """

    summary: dict
    trajectory: dict
    events: list = field(default_factory=list)

    @property
    def passed(self):
        return self.summary["verdict"] == "pass"


def make_backend(name, params):
    """A ``DesignBackend`` by name ("auto" = the fastest available compiled one)."""
    from .sim.backends import fastest_backend_name, get_backend

    if name == "auto":
        name = fastest_backend_name()
    return get_backend(name, params)


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


def run_scenario(scenario, *, seed=None, backend="auto", recorder=None, progress=None,
                 realtime=False, on_frame=None):
    """Run one scenario in closed loop and measure it.

    Parameters
    ----------
    scenario : Scenario
        From ``fpga_robotics.scenario.load_scenario``.
    seed : int, optional
        Fixes every random choice (world and camera noise); default the scenario's seed.
    backend : str or DesignBackend
        A backend name ("auto", "model", "pysim", "cxxrtl", "verilator") or a ready backend
        built for ``scenario.params`` (it is reset first; the caller keeps ownership).
    recorder : object with log_world_map, log_frame, optional
        The viewer (``fpga_robotics.viz.open_recorder``); not closed here.
    progress : callable(frames_done, frames_total), optional
    realtime : bool
        Pace the simulation to the wall clock.
    on_frame : callable(FrameRecord), optional
        Called for every frame (tests, custom logging).
    """
    from .sim.world import World

    seed = scenario.seed if seed is None else int(seed)
    params = scenario.params
    cam = scenario.camera
    sim = scenario.sim

    world = World.from_config(scenario.world, seed)
    spec = world.robot_spec
    camera = SimCamera(
        cam.width, cam.height, cam.hfov,
        mount_height=cam.mount_height if cam.mount_height is not None else spec.camera_height,
        mount_forward=(cam.mount_forward if cam.mount_forward is not None
                       else spec.camera_forward),
        tilt=cam.tilt if cam.tilt is not None else spec.camera_tilt,
        noise_std=cam.noise_std,
        # A stream of its own, so that camera noise never shifts the world's randomness.
        rng=np.random.default_rng([seed, 0xCA3E]),
    )
    motors = SimMotors(world)

    owns_backend = isinstance(backend, str)
    design = make_backend(backend, params) if owns_backend else backend
    if design.params != params:
        raise ValueError("the backend was built for other parameters than the scenario's")
    design.reset()

    dt = sim.physics_dt
    period = cam.frame_period
    total_steps = max(1, round(sim.duration / dt))
    n_frames = 0
    while round(n_frames * period / dt) < total_steps:
        n_frames += 1

    traj = {name: np.zeros(n_frames) for name in TRAJECTORY_FIELDS}
    for name in ("found", "target_in_view"):
        traj[name] = np.zeros(n_frames, bool)
    for name in ("proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right",
                 "color_sel"):
        traj[name] = np.zeros(n_frames, np.int64)
    events_all = []
    design_events = _DesignEvents(params.lost_frames)
    want_records = recorder is not None or on_frame is not None
    target_radius = next((p.radius for p in world.people_states() if p.is_target), 0.0)
    if recorder is not None:
        recorder.log_world_map(world.world_map())

    color = scenario.color_at(0.0)
    color_code = color_select_value(color)
    step = 0
    wall_start = time.perf_counter()
    cpu_start = time.process_time()
    try:
        for k in range(n_frames):
            capture_step = round(k * period / dt)
            while step < capture_step:
                motors.apply_due(step)
                world.step(dt)
                step += 1
            t = step * dt
            motors.apply_due(step)  # commands that take effect at this very instant

            # Capture and process.
            rx, ry, heading = world.robot_pose()
            pose = camera.pose((rx, ry, heading))
            rgb = camera.capture(world.scene(), pose)
            events = list(world.drain_events())
            new_color = scenario.color_at(t)
            if new_color != color:
                events.append(f"colour select changed to {new_color}")
                color, color_code = new_color, color_select_value(new_color)
            result = design.process_frame(rgb, color_code)
            events += design_events.update(bool(result.found))
            apply_step = round((k * period + sim.actuation_delay) / dt)
            motors.schedule(apply_step, result.motor_left, result.motor_right)
            motors.apply_due(step)  # a zero delay acts now

            # Measure.
            v, w = world.robot_velocity()
            cmd_v, cmd_w = world.commanded_twist()
            target = world.target_position()
            people = world.people_states() if want_records else []
            if target is not None:
                tx, ty = target
                dist = math.hypot(tx - rx, ty - ry)
                visible = in_view(pose, cam.hfov, tx, ty, target_radius)
            else:
                tx = ty = dist = math.nan
                visible = False
            row = traj
            row["t"][k], row["x"][k], row["y"][k], row["heading"][k] = t, rx, ry, heading
            row["v"][k], row["w"][k], row["cmd_v"][k], row["cmd_w"][k] = v, w, cmd_v, cmd_w
            row["found"][k], row["proximity"][k] = result.found, result.proximity
            row["centroid_x"][k], row["centroid_leds"][k] = result.centroid_x, result.centroid_leds
            row["motor_left"][k], row["motor_right"][k] = result.motor_left, result.motor_right
            row["color_sel"][k] = color_code
            row["target_x"][k], row["target_y"][k] = tx, ty
            row["target_distance"][k], row["target_in_view"][k] = dist, visible
            events_all += [(k, round(t, 6), e) for e in events]

            if want_records:
                record = FrameRecord(
                    frame=k, sim_time=t, camera_rgb=rgb, color_sel=color_code,
                    result=result, robot_x=rx, robot_y=ry, robot_heading=heading,
                    robot_v=v, robot_w=w, cmd_v=cmd_v, cmd_w=cmd_w, camera_hfov=cam.hfov,
                    people=people, target_distance=None if target is None else dist,
                    target_in_view=visible, events=events,
                )
                if recorder is not None:
                    recorder.log_frame(record)
                if on_frame is not None:
                    on_frame(record)
            if progress is not None:
                progress(k + 1, n_frames)
            if realtime:
                ahead = (t + period) - (time.perf_counter() - wall_start)
                if ahead > 0:
                    time.sleep(ahead)
        while step < total_steps:
            motors.apply_due(step)
            world.step(dt)
            step += 1
        tail = list(world.drain_events())
        events_all += [(n_frames, round(step * dt, 6), e) for e in tail]
    finally:
        if owns_backend:
            design.close()
    wall = time.perf_counter() - wall_start
    cpu = time.process_time() - cpu_start

    sim_time = total_steps * dt
    metrics = compute_metrics(traj, events_all, world.collision_counts(), period)
    checks = evaluate_checks(scenario.checks, metrics)
    summary = {
        "scenario": scenario.name,
        "backend": design.name,
        "resolution": f"{cam.width}x{cam.height}",
        "seed": seed,
        "color": scenario.color_initial,
        "overrides": list(scenario.overrides),
        "fps": cam.fps,
        "physics_dt_s": dt,
        "actuation_delay_s": sim.actuation_delay,
        "sim_time_s": round(sim_time, 6),
        "frames": n_frames,
        "wall_time_s": round(wall, 4),
        "ms_per_frame": round(1000.0 * wall / max(1, n_frames), 4),
        "realtime_factor": round(sim_time / wall, 3) if wall > 0 else None,
        # CPU time of this process: the cost per frame on a machine busy with other work.
        "cpu_ms_per_frame": round(1000.0 * cpu / max(1, n_frames), 4),
        **metrics,
        "events": len(events_all),
        "verdict": verdict(checks),
        "checks": checks,
    }
    return RunResult(summary=summary, trajectory=traj, events=events_all)
