"""Cut a time window out of a VCD file, streaming (the input is read once, line by line, and
never held in memory).

``trim_vcd(src, dst, start, end)`` writes:

- the header (everything up to and including ``$enddefinitions $end``) unchanged, so every
  variable and scope of the input is declared in the output;
- at ``#0``, a ``$dumpvars`` with the value of every variable at time ``start``: its last
  change at or before ``start`` (``x`` for a wire that never had one);
- the value changes after ``start`` and before ``end``, at their original times;
- a closing ``#end``, so that the file spans the whole window.

Times are in the file's own unit (its ``$timescale``); pass ``timescale`` to have it checked.
The input is read only up to its first time at or after ``end``. ``$comment`` blocks after the
header are dropped; other simulation keywords (``$dumpvars``, ``$dumpoff``, ...) inside the
window are kept.
"""

import re

from fpga_robotics.hw.errors import UserError

__all__ = ["VCDTrimError", "trim_vcd"]

_TOKEN = re.compile(r"\S+")

#: Value changes of these variable types have no ``x`` to stand for "no value yet".
_NO_UNKNOWN = ("real", "string", "event")


class VCDTrimError(UserError, ValueError):
    """The input is not a VCD this trimmer understands, or not in the expected time unit."""


def trim_vcd(src, dst, start, end, *, timescale=None):
    """Copy the VCD text stream ``src`` to ``dst``, keeping only the window from ``start``
    (exclusive: its values form the initial dump) to ``end`` (exclusive).

    ``start`` and ``end`` are integer times in the file's unit, ``0 <= start < end``.
    ``timescale`` (e.g. ``"1 fs"``), if given, must match the file's ``$timescale``.
    """
    if (
        isinstance(start, bool)
        or isinstance(end, bool)
        or not (isinstance(start, int) and isinstance(end, int))
    ):
        raise TypeError(f"start and end must be ints, got {start!r} and {end!r}")
    if not 0 <= start < end:
        raise ValueError(f"need 0 <= start < end, got start={start}, end={end}")
    lines = iter(src)
    variables, file_timescale, rest = _copy_header(lines, dst)
    if timescale is not None and _squash(timescale) != _squash(file_timescale or ""):
        raise VCDTrimError(f"the VCD's timescale is {file_timescale!r}, expected {timescale!r}")

    values = {}  # id code -> its latest value token ("0", "b101", "r1.5", "sfoo")
    inside = False  # past start: changes are copied
    pending = None  # a vector/real/string value waiting for its id code
    in_comment = False
    write = dst.write

    def open_window():
        write("#0\n$dumpvars\n")
        for code, (var_type, size) in variables.items():
            value = values.get(code)
            if value is None:
                if var_type in _NO_UNKNOWN:
                    continue
                value = "x" if size == "1" else "bx"
            write(_change(value, code))
        write("$end\n")

    for tokens in _sim_tokens(rest, lines):
        for token in tokens:
            if in_comment:
                in_comment = token != "$end"
                continue
            if pending is not None:
                if inside:
                    write(f"{pending} {token}\n")
                else:
                    values[token] = pending
                pending = None
                continue
            head = token[0]
            if head == "#":
                try:
                    time = int(token[1:])
                except ValueError:
                    raise VCDTrimError(f"bad time {token!r} in the VCD") from None
                if not inside and time > start:
                    open_window()
                    inside = True
                if inside:
                    if time >= end:
                        write(f"#{end}\n")
                        return
                    write(f"{token}\n")
            elif head in "01xXzZ":
                if len(token) < 2:
                    raise VCDTrimError(f"value change {token!r} without an id code")
                if inside:
                    write(f"{token}\n")
                else:
                    values[token[1:]] = head
            elif head in "bBrRsS":
                pending = token
            elif token == "$comment":
                in_comment = True
            elif head == "$":
                if inside:
                    write(f"{token}\n")
            else:
                raise VCDTrimError(f"unexpected token {token!r} after the VCD's header")
    if pending is not None:
        raise VCDTrimError(f"the VCD ends inside the value change {pending!r}")
    if not inside:
        open_window()
    write(f"#{end}\n")


def _squash(text):
    return "".join(text.split())


def _change(value, code):
    if value[0] in "bBrRsS":
        return f"{value} {code}\n"
    return f"{value}{code}\n"


def _copy_header(lines, dst):
    """Copy the header lines to ``dst``; return ``({id code: (type, size)}, timescale, rest)``
    with ``rest`` the text after ``$enddefinitions $end`` on its line."""
    variables = {}
    timescale = None
    command = None  # the tokens of the header command being read
    for line in lines:
        for match in _TOKEN.finditer(line):
            token = match.group()
            if command is None:
                if not token.startswith("$"):
                    raise VCDTrimError(f"unexpected token {token!r} in the VCD's header")
                command = [token]
            elif token != "$end":
                command.append(token)
            else:
                keyword, args = command[0], command[1:]
                command = None
                if keyword == "$var":
                    if len(args) < 4:
                        raise VCDTrimError(f"incomplete $var declaration: {' '.join(args)!r}")
                    variables.setdefault(args[2], (args[0], args[1]))
                elif keyword == "$timescale":
                    timescale = " ".join(args)
                elif keyword == "$enddefinitions":
                    dst.write(line[: match.end()] + "\n")
                    return variables, timescale, line[match.end() :]
        dst.write(line)
    raise VCDTrimError("the VCD has no $enddefinitions: not a VCD, or cut short")


def _sim_tokens(rest, lines):
    """The simulation section's tokens, a line at a time."""
    yield rest.split()
    for line in lines:
        yield line.split()
