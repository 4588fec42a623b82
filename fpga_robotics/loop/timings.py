"""``run_scenario``: one scenario in the loop timing it asks for (``sim.timing``)."""

from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.loop.compressed import run_compressed
from fpga_robotics.loop.pin_frames import PinFrames, open_pin_frames
from fpga_robotics.loop.real_clock import run_real_clock
from fpga_robotics.sim.backends import BACKEND_NAMES
from fpga_robotics.sim.backends.foreign import ForeignDesign
from fpga_robotics.sim.backends.foreign_choice import open_foreign_frames
from fpga_robotics.sim.backends.port_map import load_port_map
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
        of the scenario's design (it is reset first; the caller keeps ownership): in
        compressed timing ``get_backend(name, scenario.params)`` for FollowTarget, in
        real-clock timing a pin backend (``loop.real_clock.make_pin_backend``). A design of
        one's own or a Verilog design in compressed timing runs on a backend name.
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
    if isinstance(backend, str) and backend not in ("auto", *BACKEND_NAMES):
        # Said before the design is built (a component built and never simulated).
        raise UsageError(
            f"unknown backend {backend!r}; choose one of: auto, {', '.join(BACKEND_NAMES)}"
        )
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
    compressed = scenario.sim.timing == "compressed"
    if not isinstance(backend, str):
        check_ready_backend(backend, scenario)
    elif compressed and scenario.top not in TOPS:
        # A camera-only design of one's own: frame by frame on its pin backend, closed after.
        with open_pin_frames(backend, scenario) as design:
            return run_compressed(scenario, backend=design, **options)
    elif compressed and scenario.foreign is not None:
        # A Verilog design's own frame backend (a backend name alone opens FollowTarget).
        files = scenario.foreign
        with open_foreign_frames(
            backend,
            scenario.params,
            files=files.verilog,
            port_map=files.ports,
            overrides=files.overrides,
        ) as design:
            return run_compressed(scenario, backend=design, **options)
    return TIMINGS[scenario.sim.timing](scenario, backend=backend, **options)


def _design_of(backend):
    """What a ready frame backend simulates: ``("own", reference, params)`` for a design of
    one's own, ``("verilog", top)`` for a Verilog design, else ``("follow_target",)``."""
    if isinstance(backend, PinFrames):
        return ("own", backend.top, backend.design_params)
    design = getattr(backend, "design", None)
    if isinstance(design, ForeignDesign):
        return ("verilog", design.port_map.top)
    return ("follow_target",)


def _describe(design):
    kind = design[0]
    if kind == "own":
        return f"design {design[1]!r}"
    return f"the Verilog design {design[1]}" if kind == "verilog" else "FollowTarget"


def check_ready_backend(backend, scenario):
    """``TypeError`` for a ``backend`` that is no backend, or not one of the scenario's timing
    (frames in compressed timing, pins in real-clock timing); ``ValueError`` for a ready
    backend of another design than the scenario's (a FollowTarget backend would otherwise
    run in place of a design of one's own)."""
    # The names that run the scenario's design: the model is FollowTarget's, and a Verilog
    # design runs on the compiled simulators only.
    if scenario.foreign is not None:
        names = '"auto", "cxxrtl", "verilator"'
    elif scenario.top not in TOPS or scenario.sim.timing == "real_clock":
        names = '"auto", "cxxrtl", "verilator", "pysim"'
    else:
        names = '"auto", "model", "pysim", "cxxrtl", "verilator"'
    if not (hasattr(backend, "ports") or callable(getattr(backend, "process_frame", None))):
        raise TypeError(
            f"backend must be a backend name ({names}) or a ready backend, got {backend!r}"
        )
    if scenario.sim.timing == "real_clock":
        if not hasattr(backend, "ports"):
            raise TypeError(
                f'scenario {scenario.name!r} runs in sim.timing = "real_clock": its design '
                f"runs on a pin backend (loop.real_clock.make_pin_backend) or a backend name "
                f"({names}), not on a frame backend"
            )
        return
    if not callable(getattr(backend, "process_frame", None)):
        raise TypeError(
            f'scenario {scenario.name!r} runs in sim.timing = "compressed": its design runs '
            f"on a frame backend (get_backend) or a backend name ({names}), not on a pin backend"
        )
    runs = _design_of(backend)
    if scenario.top not in TOPS:
        wanted = ("own", scenario.top, dict(scenario.design_params))
    elif scenario.foreign is not None:
        wanted = ("verilog", load_port_map(scenario.foreign.ports).top)
    else:  # FollowTarget, or a Verilog design in its place (run --design verilog:...)
        wanted = runs if runs[0] == "verilog" else ("follow_target",)
    if runs[:2] != wanted[:2]:
        raise ValueError(
            f"the ready backend runs {_describe(runs)}; scenario {scenario.name!r} runs "
            f"{_describe(wanted)}: give run_scenario a backend name ({names}) to run it"
        )
    if runs != wanted:
        raise ValueError(
            f"the ready backend runs {_describe(runs)} with other design.params than "
            f"scenario {scenario.name!r}: give run_scenario a backend name ({names})"
        )
