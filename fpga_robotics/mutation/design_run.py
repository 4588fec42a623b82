"""Mutation coverage of a design of one's own (``fpga-robotics mutate --design REF``): Yosys
mutants of the Amaranth design, each judged against the unmutated design on the same seeded
random pin stimulus (``pin_judge``), with the same scores as FollowTarget's unit judge."""

import os
import time

from amaranth.hdl import Fragment

from ..hw.verilog import verilog_ports
from ..sim.files import write_json_atomic
from ..sim.mutation import component_rtlil, list_mutants
from ..sim.pins.base import Port
from .pin_judge import MutantPinSource, judge_pin_mutant, open_pin_mutants, pin_stimulus, pin_trace
from .scores import by_module, unit_score

__all__ = ["DEFAULT_CYCLES", "design_ports", "mutate_design"]

#: Cycles of random stimulus per mutant by default (five 20 ms ultrasound periods at 1 MHz).
DEFAULT_CYCLES = 100_000


def design_ports(spec):
    """The ports of the design ``spec`` (a ``DesignSpec``) as pin ``Port``s, named as the
    generated Verilog names them."""
    component = spec.build()
    Fragment.get(component, None)  # read for its signature only: elaborated, so no warning
    return {
        name: Port(name, value.shape().width, "in" if d == "i" else "out", value.shape().signed)
        for name, (value, d) in verilog_ports(component).items()
    }


def mutate_design(spec, n, seed, cycles, out, *, stimulus_seed=0, say=print):
    """Mutants of ``spec`` (a resolved Amaranth ``DesignSpec``) judged on ``cycles`` cycles;
    writes ``out/mutants.json`` and returns its content."""
    t0 = time.perf_counter()
    ports = design_ports(spec)
    rtlil_text = component_rtlil(spec.build())
    mutants = list_mutants(None, n, seed, rtlil_text=rtlil_text)
    name = spec.reference.rpartition(":")[2] or spec.reference
    source = MutantPinSource(rtlil_text, ports, mutants, name)
    backend = open_pin_mutants(source, on_build=lambda t: say(f"{t} ..."))
    build_s = time.perf_counter() - t0
    outputs = [p for p, port in ports.items() if port.direction == "out"]
    stimulus = pin_stimulus(ports, cycles, stimulus_seed)
    try:
        t1 = time.perf_counter()
        reference = pin_trace(backend, 0, stimulus, cycles, outputs)
        verdicts = []
        for k, m in enumerate(mutants, start=1):
            verdicts.append(judge_pin_mutant(backend, m.index, stimulus, cycles, reference))
            if k == len(mutants) or k * 10 // len(mutants) != (k - 1) * 10 // len(mutants):
                say(
                    f"unit judge: {k}/{len(mutants)} mutants, "
                    f"{sum(v.caught for v in verdicts)} caught"
                )
        unit_s = time.perf_counter() - t1
    finally:
        backend.close()
    unit = {v.index: v.caught for v in verdicts}
    result = {
        "design": {"reference": spec.reference, "params": spec.params},
        "seed": seed,
        "judge": "the unmutated design, seeded random pin stimulus",
        "stimulus": {
            "cycles": cycles,
            "seed": stimulus_seed,
            "inputs": [p for p, port in ports.items() if port.direction == "in"],
        },
        "build_and_list_s": round(build_s, 2),
        "unit_judge_s": round(unit_s, 2),
        "unit": unit_score(unit),
        "modules": by_module(mutants, unit),
        "mutants": [
            {
                **{k: v for k, v in m.__dict__.items()},
                "sources": list(m.sources),
                "describe": m.describe(),
                "unit": {
                    "caught": v.caught,
                    "first_cycle": v.first_cycle,
                    "differing": v.differing,
                    "effect": v.effect(),
                },
            }
            for m, v in zip(mutants, verdicts)
        ],
    }
    write_json_atomic(os.path.join(out, "mutants.json"), result, what="mutation results")
    return result
