"""The argument parser every subcommand uses: its defaults in ``--help``, and a bad argument
as one line ``fpga-robotics COMMAND: error: ...`` with exit code 2 (argparse's own prints the
whole usage block first)."""

import argparse

from fpga_robotics.cli.errors import USAGE_EXIT

__all__ = ["CommandParser", "DefaultsFormatter", "OnceParserMixin", "StoreOnce"]


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


class StoreOnce(argparse._StoreAction):
    """argparse's ``store``, but an option given a second, different value is a usage error
    (argparse keeps the last one silently: ``--duration 5 ... --duration 50`` ran 50 s).
    The same value twice is harmless and taken. Needs a parser that ``track_once``s."""

    def __call__(self, parser, namespace, values, option_string=None):
        seen = getattr(parser, "_stored_once", None)
        if seen is not None:
            if self.dest in seen and seen[self.dest][1] != values:
                first, value = seen[self.dest]
                parser.error(
                    f"{option_string} is given twice ({first} {value}, then {option_string} "
                    f"{values}); give it once"
                )
            seen[self.dest] = (option_string, values)
        super().__call__(parser, namespace, values, option_string)


class OnceParserMixin:
    """Makes every ``store`` option of an ``ArgumentParser`` a ``StoreOnce``."""

    def track_once(self):
        self.register("action", None, StoreOnce)
        self.register("action", "store", StoreOnce)

    def parse_known_args(self, args=None, namespace=None):
        self._stored_once = {}  # option dest -> (option string, value), for this parse
        try:
            return super().parse_known_args(args, namespace)
        finally:
            self._stored_once = None


class CommandParser(OnceParserMixin, argparse.ArgumentParser):
    """``argparse.ArgumentParser`` with ``DefaultsFormatter``, one-line errors and each
    option given once (``StoreOnce``)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        super().__init__(*args, **kwargs)
        self.track_once()

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
