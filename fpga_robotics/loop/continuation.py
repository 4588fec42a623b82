"""What the shadow design would have done (``run --shadow SPEC --shadow-continue``).

The run with a shadow (fpga_robotics.loop.shadow, pin_shadow) is recorded as a fork
reference (fpga_robotics.loop.fork, pin_fork): the primary drives, the shadow is compared in
lockstep. Then the shadow gets the run of its own: replayed on what the primary's run gave
its design until it would have driven differently, and from the world checkpoint before that
in closed loop, driving the robot itself. Its result is the shadow design's own full run in
that world (trajectory, events, checks and verdict), at the cost of the frames from the
divergence on.
"""

from dataclasses import dataclass

from fpga_robotics.loop.compressed import RunResult
from fpga_robotics.loop.pin_fork import reference_run

__all__ = ["Continued", "continuation_summary", "run_continued"]


@dataclass(eq=False)
class Continued:
    """The primary's run (with its shadow comparison) and the shadow's own.

    ``parted`` is the first frame the shadow drove differently (None if it never did: then
    its run is the primary's world with its own outputs)."""

    main: RunResult
    shadow: RunResult
    parted: int | None


def run_continued(
    scenario,
    *,
    design,
    shadow,
    shadow_scenario=None,
    seed=None,
    shadow_label="shadow",
    checkpoint_every=30,
    **run_args,
):
    """Run ``scenario`` on ``design`` with ``shadow`` compared in lockstep, then the shadow
    on its own from where it parts. ``shadow_scenario``: the shadow's (its design parameters
    or design), default ``scenario``; ``run_args`` are ``recorder``, ``on_frame`` and
    ``progress`` for the primary's run. Both designs are reset here, not closed."""
    reference = reference_run(
        scenario,
        design=design,
        seed=seed,
        checkpoint_every=checkpoint_every,
        shadow=shadow,
        shadow_label=shadow_label,
        **run_args,
    )
    result = reference.run_variant(shadow, shadow_scenario)
    return Continued(reference.result, result, reference.last_divergence)


def continuation_summary(continued):
    """JSON-ready, for the primary's summary (``shadow_continued``): where the shadow took
    over and its own summary."""
    return {"parted_at_frame": continued.parted, **continued.shadow.summary}
