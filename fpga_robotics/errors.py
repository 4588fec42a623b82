"""User-facing errors and the CLI wrapper that turns them into a message and an exit code."""

import sys

__all__ = ["UsageError", "run_cli"]

#: Exit code for a bad argument, a malformed input file or a missing tool.
USAGE_EXIT = 2


class UsageError(Exception):
    """Something the user can fix: the message says what is wrong and how to fix it."""


def run_cli(main, argv=None, prog=None):
    """Call ``main(argv)``; print a ``UsageError``, a ``FrameError`` or a missing file as one
    line and exit 2, without a traceback. CLIs convert parameter ``ValueError``s into
    ``UsageError`` themselves, so that a bug elsewhere still shows its traceback."""
    from .sim.frames import FrameError

    name = prog or "fpga_robotics"
    try:
        code = main(argv)
    except (UsageError, FrameError, FileNotFoundError) as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        sys.exit(USAGE_EXIT)
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        sys.exit(130)
    sys.exit(code or 0)
