"""``run_scenario``: one scenario in the loop timing it asks for (``sim.timing``)."""

from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.loop.compressed import run_compressed
from fpga_robotics.loop.pin_frames import open_pin_frames
from fpga_robotics.loop.real_clock import run_real_clock
from fpga_robotics.sim.world.world import check_seed

__all__ = ["TIMINGS", "run_scenario"]

#: ``sim.timing`` -> the function that runs a scenario in that timing (``run_scenario``'s
#: arguments, by keyword).
TIMINGS = {"compressed": run_compressed, "real_clock": run_real_clock}


def run_scenario(
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
    shadow : DesignBackend, optional
        A second design run on the same frames in lockstep, never driving the robot; the
        summary gains ``shadow`` (first divergence, differing frames per output). Reset
        first; the caller keeps ownership.
    shadow_label : str
        How the summary and the events name the shadow design.
    controls : object with inputs_for(frame, t), optional
        Live control inputs (``fpga_robotics.ros.controls``): colour select, the target
        driven by hand, pause and step; applied just after each frame's capture.
    """
    if seed is not None:
        check_seed(seed)  # before int() would turn 1.5 or "1" into another seed
    options = {
        "seed": seed,
        "recorder": recorder,
        "progress": progress,
        "realtime": realtime,
        "on_frame": on_frame,
        "shadow": shadow,
        "shadow_label": shadow_label,
        "controls": controls,
    }
    own = scenario.top not in TOPS and scenario.sim.timing == "compressed"
    if own and isinstance(backend, str):
        # A camera-only design of one's own: frame by frame on its pin backend, closed after.
        with open_pin_frames(backend, scenario) as design:
            return run_compressed(scenario, backend=design, **options)
    return TIMINGS[scenario.sim.timing](scenario, backend=backend, **options)
