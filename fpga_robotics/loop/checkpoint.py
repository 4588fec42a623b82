"""World checkpoints: the whole closed-loop state at a frame boundary, saved and restored.

A checkpoint of a ``ClosedLoop`` (compressed timing) taken before frame ``k`` holds
everything the run's future depends on except the design: the pymunk world (bodies, people's
scripts, terrain under the robot, collision episodes, the uncertainty streams, lighting),
the camera's noise, drift and sensor streams, the motor commands still scheduled, the colour
select, the trajectory, events and metrics so far and the step and frame counters. Restored
into a loop of the same scenario and seed and run on from frame ``k`` with a design in the
state it had there, the run is bit-identical to the uninterrupted one.

A real-clock loop (fpga_robotics.loop.real_clock) adds its own state (``EXTRA_STATE``): the
pin connectors (ultrasound modules with their pending echoes, line sensors, bumpers, their
random streams), the wheels' actuation delay queue, the watched pins' last values, the row
awaiting its frame outputs and the extra columns.

The design is not part of it (whatever backend drives the loop keeps its own state): a
frame-level design is brought to the frame by its recorded images, a pin design by its
journal (``design_calls``: fpga_robotics.loop.pin_journal). Nor is the renderer (a pure
function of the scene: shared, never copied), the viewer or the live controls.
"""

import copy

__all__ = ["STATE", "Checkpoint", "restore", "take"]

#: The ``ClosedLoop`` attributes that make up its state at a frame boundary.
STATE = (
    "world",
    "camera",
    "motors",
    "step",
    "frames_done",
    "ended_early",
    "traj",
    "absent",
    "events",
    "cycles",
    "design_events",
    "color",
    "scheduled_color",
    "color_code",
    # Further cameras and servos (loop/camera_rig.py), with their channels' state.
    "rig",
)


class Checkpoint:
    """The state of a loop before frame ``frame``; restore it as often as needed."""

    def __init__(self, frame, state, shared, design_calls=None):
        self.frame = frame
        self._state = state
        self._shared = shared
        #: With a journaled pin design: how many calls it had been given (the first
        #: ``design_calls`` of its journal bring a reset design to this point).
        self.design_calls = design_calls

    def copy_state(self):
        """A fresh deep copy of the saved state (the objects that never change shared)."""
        return copy.deepcopy(self._state, {id(x): x for x in self._shared})


def _never_changing(loop):
    """Objects of the state that no step changes, shared rather than copied: the renderer,
    and the terrain maps with their (frozen) patches, which the world compares by identity."""
    shared = [loop.camera.renderer, loop.design, getattr(loop, "pins", None)]
    if loop.rig is not None:
        shared += [cam.connector.renderer for cam in loop.rig.cameras]
    for terrain in (loop.world.terrain, loop.world._painted):
        shared += [terrain, *terrain.patches]
    return shared


def take(loop):
    """A ``Checkpoint`` of ``loop`` at its current frame boundary (``loop.frames_done``)."""
    shared = _never_changing(loop)
    memo = {id(x): x for x in shared}
    # The camera's turn-rate callback reads the loop it belongs to: left out, bound on restore.
    memo[id(loop.camera.turn_rate)] = None
    names = STATE + getattr(loop, "EXTRA_STATE", ())
    state = copy.deepcopy({name: getattr(loop, name) for name in names}, memo)
    calls = getattr(getattr(loop, "primary", None), "calls", None)
    return Checkpoint(loop.frames_done, state, shared, None if calls is None else len(calls))


def restore(loop, checkpoint):
    """Put ``checkpoint``'s state into ``loop`` (a loop of the same scenario and seed)."""
    for name, value in checkpoint.copy_state().items():
        setattr(loop, name, value)
    loop.restored()
