"""The figures of docs/render3d.md (``fpga-robotics bench render3d --figures FOLDER``).

For each 3D scenario (``divider_3d``, ``lighting_3d``), the same instant drawn by both
renderers side by side (raster left, 3D right), and under each frame what the design's red
filter passes with the default ``diff_min = 6`` (the threshold each story starts from).
Written as ``FOLDER/<scenario>.png``; the robot stands at its start, the people walk their
paths up to the instant shown. With ``--viewer``, also ``FOLDER/viewer_3d.png``: the rerun
viewer's window (headless, 1920x1080) after 3 s of ``divider_3d`` in closed loop, with the
world in 3D beside the map; it needs a Vulkan driver (on Debian ``mesa-vulkan-drivers``).
"""

import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.connectors.camera import make_renderer
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.frames import rgb444_to_rgb888, to_rgb444
from fpga_robotics.sim.files import check_output_dir, write_atomic
from fpga_robotics.sim.models.follow_target import filter_frame
from fpga_robotics.sim.world import World

__all__ = ["FIGURES", "figure", "write_figures"]

#: Scenario -> (simulated time shown, s; overrides).
FIGURES = {
    "divider_3d": (3.0, ["camera.shadow_size=1024"]),
    "lighting_3d": (12.0, ["camera.shadow_size=1024"]),
}
SIZE = (320, 240)
FILTER_DIFF_MIN = 6


def figure(name, t, overrides=()):
    """The (2H, 2W, 3) uint8 figure of scenario ``name`` at time ``t``."""
    scenario = load_scenario(name, list(overrides))
    cam = scenario.camera
    world = World.from_config(scenario.world, scenario.seed)
    while world.time < t:
        world.step(1 / 30)
    scene, pose = world.scene(), world.camera_pose()
    w, h = SIZE
    params = FollowTargetParams(width=w, height=h, diff_min=FILTER_DIFF_MIN)
    columns = []
    for renderer in ("raster", "mujoco"):
        image = make_renderer(renderer, w, h, cam.hfov, cam.render3d).render(scene, pose)
        packed = to_rgb444(image, w, h)
        filtered = rgb444_to_rgb888(filter_frame(packed, "red", params))
        columns.append(np.vstack([image, filtered]))
    return np.hstack(columns)


def write_figures(folder, viewer=False):
    """Write ``FOLDER/<scenario>.png`` for each of ``FIGURES`` (and the viewer's screenshot)."""
    folder = Path(folder)
    check_output_dir(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name, (t, overrides) in FIGURES.items():
        image = figure(name, t, overrides)
        path = folder / f"{name}.png"
        ok, data = cv2.imencode(".png", cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
        if not ok:
            raise UsageError("OpenCV could not encode a PNG (is its image codec installed?)")
        write_atomic(path, data.tobytes())
        print(f"wrote {path}")
    if viewer:
        path = folder / "viewer_3d.png"
        _viewer_screenshot(path)
        print(f"wrote {path}")


def _viewer_screenshot(path, port=9877):
    """Run ``divider_3d`` for 3 s into a recording and save the headless viewer's window."""
    import rerun.experimental as rrx  # lazy: rerun costs ~1 s; only the screenshot needs it

    from fpga_robotics.viz import open_recorder  # lazy: viz imports rerun (~1 s)

    with tempfile.TemporaryDirectory() as tmp:
        rrd = str(Path(tmp) / "divider_3d.rrd")
        with open_recorder(f"save:{rrd}", default_path=rrd) as rec:
            run_scenario(load_scenario("divider_3d", ["sim.duration=3"]), recorder=rec)
        viewer = rrx.ViewerClient.spawn(headless=True, port=port, hide_welcome_screen=True)
        try:
            viewer.open(rrd)
            time.sleep(8)  # the viewer loads the file and draws every view
            viewer.save_screenshot(str(path))
        finally:
            viewer.quit()
