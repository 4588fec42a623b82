"""A reference run (fpga_robotics.loop.fork, fpga_robotics.loop.pin_fork) in a form another
process can take: what ``run_variant`` reads of it, with nothing bound to the process that
ran it.

The images are one contiguous ``uint8`` array (a frame is a view into it: one buffer to
pickle and to keep), the world checkpoints are ``PortableCheckpoint`` bytes that restore
into the variant's own loop. Made by ``ReferenceRun.portable()`` (``PinReferenceRun``'s: the
journal of the design's pin calls instead of images), opened again by ``from_portable``.
"""

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

__all__ = ["PinReferenceData", "ReferenceData", "recorded_of"]


@dataclass(eq=False)
class ReferenceData:
    """A reference run, picklable and self-contained.

    Attributes
    ----------
    scenario : Scenario
    seed : int
    result : RunResult
        The reference's own run.
    frames : numpy.ndarray
        ``(frames, height, width, 3)`` uint8: the image of every frame the reference ran.
    colors : list of int
        The colour select of every frame.
    commands : list of (int, int)
        The wheel commands (DPS) of every frame, as the motors took them.
    world_events : list of (list of str, list of str)
        The world's events before and after the design's own, per frame.
    n_frames : int
        The frames of the whole run (more than ``len(frames)`` for a robot that tipped over).
    checkpoints : list of PortableCheckpoint
        In frame order.
    final : PortableCheckpoint
        Once the frames and the physics after them are done.
    captures : list
        Further cameras' captures with their channels' outputs, in the order the run made
        them (fpga_robotics.loop.fork); empty without a rig.
    rig_interface : tuple or None
        How the rig binds the design: a variant's must be the same to replay the captures.
    servo_ports : frozenset
        The channel outputs that command a servo.
    watch_first : dict or None
        The frame each bit of the reference design's watch output first rose in (None: the
        design has no watch).
    """

    scenario: object
    seed: int
    result: object
    frames: np.ndarray
    colors: list
    commands: list
    world_events: list
    n_frames: int
    checkpoints: list
    final: object
    captures: list
    rig_interface: object
    servo_ports: frozenset
    watch_first: dict | None = None

    @property
    def nbytes(self):
        """Roughly how much memory it takes: the images and the checkpoints."""
        saved = [*self.checkpoints, self.final]
        captured = sum(c.rgb.nbytes for c in self.captures)
        return self.frames.nbytes + captured + sum(len(c.blob) for c in saved)


@dataclass(eq=False)
class PinReferenceData:
    """A real-clock reference run (``PinReferenceRun``), picklable and self-contained.

    Attributes
    ----------
    scenario, seed, result
        As ``ReferenceData``'s.
    calls : list of Call
        The journal of the design's pin calls, with their answers (fpga_robotics.loop.
        pin_journal).
    frame_calls : list of int
        The journal's length as each frame started.
    extra_reads : dict
        Journal index of a read of an extra output -> (row, name).
    n_frames, frames_done : int
        The frames of the whole run, and those it ran.
    checkpoints : list of PortableCheckpoint
        In frame order, each with the journal's length where it was taken.
    final : PortableCheckpoint
        At the end of the run.
    watch_first : dict or None
        As ``ReferenceData``'s, by row.
    interface : tuple
        How the loop bound its design (pin_fork's ``_interface``).
    end_cycle : int
        The design's cycle at the end of the run.
    """

    scenario: object
    seed: int
    result: object
    calls: list
    frame_calls: list
    extra_reads: dict
    n_frames: int
    frames_done: int
    checkpoints: list
    final: object
    watch_first: dict | None
    interface: tuple
    end_cycle: int


def pack_frames(seen):
    """The images of ``seen`` ((rgb, colour code) per frame) as one contiguous array."""
    if not seen:
        return np.zeros((0, 0, 0, 3), np.uint8)
    return np.stack([rgb for rgb, _ in seen])


def recorded_of(data):
    """What ``ReferenceRun.run_variant`` reads of its recording loop, from ``data``."""
    return SimpleNamespace(
        seen=list(zip(data.frames, data.colors)),
        commands=data.commands,
        world_events=data.world_events,
        n_frames=data.n_frames,
        checkpoints=data.checkpoints,
        final=data.final,
        captures=data.captures,
        rig_interface=data.rig_interface,
        servo_ports=data.servo_ports,
        watch_first=data.watch_first,
    )
