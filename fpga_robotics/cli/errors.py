"""User-facing errors and the CLI wrapper that turns them into a message and an exit code.

Library code (``hw``, ``sim``, ``viz``) raises its own exceptions; only here, in the
application layer, do they become one line on stderr and exit code 2. A bug anywhere else
still shows its traceback.
"""

import importlib
import signal
import sys

__all__ = ["USAGE_EXIT", "Terminated", "UsageError", "run_cli", "user_error_types"]

#: Exit code for a bad argument, a malformed input file or a missing tool.
USAGE_EXIT = 2

#: Library exceptions that mean "the user can fix this": (module, class name). Looked up
#: lazily so that a CLI does not import the viewer or the world just to report an error.
_LIBRARY_ERRORS = (
    ("fpga_robotics.sim.camera.frames", "FrameError"),
    ("fpga_robotics.sim.files", "OutputPathError"),
    ("fpga_robotics.sim.world.config", "WorldConfigError"),
    ("fpga_robotics.viz.errors", "ViewerError"),
)


class UsageError(Exception):
    """Something the user can fix: the message says what is wrong and how to fix it."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (what ``timeout``, CI runners and process managers send), raised like Ctrl-C so
    that every ``finally:`` runs: recordings are closed under their names, temporary files
    removed, child compilers ended."""


def user_error_types():
    """The exception classes that ``run_cli`` reports as one line with exit code 2."""
    types = [UsageError, FileNotFoundError]
    for module_name, class_name in _LIBRARY_ERRORS:
        module = sys.modules.get(module_name)
        if module is None:
            try:
                module = importlib.import_module(module_name)
            except ImportError:
                continue
        cls = getattr(module, class_name, None)
        if cls is not None:
            types.append(cls)
    return tuple(types)


def _raise_terminated(signum, frame):
    raise Terminated()


def run_cli(main, argv=None, prog=None):
    """Call ``main(argv)`` and exit with its code; a user error (``user_error_types``) is one
    line ``prog: error: message`` and exit 2, without a traceback. Ctrl-C exits 130 and
    SIGTERM 143, after the ``finally:`` blocks of ``main`` have run."""
    name = prog or "fpga_robotics"
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        code = main(argv)
    except KeyboardInterrupt as exc:
        print(f"{name}: {'terminated' if isinstance(exc, Terminated) else 'interrupted'}",
              file=sys.stderr)
        sys.exit(128 + (signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT))
    except Exception as exc:
        if not isinstance(exc, user_error_types()):
            raise
        print(f"{name}: error: {exc}", file=sys.stderr)
        sys.exit(USAGE_EXIT)
    finally:
        signal.signal(signal.SIGTERM, previous)
    sys.exit(code or 0)

