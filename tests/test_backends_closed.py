"""A compiled backend used after ``close()`` raises an error that says so; before, the harness
was handed a freed (null) model and the whole Python process died of a segmentation fault."""

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.backends import BackendError, get_backend
from fpga_robotics.sim.backends.foreign_choice import open_foreign_frames
from fpga_robotics.sim.backends.port_map import follow_target_port_map

PARAMS = FollowTargetParams(
    width=40, height=16, min_pixels=4, proximity_thresholds=(4, 8, 16, 32, 64, 96, 128)
)
FRAME = np.zeros((16, 40, 3), np.uint8)
CLOSED = "the backend is closed; open a new one"


def _check_closed(backend):
    first = backend.process_frame(FRAME)
    backend.close()
    backend.close()  # twice is fine
    with pytest.raises(BackendError, match=CLOSED):
        backend.process_frame(FRAME)
    with pytest.raises(BackendError, match=CLOSED):
        backend.process_frame(FRAME[:, :, 0].astype(np.uint16))  # the packed path too
    with pytest.raises(BackendError, match=CLOSED):
        backend.reset()
    return first


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_builtin_backend_after_close(name):
    with get_backend(name, PARAMS) as backend:
        first = _check_closed(backend)
    # It ran before: a black frame finds nothing.
    assert not first.found and first.cycles > 0
    with get_backend(name, PARAMS) as again:  # a new one runs as before
        assert again.process_frame(FRAME) == first


@pytest.mark.slow
@pytest.mark.parametrize("name", ["cxxrtl", "verilator"])
def test_verilog_design_after_close(name, tmp_path):
    (tmp_path / "ft.v").write_text(generate_verilog(PARAMS))
    (tmp_path / "ft.toml").write_text(follow_target_port_map(PARAMS))
    backend = open_foreign_frames(
        name, PARAMS, files=[tmp_path / "ft.v"], port_map=tmp_path / "ft.toml"
    )
    first = _check_closed(backend)
    model = get_backend("model", PARAMS)
    assert first.outputs() == model.process_frame(FRAME).outputs()
