"""Child processes (compilers, the FPGA flow) that never outlive an interrupt.

A build runs ``make`` or ``sh``, which start compilers of their own. Killing only the direct
child on Ctrl-C or SIGTERM would leave those running; so each child gets a process group of
its own, and on any exception the whole group is ended.
"""

import os
import signal
import subprocess

__all__ = ["run_captured"]

#: Seconds a process group gets to end after SIGTERM before it is killed.
_GRACE_S = 2.0


def _end_group(proc):
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=_GRACE_S)
            return
        except subprocess.TimeoutExpired:
            continue


def run_captured(argv, *, cwd=None, env=None, stdout=subprocess.PIPE, timeout=None):
    """Run ``argv``; return ``(returncode, output)`` with stderr merged into stdout (text).

    ``stdout`` may be a file object to send the output there instead (``output`` is then
    ``None``). On an exception here (KeyboardInterrupt, a timeout) the child's whole process
    group is ended before the exception goes on.
    """
    proc = subprocess.Popen(
        [str(a) for a in argv],
        cwd=cwd,
        env=env,
        stdout=stdout,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        out, _ = proc.communicate(timeout=timeout)
    except BaseException:
        _end_group(proc)
        raise
    return proc.returncode, out
