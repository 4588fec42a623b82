"""``fpga-robotics``: one command, with a subcommand for each job.

    fpga-robotics run [options]           closed loop (python -m fpga_robotics.run)
    fpga-robotics export [options]        Verilog of the design (python -m fpga_robotics.export)
    fpga-robotics board [options]         board top, LPF and bitstream
    fpga-robotics ports PORTS.toml        check (or --example: write) a port map
    fpga-robotics bench [WHAT] [options]  benchmarks: design (default), pysim, camera, world,
                                          viewer, shadow
    fpga-robotics designs [REF]           the designs a run can name, ports and connectors
    fpga-robotics mutate [options]        mutation coverage (python -m fpga_robotics.mutation)
    fpga-robotics readback FILE.rrd       what a saved recording holds
    fpga-robotics sweep CAMPAIGN [options]  a verification campaign on Dask
    fpga-robotics sweep report DIR        the report of a finished campaign
    fpga-robotics formal [options]        formal proofs of the gateware's promises
    fpga-robotics new NAME                a project skeleton: design, scenario, test, README
    fpga-robotics --version               the installed version

Each subcommand is the ``main(argv, prog)`` of its module, and the ``python -m`` aliases call
``run_command``, so ``fpga-robotics run --help`` and ``python -m fpga_robotics.run --help`` are
the same command under the same name. New subcommands are one row of ``COMMANDS`` (or
``BENCHMARKS``).
"""

import gc
import importlib
import inspect
import sys

from fpga_robotics.cli.errors import USAGE_EXIT, run_cli

__all__ = ["BENCHMARKS", "COMMANDS", "main", "run_command", "version"]

#: Subcommand -> (module with ``main(argv, prog)``, one-line help).
COMMANDS = {
    "run": (
        "fpga_robotics.cli.run",
        "run a scenario in closed loop (or the design on real frames)",
    ),
    "export": ("fpga_robotics.cli.export", "write the design as one Verilog file"),
    "board": (
        "fpga_robotics.cli.board",
        "export a board top (Verilog + LPF) and build its bitstream",
    ),
    "bench": (None, "print speed figures (see `fpga-robotics bench --list`)"),
    "designs": (
        "fpga_robotics.cli.designs",
        "the designs a run can name: their ports and the connectors they bind",
    ),
    "ports": (
        "fpga_robotics.cli.ports",
        "write (--example) or check a port map for run --design verilog:...",
    ),
    "mutate": (
        "fpga_robotics.cli.mutate",
        "mutation coverage: Yosys mutants of the design against the golden model",
    ),
    "readback": (
        "fpga_robotics.cli.readback",
        "what a saved .rrd recording holds, entity by entity",
    ),
    "sweep": (
        "fpga_robotics.cli.sweep",
        "a verification campaign: many runs on Dask, results table and report",
    ),
    "formal": ("fpga_robotics.cli.formal", "prove the gateware's promises (SymbiYosys, Yices)"),
    "new": (
        "fpga_robotics.cli.new",
        "write a project skeleton: a design, a scenario and a test that runs it",
    ),
}

#: ``fpga-robotics bench WHAT`` -> (module, one-line help); the first is the default.
BENCHMARKS = {
    "design": ("fpga_robotics.bench.design", "every simulation backend, and the paired fraction"),
    "pysim": ("fpga_robotics.bench.pysim", "Amaranth's simulator, checked against the model"),
    "camera": ("fpga_robotics.bench.camera", "the camera renderer"),
    "world": ("fpga_robotics.bench.world", "the physics of the robot world"),
    "render3d": (
        "fpga_robotics.bench.render3d",
        "the raster and the 3D renderer, per frame and in the closed loop",
    ),
    "viewer": ("fpga_robotics.bench.viewer", "the cost of logging to the rerun viewer"),
    "shadow": ("fpga_robotics.bench.shadow", "a shadow design's cost in the closed loop"),
    "fork": (
        "fpga_robotics.bench.fork",
        "design variants forked from one reference run against run in full",
    ),
    "mutant_replay": (
        "fpga_robotics.bench.mutant_replay",
        "the most a forked mutant run can save: the mutant netlist's replay against a full run",
    ),
    "loop": ("fpga_robotics.bench.loop", "where the closed loop's time goes, per frame"),
    "foreign": (
        "fpga_robotics.bench.foreign",
        "a Verilog design through a port map against the built-in Verilator backend",
    ),
    "ros": ("fpga_robotics.bench.ros", "writing a ROS 2 bag and publishing live to Foxglove"),
    "pins": ("fpga_robotics.bench.pins", "the pin backends in real-clock time (Mcycles/s)"),
    "user_verilog": (
        "fpga_robotics.bench.user_verilog",
        "a user's Verilog design in real-clock timing on each backend (Mcycles/s)",
    ),
    "sweep": ("fpga_robotics.bench.sweep", "campaign throughput on 1 worker and on N"),
    "lidar": (
        "fpga_robotics.bench.lidar",
        "a LIDAR revolution against a camera frame; the UART binding's cycles per second",
    ),
    "cameras": ("fpga_robotics.bench.cameras", "the closed loop with two cameras against one"),
    "calibrate": (
        "fpga_robotics.bench.calibrate",
        "this machine's calibration frame time: divide a time by it to compare",
    ),
}

PROG = "fpga-robotics"


def _listing(usage, heading, table):
    """A usage line and an aligned ``name  help`` row per entry of ``table``."""
    width = max(map(len, table))
    rows = [f"  {name:<{width}}  {text}" for name, (_module, text) in table.items()]
    return "\n".join([usage, "", f"{heading}:", *rows])


def _usage():
    return _listing(
        f"usage: {PROG} COMMAND [options]   ({PROG} COMMAND --help for its options)"
        f"\n       {PROG} --version",
        "commands",
        COMMANDS,
    )


def _bench_list():
    return _listing(
        f"usage: {PROG} bench [WHAT] [options]   (WHAT defaults to design)",
        "benchmarks",
        BENCHMARKS,
    )


def version():
    """The installed package's version (``fpga-robotics --version``)."""
    from importlib.metadata import PackageNotFoundError  # lazy: ~40 ms at every start
    from importlib.metadata import version as package_version  # lazy: ~40 ms at every start

    try:
        return package_version("fpga-robotics")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "unknown (not installed)"


def run_command(command, argv=None):
    """Run subcommand ``command`` as ``fpga-robotics command`` does (the ``python -m``
    aliases): the same name in its usage and errors."""
    own_process = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    _call(COMMANDS[command][0], argv, f"{PROG} {command}", own_process)


def _import_main(module_name, own_process):
    """The ``main`` of a command's module. In a process of its own, the modules' objects live
    to its end: the collector is held while they are imported and then told to leave them
    alone (``gc.freeze``), instead of scanning them all again in every full collection."""
    if not own_process:
        return importlib.import_module(module_name).main
    gc.disable()
    try:
        return importlib.import_module(module_name).main
    finally:
        gc.freeze()
        gc.enable()


def _call(module_name, argv, prog, own_process=False):
    main = _import_main(module_name, own_process)
    if "prog" in inspect.signature(main).parameters:
        return run_cli(lambda a: main(a, prog=prog), argv, prog=prog)
    return run_cli(main, argv, prog=prog)


def _print_and_exit(text):
    """Print ``text`` and exit 0, through ``run_cli`` as every command's output goes: a reader
    that went away (``| head``) ends it quietly, not in a traceback."""
    run_cli(lambda _argv: print(text), prog=PROG)


def main(argv=None):
    own_process = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] in (["-h"], ["--help"]):
        _print_and_exit(_usage())
    if argv[:1] == ["--version"]:
        _print_and_exit(f"{PROG} {version()}")
    if not argv:
        print(_usage(), file=sys.stderr)
        print(f"{PROG}: error: a command is needed", file=sys.stderr)
        sys.exit(USAGE_EXIT)
    command, rest = argv[0], argv[1:]
    if command not in COMMANDS:
        print(
            f"{PROG}: error: unknown command {command!r}; choose one of: {', '.join(COMMANDS)}",
            file=sys.stderr,
        )
        sys.exit(USAGE_EXIT)
    if command == "bench":
        if rest[:1] in (["--list"], ["-h"], ["--help"]):
            hint = f"\n\n{PROG} bench WHAT --help gives a benchmark's options."
            _print_and_exit(_bench_list() + ("" if rest[0] == "--list" else hint))
        what = rest[0] if rest and not rest[0].startswith("-") else "design"
        if what not in BENCHMARKS:
            print(
                f"{PROG} bench: error: unknown benchmark {what!r}; choose one of: "
                f"{', '.join(BENCHMARKS)}",
                file=sys.stderr,
            )
            sys.exit(USAGE_EXIT)
        if rest and rest[0] == what:
            rest = rest[1:]
        _call(BENCHMARKS[what][0], rest, f"{PROG} bench {what}", own_process)
    _call(COMMANDS[command][0], rest, f"{PROG} {command}", own_process)


if __name__ == "__main__":
    main()
