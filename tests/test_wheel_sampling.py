"""Real-clock timing samples the wheel pins once a physics step, at the last edge whose change
acts at that step (fpga_robotics.loop.connectors.motors): the commands of a design whose
wheel pins change at every edge are the values at those edges, found here by brute force,
and its run costs a few design stops a step, not one an edge."""

import math
from pathlib import Path

import numpy as np
import pytest
from pin_proxy import PinProxy

from fpga_robotics.loop.connectors.motors import MotorConnector
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

TOGGLER = Path(__file__).parent / "data" / "user_designs" / "toggler.toml"


class _Clock:
    """What the motor connector asks of its pins' ``PinIO``: edge times."""

    def __init__(self, clock_hz):
        self.clock_hz = clock_hz

    def time_of(self, edge):
        return edge / self.clock_hz


def _brute_last_edge(motors, io, step, horizon):
    """The last edge (of the first ``horizon``) whose change acts at or before ``step``."""
    edges = [c for c in range(horizon) if motors.step_of(io, c) <= step]
    return edges[-1] if edges else -1


@pytest.mark.parametrize(
    "clock_hz, dt, delay",
    [
        (1e5, 1e-3, 0.02),  # 100 edges a step, a delay of whole steps
        (1e5, 1e-3, 0.0),
        (33333.0, 1e-3, 0.0123),  # edges that fall between steps
        (700.0, 1e-3, 0.005),  # fewer edges than steps: most steps have none
        (50e6 / 4096, 1 / 240, 1 / 30),
    ],
)
def test_the_sample_edges_are_the_last_edge_acting_at_each_step(clock_hz, dt, delay):
    motors = MotorConnector(world=None)
    motors.configure_real_clock(dt, delay)
    io = _Clock(clock_hz)
    horizon = int(clock_hz * (40 * dt + delay)) + 50
    expected = sorted(
        {_brute_last_edge(motors, io, s, horizon) for s in range(40)} - {-1},
    )
    got, edge = [], 0
    while True:
        edge = motors.sample_edge_after(io, edge)
        if edge > expected[-1]:
            break
        got.append(edge)
    # The edge out of reset (0) is sampled by the loop before it runs any.
    assert got == [e for e in expected if e > 0]


class _CountingPins(PinProxy):
    """A pin backend that counts the loop's ``run`` calls (its stops)."""

    def __init__(self, inner):
        super().__init__(inner)
        self.runs = 0

    def run(self, cycles):
        self.runs += 1
        return self.inner.run(cycles)


def _run(scenario):
    with make_pin_backend("cxxrtl", scenario) as design:
        pins = _CountingPins(design)
        return run_scenario(scenario, backend=pins), pins.runs


def test_wheels_that_change_every_edge_get_the_value_at_each_steps_last_edge():
    toggler = load_scenario(str(TOGGLER))
    result, stops = _run(toggler)
    sim = toggler.sim
    steps = round(sim.duration / sim.physics_dt)
    edges = round(sim.duration * sim.clock_hz)
    # 100 edges a step and a delay of 2000 edges: every step's last edge is even, where the
    # design drives ``low`` (its ``odd`` register is 0 out of reset, flips at every edge).
    assert (sim.clock_hz * sim.physics_dt, sim.clock_hz * sim.actuation_delay) == (100, 2000)
    steady = load_scenario(str(TOGGLER), ["design.params.high=200"])  # low = 200 always
    expected, _ = _run(steady)
    for name in ("x", "y", "heading"):
        assert np.array_equal(result.trajectory[name], expected.trajectory[name]), name
    # It moved: 200 DPS on a GoPiGo3's 66.5 mm wheels, straight on, from the delay on.
    travelled = result.trajectory["x"][-1] - result.trajectory["x"][0]
    assert travelled == pytest.approx(
        math.radians(200) * 0.0665 / 2 * (sim.duration - sim.actuation_delay), rel=0.1
    )
    # A stop per step (and per frame), not one per edge.
    assert stops < 3 * steps < edges / 10
