"""The host's side of an Amaranth simulation that lives as long as its backend, shared by the
pysim frame backend (pysim.py) and the pysim pin backend (sim/pins/pysim.py).

One async testbench owns the design and runs the host's jobs one at a time: ``submit(job)``
hands it a job and advances the simulator until the job is done, then returns its outcome
(or raises the error it ended with). Between jobs the testbench parks on a delay. A failure
inside the simulator leaves it unusable: that call and every later one raise ``error``.
"""

__all__ = ["JobLoop"]


class JobLoop:
    """Jobs for ``sim`` (an Amaranth ``Simulator``).

    Parameters
    ----------
    sim : Simulator
    run_job : async callable(ctx, job)
        Runs one job in the testbench; its return value is ``submit``'s.
    park : float
        Seconds of simulated time the testbench waits between two jobs.
    error : type
        The backend's exception: raised by ``run_job`` it is the job's outcome (``submit``
        raises it), and it reports a failed simulation.
    """

    def __init__(self, sim, run_job, *, park, error):
        self._sim = sim
        self._run_job = run_job
        self._park = park
        self._error = error
        self._job = None
        self._outcome = None
        self._broken = None
        #: Whether the testbench has been added (with the first job, or by ``start``).
        self.started = False

    def start(self):
        """Add the testbench (Amaranth creates its coroutine at once: adding it lazily spares
        a backend that never runs the warning about a coroutine never awaited)."""
        if not self.started:
            self._sim.add_testbench(self._testbench)
            self.started = True

    def submit(self, job):
        if self._broken is not None:
            raise self._error(
                f"the pysim simulation failed earlier ({self._broken}); create a new backend"
            )
        self.start()
        self._job, self._outcome = job, None
        advance = self._sim.advance
        try:
            while self._job is not None:
                advance()
        except self._error:
            raise
        except Exception as exc:
            self._broken = f"{type(exc).__name__}: {exc}"
            self._job = None
            raise self._error(f"pysim simulation failed: {self._broken}") from exc
        outcome, self._outcome = self._outcome, None
        if isinstance(outcome, self._error):
            raise outcome
        return outcome

    async def _testbench(self, ctx):
        while True:
            job = self._job
            try:
                outcome = await self._run_job(ctx, job)
            except self._error as exc:
                outcome = exc
            self._outcome, self._job = outcome, None
            await ctx.delay(self._park)
