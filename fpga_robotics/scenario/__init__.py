"""Scenarios as data: the shipped files (``shipped/``), loading, ``--set`` overrides and
validation (``load.py``), the keys of every section (``schema.py``) and the connector tables
(``connectors.py``)."""

from fpga_robotics.scenario.load import (
    DEFAULTS,
    ScenarioError,
    load_scenario,
    shipped_scenarios,
)

__all__ = ["DEFAULTS", "ScenarioError", "load_scenario", "shipped_scenarios"]
