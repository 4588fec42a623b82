"""User-facing errors and the CLI wrapper that turns them into a message and an exit code.

Library code (``hw``, ``sim``, ``viz``) raises exceptions derived from
``fpga_robotics.hw.errors.UserError`` for what the user can fix; only here, in the
application layer, do they become one line on stderr and exit code 2. A bug anywhere else
still shows its traceback.
"""

import os
import signal
import sys

from fpga_robotics.hw.errors import UsageError, UserError

__all__ = ["USAGE_EXIT", "Terminated", "UsageError", "UserError", "run_cli"]

#: Exit code for a bad argument, a malformed input file or a missing tool.
USAGE_EXIT = 2


class Terminated(KeyboardInterrupt):
    """SIGTERM (what ``timeout``, CI runners and process managers send), raised like Ctrl-C so
    that every ``finally:`` runs: recordings are closed under their names, temporary files
    removed, child compilers ended."""


def _raise_terminated(signum, frame):
    raise Terminated()


def run_cli(main, argv=None, prog=None):
    """Call ``main(argv)`` and exit with its code; a user error (``UserError``, or a missing
    input file) is one line ``prog: error: message`` and exit 2, without a traceback. Ctrl-C
    exits 130 and SIGTERM 143, after the ``finally:`` blocks of ``main`` have run."""
    name = prog or "fpga-robotics"
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse's --help and usage errors, a main's own exit
            code = exc.code
        # Flushed here, not at exit: a reader gone by then would get Python's "Exception
        # ignored ... BrokenPipeError" and exit 120 instead of the quiet stop below.
        sys.stdout.flush()
    except KeyboardInterrupt as exc:
        print(
            f"{name}: {'terminated' if isinstance(exc, Terminated) else 'interrupted'}",
            file=sys.stderr,
        )
        sys.exit(128 + (signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT))
    except (UserError, FileNotFoundError) as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        sys.exit(USAGE_EXIT)
    except BrokenPipeError:
        # The reader went away (`| head`): stop quietly, as Unix tools do, and keep Python's
        # flush at exit from failing again on the closed pipe.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(128 + signal.SIGPIPE)
    finally:
        signal.signal(signal.SIGTERM, previous)
    sys.exit(code or 0)
