"""The argument parser every subcommand uses: its defaults in ``--help``, and a bad argument
as one line ``fpga-robotics COMMAND: error: ...`` with exit code 2 (argparse's own prints the
whole usage block first)."""

import argparse

from fpga_robotics.cli.errors import USAGE_EXIT

__all__ = ["CommandParser", "DefaultsFormatter"]


class DefaultsFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Appends ``(default: X)`` to an option's help when there is a default worth showing:
    not for flags, options without a default, or help that already names its default."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (
            action.default in (None, False, [], argparse.SUPPRESS)
            or "default" in text
            or not action.option_strings
        ):
            return text
        return super()._get_help_string(action)


class CommandParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` with ``DefaultsFormatter`` and one-line errors."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        super().__init__(*args, **kwargs)

    def given_options(self, args, ignore=()):
        """The options ``args`` gives other than their defaults (as ``--name``), but those
        whose ``dest`` is in ``ignore``."""
        return [
            action.option_strings[0]
            for action in self._actions
            if action.option_strings
            and action.dest not in ignore
            and getattr(args, action.dest, action.default) != action.default
        ]

    def error(self, message):
        self.exit(USAGE_EXIT, f"{self.prog}: error: {message}\n")
