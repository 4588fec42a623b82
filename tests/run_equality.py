"""Two closed-loop runs compared field by field: trajectories, events and summaries equal
bit for bit, the wall-clock timing fields excepted (they measure the machine, not the run)."""

import numpy as np

#: Summary fields that measure how fast the run went.
TIMING_FIELDS = (
    "wall_time_s",
    "ms_per_frame",
    "realtime_factor",
    "cpu_ms_per_frame",
    "cycles_per_wall_s",
)


def assert_same_run(a, b):
    assert a.trajectory.keys() == b.trajectory.keys()
    for name, values in a.trajectory.items():
        other = b.trajectory[name]
        assert values.dtype == other.dtype, name
        assert np.array_equal(values, other, equal_nan=values.dtype.kind == "f"), name
    assert a.events == b.events
    sa = {k: v for k, v in a.summary.items() if k not in TIMING_FIELDS}
    sb = {k: v for k, v in b.summary.items() if k not in TIMING_FIELDS}
    assert sa == sb
