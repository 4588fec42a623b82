"""The error of a scenario that cannot be loaded (its own module, so that every part of the
scenario reader can raise it)."""

from fpga_robotics.hw.errors import UsageError

__all__ = ["ScenarioError"]


class ScenarioError(UsageError):
    """A scenario that cannot be loaded: unknown name, malformed file, bad value or key."""
