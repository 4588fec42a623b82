"""Verification campaigns: many closed-loop runs on Dask, one results table, one report.

``python -m fpga_robotics.sweep CAMPAIGN.toml`` (docs/campaigns.md), or from Python::

    from fpga_robotics.sweep import load_campaign_file, run_campaign
    rows = run_campaign(load_campaign_file("regression"), "runs/sweeps/regression")
"""

from .api import report_dir, run_campaign
from .campaign import Campaign, CampaignError, RunSpec, load_campaign, read_campaign_file

__all__ = [
    "Campaign",
    "CampaignError",
    "RunSpec",
    "load_campaign",
    "load_campaign_file",
    "read_campaign_file",
    "report_dir",
    "run_campaign",
]


def load_campaign_file(name_or_path):
    """The ``Campaign`` of a shipped campaign name or a campaign file."""
    data, path = read_campaign_file(name_or_path)
    return load_campaign(data, source=str(path))
