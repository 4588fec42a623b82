"""A campaign's scenario warnings (``fpga_robotics.scenario.sanity``), before any run starts:
each scenario is loaded once per distinct set of overrides the campaign gives it."""

from argparse import Namespace
from dataclasses import replace

from fpga_robotics.cli import run
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.scenario.sanity import report_warnings

__all__ = ["report_campaign_warnings"]


def report_campaign_warnings(campaign, strict, stream, error):
    """Print the warnings of every scenario the campaign runs (each line once); with
    ``strict`` raise ``error`` with the first instead."""
    seen = set()
    for spec in campaign.runs:
        key = (spec.scenario, spec.resolution, spec.duration, tuple(spec.set_items()))
        if key in seen:
            continue
        seen.add(key)
        # The run's own overrides, as ``run`` makes them of its options.
        args = Namespace(
            overrides=list(spec.set_items()),
            resolution=spec.resolution,
            duration=spec.duration,
            color=None,
            design=None,
            ports=None,
        )
        try:
            scenario = load_scenario(spec.scenario, run._overrides(args))
        except UsageError:  # the run reports it as its own failure
            continue
        fresh = tuple(w for w in scenario.warnings if (scenario.name, w) not in seen)
        seen.update((scenario.name, w) for w in fresh)
        if fresh:
            report_warnings(_with_warnings(scenario, fresh), strict, stream, error)


def _with_warnings(scenario, warnings):
    return replace(scenario, warnings=warnings)
