"""The default layout's views (viz.blueprint): what each camera panel is called says what it
shows, for a design that takes the camera and for one that only has it film the run."""

import rerun.blueprint as rrb

from fpga_robotics.viz.blueprint import default_blueprint


def _views(blueprint):
    """(kind, name, origin) of every view in the layout, in order."""
    found, todo = [], [blueprint.root_container]
    while todo:
        item = todo.pop(0)
        if isinstance(item, rrb.View):
            found.append((type(item).__name__, item.name, str(item.origin)))
        todo[:0] = [c for c in getattr(item, "contents", None) or () if not isinstance(c, str)]
    return found


def _camera_views(blueprint):
    return [name for kind, name, origin in _views(blueprint) if origin == "camera/raw"]


def test_a_camera_design_sees_the_frame_as_it_receives_it():
    views = _views(default_blueprint())
    assert _camera_views(default_blueprint()) == ["Camera (RGB444, as the design receives it)"]
    assert ("Spatial2DView", "Filtered (design output)", "camera/filtered") in views


def test_a_design_without_a_camera_input_is_not_said_to_receive_the_frame():
    blueprint = default_blueprint(frame_outputs=False, camera=None)
    assert _camera_views(blueprint) == ["Camera (filming the run; not a design input)"]
    assert not [v for v in _views(blueprint) if v[2] == "camera/filtered"]


def test_the_world_in_3d_sits_beside_the_map_when_asked_for():
    names = [name for _, name, _ in _views(default_blueprint(world3d=True))]
    assert "World (3D)" in names and "World (top-down)" in names
    assert "World (3D)" not in [name for _, name, _ in _views(default_blueprint())]
