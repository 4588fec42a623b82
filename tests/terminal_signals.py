"""What a terminal gives the command it starts: Ctrl-C and SIGTERM at their defaults and no
signal blocked. The tests that stop a run with Ctrl-C start it so (``preexec_fn``), whatever
the test process's own disposition: an ignored or blocked signal is inherited across exec,
and a command started with SIGINT ignored could never be stopped by it."""

import signal

__all__ = ["FROM_A_TERMINAL", "as_from_a_terminal"]


def as_from_a_terminal():
    """Run in the child before its exec (``subprocess.Popen(preexec_fn=...)``)."""
    signal.pthread_sigmask(signal.SIG_SETMASK, [])
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_DFL)


#: ``subprocess.Popen`` arguments that start a command as a terminal does. The child calls
#: only signal functions between fork and exec (no lock another thread could hold), which is
#: what makes ``preexec_fn`` safe here although the test process has threads.
FROM_A_TERMINAL = {"preexec_fn": as_from_a_terminal}
