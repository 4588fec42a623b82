"""A shadow design in the recording: a second LED row and DPS series beside the primary's, the
first divergence among the events, a layout with both."""

from pathlib import Path

import numpy as np
import pytest

from fpga_robotics import cli
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.leds import centroid_image
from fpga_robotics.viz.readback import read_rrd


def test_shadow_outputs_are_recorded_beside_the_primary(tmp_path):
    s = load_scenario("lost_target", ["sim.duration=5"])
    other = s.with_overrides(["design.lost_frames=5"]).params
    rec = open_recorder(f"save:{tmp_path / 'run.rrd'}", default_path=str(tmp_path / "d.rrd"))
    shadow_results = []
    with ModelBackend(other) as shadow:
        r = run_scenario(
            s,
            backend="model",
            recorder=rec,
            shadow=shadow,
            shadow_label="five",
            on_frame=lambda record: shadow_results.append(record.shadow_result),
        )
    rec.close()
    data = read_rrd(str(tmp_path / "run.rrd"))
    n = r.summary["frames"]
    for path in (P.SHADOW_LEDS_PROXIMITY, P.SHADOW_LEDS_CENTROID, P.SHADOW_MOTORS_DPS):
        assert data.entities[path].frames == list(range(n)), path
    dps = np.array([v for v in data.entities[P.SHADOW_MOTORS_DPS].values["Scalars:scalars"]])
    expected = [(res.motor_left, res.motor_right) for res in shadow_results]
    assert np.array_equal(dps.reshape(n, 2), np.array(expected, float))
    # The shadow design's LEDs as the board would light them, frame by frame.
    k = r.summary["shadow"]["first_divergence"]["frame"]
    led_rows = data.entities[P.SHADOW_LEDS_CENTROID].values["Image:buffer"]
    assert np.array_equal(
        np.asarray(led_rows[k]).ravel(), centroid_image(shadow_results[k].centroid_leds).ravel()
    )
    texts = [str(v) for v in data.entities[P.EVENTS].values["TextLog:text"]]
    assert any("shadow design five diverges" in t for t in texts)
    assert data.blueprints == 2  # the layout with the shadow rows replaces the first one
    assert P.SHADOW_MOTORS_DPS in data.static  # its series names and colours


def test_no_shadow_entities_without_a_shadow(tmp_path):
    s = load_scenario("lost_target", ["sim.duration=1"])
    rec = open_recorder(f"save:{tmp_path / 'run.rrd'}", default_path=str(tmp_path / "d.rrd"))
    run_scenario(s, backend="model", recorder=rec)
    rec.close()
    data = read_rrd(str(tmp_path / "run.rrd"))
    assert not any(
        p.startswith("shadow") or p == P.SHADOW_MOTORS_DPS
        for p in list(data.entities) + list(data.static)
    )


def test_a_shadow_design_on_pins_is_recorded_through_its_own_ports(tmp_path, capsys):
    """Real-clock timing, --shadow REF: the shadow's wheels (declared as wheel_l/wheel_r)
    and its extra outputs are recorded row by row beside the primary's. NearRedCam is
    NearRed's logic under other port names, here at 300 DPS against the primary's 400."""
    designs = Path(__file__).parent / "data" / "user_designs"
    path = tmp_path / "run.rrd"
    argv = ["run", "--scenario", str(designs / "near_red.toml"), "--duration", "2"]
    argv += ["--set", "robot.start=[2.2, 1.5]"]  # near the person within the run
    argv += ["--shadow", f"{designs / 'near_red_cam.py'}:NearRedCam", "--shadow-param", "speed=300"]
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "--backend", "cxxrtl", "--rerun", f"save:{path}", "--quiet"])
    assert info.value.code == 0, capsys.readouterr().err
    data = read_rrd(str(path))

    def series(entity):
        assert data.entities[entity].frames == list(range(20)), entity
        return np.array(data.entities[entity].values["Scalars:scalars"], float).reshape(20, -1)

    primary, shadow = series(P.MOTORS_DPS), series(P.SHADOW_MOTORS_DPS)
    assert set(primary.ravel()) == {0.0, 400.0}  # it drives, then stops near the person
    assert np.array_equal(shadow * 4, primary * 3)  # the same decisions, at 300 DPS
    for name in ("red_count", "near"):
        own = series(f"design/shadow_extra/{name}")
        assert np.array_equal(own, series(f"design/extra/{name}")), name
    assert P.SHADOW_LEDS_PROXIMITY not in data.entities  # NearRedCam has no LEDs
