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

``portable(checkpoint)`` is the same checkpoint as bytes, for another process: the shared
objects are pickled as their place among ``_never_changing`` and bound on restore to the
restoring loop's own (a loop of the same scenario has the same ones, in the same order).
"""

import copy
import io
import pickle

__all__ = ["STATE", "Checkpoint", "PortableCheckpoint", "portable", "restore", "take"]

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
    "exact_extra",
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

    def copy_state(self, loop=None):
        """A fresh deep copy of the saved state (the objects that never change shared with
        the loop it was taken from, whichever ``loop`` restores it)."""
        return copy.deepcopy(self._state, {id(x): x for x in self._shared})


class PortableCheckpoint:
    """A ``Checkpoint`` pickled on its own (``portable``): it restores into a loop of the
    same scenario and seed in any process, sharing that loop's never-changing objects."""

    def __init__(self, frame, blob, shared_types, design_calls=None):
        self.frame = frame
        self.blob = blob
        self.shared_types = shared_types  # of the shared objects, to check the restoring loop's
        self.design_calls = design_calls

    def copy_state(self, loop):
        """The saved state, unpickled with ``loop``'s own never-changing objects in it."""
        shared = _never_changing(loop)
        if _kinds(shared) != self.shared_types:
            raise ValueError("a checkpoint restores only into a loop of its own scenario")
        unpickler = pickle.Unpickler(io.BytesIO(self.blob))
        unpickler.persistent_load = shared.__getitem__
        return unpickler.load()


#: The design's places among the shared objects: the loop's design, and a real-clock loop's
#: pins (the reference's journal; a variant's own pins or play-back).
_DESIGN = (1, 2)


def _never_changing(loop):
    """Objects of the state that no step changes, shared rather than copied: the renderer,
    and the terrain maps with their (frozen) patches, which the world compares by identity."""
    shared = [loop.camera.renderer, loop.design, getattr(loop, "pins", None)]  # _DESIGN
    if loop.rig is not None:
        shared += [cam.connector.renderer for cam in loop.rig.cameras]
    for terrain in (loop.world.terrain, loop.world._painted):
        shared += [terrain, *terrain.patches]
    return shared


def _kinds(shared):
    """The types of the shared objects (``_never_changing``), the design's left out: a
    variant's design restores the reference's checkpoints."""
    return [type(x).__name__ for i, x in enumerate(shared) if i not in _DESIGN]


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


def portable(checkpoint):
    """``checkpoint`` as a ``PortableCheckpoint`` (the state pickled once, here)."""
    where = {id(x): i for i, x in enumerate(checkpoint._shared) if x is not None}
    out = io.BytesIO()
    pickler = pickle.Pickler(out, protocol=pickle.HIGHEST_PROTOCOL)
    pickler.persistent_id = lambda obj: where.get(id(obj))
    pickler.dump(checkpoint._state)
    kinds = _kinds(checkpoint._shared)
    return PortableCheckpoint(checkpoint.frame, out.getvalue(), kinds, checkpoint.design_calls)


def restore(loop, checkpoint):
    """Put ``checkpoint``'s state (a ``Checkpoint`` or ``PortableCheckpoint``) into ``loop``
    (a loop of the same scenario and seed)."""
    for name, value in checkpoint.copy_state(loop).items():
        setattr(loop, name, value)
    loop.restored()
