"""Scenarios as data: the shipped files (``shipped/``), loading, ``--set`` overrides and
validation (``load.py``), the connector tables (``connectors.py``) and the renderer's keys
(``render3d_keys.py``)."""

from fpga_robotics.scenario.load import (
    DEFAULTS,
    ScenarioError,
    load_scenario,
    shipped_scenarios,
)

__all__ = ["DEFAULTS", "ScenarioError", "load_scenario", "shipped_scenarios"]
