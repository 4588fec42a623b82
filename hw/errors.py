"""The one base of every error the user can fix.

The application (``fpga_robotics.cli``) reports a ``UserError`` as one line
``fpga-robotics COMMAND: error: message`` and exit code 2; any other exception is a bug and
keeps its traceback. It lives in the lowest layer so that the gateware, the simulation and the
viewer can all raise it without importing the application.
"""

__all__ = ["USER_CODE_ERRORS", "ParamError", "UsageError", "UserError"]


class UserError(Exception):
    """Something the user can fix; the message says what is wrong and how to fix it."""


class ParamError(UserError, ValueError):
    """A design parameter out of its range, or an unknown preset, variant or choice (still a
    ``ValueError``, as callers that check values catch)."""


class UsageError(UserError):
    """A bad argument or input the user gave (a command-line option, a scenario or campaign
    value, a design reference): the message says what is wrong and how to fix it."""


#: What a user's design code (its module, constructor, ``elaborate``, formal hooks) may raise
#: and a command reports as an error of that design: ``sys.exit()`` too (argparse at import,
#: say), which would otherwise end the command with its code, 0 included, and nothing said.
USER_CODE_ERRORS = (Exception, SystemExit)
