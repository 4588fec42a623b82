"""``--interactive``: the live controls from the terminal, one key each (no Enter).

A reader thread puts the terminal in cbreak mode (keys arrive at once, Ctrl-C still
interrupts), turns keys into ``LiveControls`` inputs and restores the terminal on ``close``.
"""

import os
import select
import sys
import termios
import threading
import tty

from fpga_robotics.hw.errors import UsageError

from .controls import TELEOP_SPEED

__all__ = ["KEYS", "TerminalControls", "check_terminal", "key_input"]

_COLORS = {
    "r": "red",
    "g": "green",
    "b": "blue",
    "y": "yellow",
    "m": "magenta",
    "c": "cyan",
    "w": "white",
    "n": "none",
}
_MOVES = {
    "\x1b[A": (0.0, 1.0),
    "\x1b[B": (0.0, -1.0),
    "\x1b[C": (1.0, 0.0),
    "\x1b[D": (-1.0, 0.0),
    "i": (0.0, 1.0),
    "k": (0.0, -1.0),
    "l": (1.0, 0.0),
    "j": (-1.0, 0.0),
}

#: What each key does (docs/ros.md lists the same).
KEYS = {
    "r g b y m c w n": "colour select red, green, blue, yellow, magenta, cyan, white, none",
    "space or p": "pause / resume",
    "s": "one frame (while paused)",
    "arrows or i j k l": f"drive the target person at {TELEOP_SPEED} m/s (up = +y, "
    "right = +x on the map)",
    "x": "stop the target person",
    "h": "hand the target back to its script",
    "+ -": "pace twice as fast / half as fast",
    "q": "stop reading keys (the run goes on to its end)",
}


def key_input(key, controls):
    """The ``(kind, value)`` input of ``key`` (None for an unbound key); ``controls`` gives
    the current pause state and speed."""
    if key in _COLORS:
        return "color", _COLORS[key]
    if key in (" ", "p"):
        return ("resume" if controls.paused else "pause"), None
    if key == "s":
        return "step", None
    if key in _MOVES:
        dx, dy = _MOVES[key]
        return "target_velocity", [dx * TELEOP_SPEED, dy * TELEOP_SPEED]
    if key == "x":
        return "target_velocity", [0.0, 0.0]
    if key == "h":
        return "target_velocity", None
    if key in ("+", "-") and controls.speed is not None:
        return "speed", controls.speed * (2.0 if key == "+" else 0.5)
    return None


def check_terminal(stream=None):
    """``UsageError`` unless ``stream`` (standard input) is a terminal: checked before a run
    starts, not when its controls open."""
    stream = sys.stdin if stream is None else stream
    if not stream.isatty():
        raise UsageError(
            "--interactive needs a terminal on standard input "
            "(use --live foxglove or --replay-inputs otherwise)"
        )


class TerminalControls:
    """Reads keys from ``stream`` (a terminal) into ``controls`` until ``close()``."""

    def __init__(self, controls, stream=None):
        self.controls = controls
        stream = sys.stdin if stream is None else stream
        check_terminal(stream)
        self._fd = stream.fileno()
        self._saved = termios.tcgetattr(self._fd)
        tty.setcbreak(self._fd)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, name="interactive-keys", daemon=True)
        self._thread.start()

    def help_lines(self):
        return ["keys: " + "; ".join(f"{k}: {what}" for k, what in KEYS.items())]

    def _read(self):
        pending = ""
        while not self._stop.is_set():
            ready, _, _ = select.select([self._fd], [], [], 0.1)
            if not ready:
                continue
            chunk = os.read(self._fd, 64).decode(errors="replace")
            if not chunk:
                return
            pending += chunk
            while pending:
                if pending.startswith("\x1b"):  # an arrow: ESC [ A..D
                    if len(pending) < 3:
                        break
                    key, pending = pending[:3], pending[3:]
                else:
                    key, pending = pending[0], pending[1:]
                if key == "q":
                    self.controls.close()
                    return
                item = key_input(key, self.controls)
                if item is not None:
                    self.controls.submit(*item)

    def close(self):
        self._stop.set()
        self._thread.join(1.0)
        termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
        return ""
