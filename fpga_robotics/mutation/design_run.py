"""Mutation coverage of a design of one's own (``fpga-robotics mutate --design REF``): Yosys
mutants of the Amaranth design, each judged against the unmutated design on the same seeded
random pin stimulus (``pin_judge``), with the same scores as FollowTarget's unit judge."""

import os
import time

from amaranth.hdl import Fragment

from ..designs.builtin import connector_kinds
from ..designs.reference import stream_ports
from ..hw.verilog import verilog_ports
from ..sim.backends.foreign import ForeignDesign
from ..sim.backends.port_map import load_port_map
from ..sim.files import read_user_text, write_atomic, write_json_atomic
from ..sim.mutation import (
    MUTATION_SELECT,
    MutationError,
    component_rtlil,
    list_mutants,
    mutant_cones,
    mutant_netlist,
)
from ..sim.pins.base import Port
from ..sim.pins.compiled import VerilatorPins
from ..sim.pins.verilog import VerilogPinSource
from .design import (
    NETLIST_NAME,
    PORTS_NAME,
    WATCH_PORTS_NAME,
    design_mutant_port_map,
    netlist_has_reset,
    with_mutant_select,
)
from .pin_judge import (
    STREAM_PORTS,
    MutantPinSource,
    judge_pin_mutant,
    open_pin_mutants,
    pin_stimulus,
    pin_trace,
    streams_frames,
)
from .reasons import pin_blind_spot_reason
from .robot_judge import (
    check_resume,
    clear_earlier_run,
    mutants_key,
    robot_judge,
    start_prebuild,
)
from .scores import blind_spots, by_module, robot_score, unit_score

__all__ = [
    "DEFAULT_CYCLES",
    "DEFAULT_FRAME",
    "design_ports",
    "mutate_design",
    "mutate_verilog_design",
]

#: Cycles of random stimulus per mutant by default (five 20 ms ultrasound periods at 1 MHz).
DEFAULT_CYCLES = 100_000
#: The frames a camera design's unit judge streams by default (width, height): the camera's.
DEFAULT_FRAME = (160, 120)


def design_ports(spec):
    """The ports of the design ``spec`` (a ``DesignSpec``) as pin ``Port``s, named as the
    generated Verilog names them."""
    component = spec.build()
    Fragment.get(component, None)  # read for its signature only: elaborated, so no warning
    return {
        name: Port(name, value.shape().width, "in" if d == "i" else "out", value.shape().signed)
        for name, (value, d) in verilog_ports(component).items()
    }


def mutate_design(
    spec,
    n,
    seed,
    cycles,
    out,
    *,
    stimulus_seed=0,
    say=print,
    campaign=None,
    robot=None,
    frame=DEFAULT_FRAME,
):
    """Mutants of ``spec`` (a resolved Amaranth ``DesignSpec``) judged on ``cycles`` cycles;
    writes ``out/mutants.json`` (and the mutant netlist with its port map, for the robot
    judge) and returns its content. With ``campaign`` the mutants the unit judge catches go
    on to the robot judge (``robot_judge.robot_judge`` with the keyword arguments ``robot``:
    workers, scheduler, resume, fork): the campaign's runs in closed loop, each with the
    mutant netlist as its Verilog design. ``frame``: (width, height) of the frames a camera
    design's pixel stream carries in the unit judge (pin_judge)."""
    t0 = time.perf_counter()
    ports = design_ports(spec)
    rtlil_text = component_rtlil(spec.build())
    mutants = list_mutants(None, n, seed, rtlil_text=rtlil_text)
    robot = _keyed(robot, out, mutants_key(rtlil_text, mutants), campaign)
    name = spec.reference.rpartition(":")[2] or spec.reference
    source = MutantPinSource(rtlil_text, ports, mutants, name)
    # The netlist and its port map as a Verilog design the closed loop runs (the robot
    # judge: one build, ``--runtime mutsel=K`` picks the mutant).
    clear_earlier_run(out, robot.get("resume"))
    netlist = os.path.join(out, NETLIST_NAME)
    write_atomic(netlist, source.verilog, what="mutant netlist")
    port_map, watch_map = os.path.join(out, PORTS_NAME), os.path.join(out, WATCH_PORTS_NAME)
    reset = netlist_has_reset(source.verilog)
    for path, watch in ((port_map, False), (watch_map, True)):
        text = design_mutant_port_map(spec, ports, reset=reset, watch=watch)
        write_atomic(path, text, what="port map")
    mapped = load_port_map(port_map)  # read before the build: a map it refuses stops here
    prebuilt = _prebuild(campaign, robot, netlist, watch_map)
    backend = open_pin_mutants(source, on_build=lambda t: say(f"{t} ..."))
    build_s = time.perf_counter() - t0
    return _judge(
        {"reference": spec.reference, "params": spec.params},
        backend,
        ports,
        mutants,
        (netlist, port_map, watch_map),
        mapped,
        build_s,
        seed,
        cycles,
        out,
        stimulus_seed=stimulus_seed,
        frame=frame,
        say=say,
        campaign=campaign,
        robot=robot,
        prebuilt=prebuilt,
        cones_of=lambda some: mutant_cones(None, some, rtlil_text=rtlil_text),
        stream=stream_ports(spec.bindings),
    )


def mutate_verilog_design(
    files,
    ports_path,
    n,
    seed,
    cycles,
    out,
    *,
    stimulus_seed=0,
    say=print,
    campaign=None,
    robot=None,
    frame=DEFAULT_FRAME,
    overrides=None,
):
    """``mutate_design`` for a Verilog design: ``files`` with its port map ``ports_path``,
    built with ``overrides`` (``VerilogOverrides``: its parameters and `define macros).
    Yosys reads the files (``read_verilog``) and mutates the map's top module; the mutant
    netlist's port map is the design's with ``mutsel`` a ``[runtime]`` input, and the unit
    judge drives every input the map gives the pin backend (its connector pins, the pixel
    stream's and colour select's ports; ``[runtime]`` inputs aside)."""

    t0 = time.perf_counter()
    # The frames' size: a framebuffer design's address and new-frame pulse are made for it.
    kinds, frame_size = connector_kinds(), tuple(frame)
    design = ForeignDesign(
        files,
        ports_path,
        pins=True,
        connector_kinds=kinds,
        frame_size=frame_size,
        overrides=overrides,
    )
    top = design.port_map.top
    sources = {
        "verilog": design.sources,
        "top": top,
        "includes": design.includes,
        "overrides": design.overrides,
    }
    mutants = list_mutants(None, n, seed, **sources)
    robot = _keyed(robot, out, mutants_key(design.digest(), mutants), campaign)
    verilog = mutant_netlist(None, mutants, **sources)
    os.makedirs(out, exist_ok=True)
    clear_earlier_run(out, robot.get("resume"))
    netlist = os.path.join(out, NETLIST_NAME)
    write_atomic(netlist, verilog, what="mutant netlist")
    port_map, watch_map = os.path.join(out, PORTS_NAME), os.path.join(out, WATCH_PORTS_NAME)
    text = read_user_text(ports_path)  # already checked by ForeignDesign
    write_atomic(port_map, with_mutant_select(text), what="port map")
    watched = with_mutant_select(text, watch=True)
    if watched is None:  # the map watches an output of its own: no mutant watch
        watch_map = None
    else:
        write_atomic(watch_map, watched, what="port map")
    prebuilt = _prebuild(campaign, robot, netlist, watch_map)
    # The pixel ports driven as any input, each edge at random (as an Amaranth design's).
    # A mutant may loop through its own select multiplexers; the design was checked above.
    mutant_design = ForeignDesign(
        [netlist],
        port_map,
        pins=True,
        connector_kinds=kinds,
        frame_size=frame_size,
        refuse_loops=False,
    )
    source = VerilogPinSource(mutant_design, stream=False)
    backend = VerilatorPins(source, on_build=lambda t: say(f"{t} ..."))
    build_s = time.perf_counter() - t0
    driven = {p: port for p, port in backend.ports.items() if p not in source.runtime}
    driven[MUTATION_SELECT] = backend.ports[MUTATION_SELECT]
    return _judge(
        {"reference": "verilog:" + ",".join(str(f) for f in files), "ports": str(ports_path)},
        backend,
        driven,
        mutants,
        (netlist, port_map, watch_map),
        mutant_design.port_map,
        build_s,
        seed,
        cycles,
        out,
        stimulus_seed=stimulus_seed,
        frame=frame,
        say=say,
        campaign=campaign,
        robot=robot,
        prebuilt=prebuilt,
        cones_of=lambda some: mutant_cones(None, some, **sources),
    )


def _prebuild(campaign, robot, netlist, watch_map):
    """With a forked robot judge, the references' model (the netlist with its watch, a model
    of its own) building in a thread beside the unit judge's (``start_prebuild``)."""
    if campaign is None or not (robot or {}).get("fork", True) or not watch_map:
        return None
    return start_prebuild(campaign, os.path.abspath(netlist), os.path.abspath(watch_map), None)


def _keyed(robot, out, key, campaign):
    """The robot judge's keyword arguments with the mutants' key; with ``resume``, checked
    with ``campaign`` against the journal in ``out`` first (``check_resume``: before
    anything is written)."""
    robot = dict(robot or {})
    if robot.get("resume"):
        check_resume(out, key, campaign)
    return {**robot, "mutants": key}


def _judge(
    design,
    backend,
    ports,
    mutants,
    files,
    mapped,
    build_s,
    seed,
    cycles,
    out,
    *,
    stimulus_seed,
    frame,
    say,
    campaign,
    robot,
    prebuilt,
    cones_of,
    stream=STREAM_PORTS,
):
    """The unit judge of ``mutants`` on ``backend`` (closed here), then the robot judge with
    ``campaign`` (forked: first the fan-out cones of the caught mutants, ``cones_of``);
    writes and returns ``mutants.json``'s content. ``files``: the paths of the netlist and
    its port maps; ``mapped``: the first, parsed (``PortMap``)."""
    netlist, port_map, watch_map = files
    outputs = [p for p, port in ports.items() if port.direction == "out"]
    framed = streams_frames(ports, stream)
    stimulus = pin_stimulus(ports, cycles, stimulus_seed, frame if framed else None, stream)
    try:
        t1 = time.perf_counter()
        reference = pin_trace(backend, 0, stimulus, cycles, outputs)
        verdicts = []
        for k, m in enumerate(mutants, start=1):
            verdicts.append(judge_pin_mutant(backend, m.index, stimulus, cycles, reference, ports))
            if k == len(mutants) or k * 10 // len(mutants) != (k - 1) * 10 // len(mutants):
                say(
                    f"unit judge: {k}/{len(mutants)} mutants, "
                    f"{sum(v.caught for v in verdicts)} caught"
                )
        unit_s = time.perf_counter() - t1
    finally:
        backend.close()
    unit = {v.index: v.caught for v in verdicts}
    robot_verdicts, baseline, robot_s, cones, cone_s = {}, None, None, None, None
    if campaign is not None:
        caught = [v.index for v in verdicts if v.caught]
        if (robot or {}).get("fork", True):  # --no-fork: every run in full
            t3 = time.perf_counter()
            try:
                cones = cones_of([m for m in mutants if m.index in caught])
            except MutationError as exc:  # no verdict without a run then: all run
                say(f"fan-out cones: {str(exc).splitlines()[0]}; every mutant runs")
            cone_s = time.perf_counter() - t3
        t2 = time.perf_counter()
        baseline, robot_verdicts = robot_judge(
            campaign,
            os.path.abspath(netlist),
            os.path.abspath(port_map),
            None,
            caught,
            out,
            say=say,
            cones=cones,
            watch_ports=watch_map and os.path.abspath(watch_map),
            prebuilt=prebuilt,
            **(robot or {}),
        )
        robot_s = time.perf_counter() - t2
    caught_by_robot = {k: v["caught"] for k, v in robot_verdicts.items()}
    blind = set(blind_spots(unit, caught_by_robot))
    filtered, recorded = mapped.filtered_payload, set(mapped.extra_outputs.values())
    result = {
        "design": design,
        "seed": seed,
        "judge": "the unmutated design, seeded random pin stimulus",
        "stimulus": {
            "cycles": cycles,
            "seed": stimulus_seed,
            "inputs": [
                p for p, port in ports.items() if port.direction == "in" and p != MUTATION_SELECT
            ],
            # The pixel stream's frames (width, height), for a camera design.
            "frame": list(frame) if framed else None,
            # Whether any output of the unmutated design changed: if none did, only a mutant
            # that changes a constant output can be caught (a stimulus the design ignored).
            "outputs_changed": any(len(changes) > 1 for changes in reference.values()),
        },
        "build_and_list_s": round(build_s, 2),
        "unit_judge_s": round(unit_s, 2),
        # From the unrounded time: a fast unit judge takes well under 0.01 s.
        "unit_mutants_per_minute": round(60 * len(mutants) / max(unit_s, 1e-9), 1),
        "netlist": NETLIST_NAME,
        "ports": PORTS_NAME,
        "unit": unit_score(unit),
        "robot": robot_score(unit, caught_by_robot) if campaign is not None else None,
        "campaign": campaign.name if campaign is not None else None,
        "robot_judge_s": round(robot_s, 2) if robot_s is not None else None,
        "cone_s": round(cone_s, 2) if cone_s is not None else None,
        "baseline": baseline,
        "modules": by_module(mutants, unit, caught_by_robot),
        "mutants": [
            {
                **{k: v for k, v in m.__dict__.items()},
                "sources": list(m.sources),
                "describe": m.describe(),
                "unit": {
                    "caught": v.caught,
                    "first_cycle": v.first_cycle,
                    "differing": v.differing,
                    # output -> [cycles during which it differs, largest difference]
                    "extent": {name: list(e) for name, e in v.extent.items()},
                    "cycles_differing": v.cycles_differing,
                    "effect": v.effect(),
                },
                "robot": robot_verdicts.get(m.index),
                "blind_spot_reason": (
                    pin_blind_spot_reason(v, filtered, recorded) if m.index in blind else None
                ),
            }
            for m, v in zip(mutants, verdicts)
        ],
    }
    write_json_atomic(os.path.join(out, "mutants.json"), result, what="mutation results")
    return result
