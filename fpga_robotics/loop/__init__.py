"""The closed loop: the design, its connectors and the world stepped together.

``timings.py`` runs a scenario in the timing it asks for: ``compressed.py`` runs a camera
frame's pixels back to back (the default for FollowTarget), ``real_clock.py`` every design
cycle at its instant of world time; ``connectors/`` are what the design's pins see of the
world and do to it, ``bindings.py`` checks what the scenario's connectors bind to before a
design is built; ``shadow.py`` runs a second design on the same frames; ``checkpoint.py`` saves and restores a loop's world at a frame boundary,
``fork.py`` (frames) and ``pin_fork.py`` (real clock, with ``pin_journal.py``: a pin design's
calls, replayed) run design variants from a reference run's recordings and checkpoints
(``reference_data.py``: a frame-level reference in a picklable form, for another process),
``continuation.py`` lets a shadow design drive from where it parts (``run --shadow-continue``);
``sources.py`` feeds frames from outside the simulation.
"""

__all__ = [
    "TRAJECTORY_FIELDS",
    "ClosedLoop",
    "RunResult",
    "frame_count",
    "make_backend",
    "run_scenario",
]

#: The names are handed out on first use (PEP 562): importing a module of this package (a
#: connector, say) does not import the whole loop, which imports the designs that import
#: the connectors.


def __getattr__(name):
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from fpga_robotics.loop import compressed, timings  # lazy: a name of the package, on use

    return getattr(timings if name == "run_scenario" else compressed, name)
