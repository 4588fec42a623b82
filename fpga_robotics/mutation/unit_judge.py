"""The unit judge: each mutant against the golden model, frame by frame, on a fixed set of
frames.

The frames are seeded synthetic sequences that move every output: a still target at the
centre, left and right; a sweep across the image; an approach through every proximity level;
a target lost long enough for the search and found again on the other side; the same sweep
in green (the colour select); a wooden distractor; noise frames that may match anywhere. They
run in one order from a reset, so state (the motor's lost-frame count, the divider) matters.

A mutant is *caught* when any output of any frame differs from the model's (the filtered
image included) or the design breaks the frame protocol (no result strobe within the time-out,
a filtered stream of the wrong length); otherwise it is *equivalent on these frames* (reported apart: it may be a
real equivalent mutant, or a bug these frames cannot show).
"""

from dataclasses import dataclass, field

from fpga_robotics.loop.shadow import COMPARED_OUTPUTS, differing_outputs, output_value
from fpga_robotics.sim.camera import synthetic

from ..sim.backends import BackendError, get_backend
from ..sim.mutation import MUTATION_SELECT

__all__ = ["UnitVerdict", "golden_results", "judge_frames", "judge_mutant", "reference_results"]


@dataclass
class UnitVerdict:
    """What the unit judge found for one mutant."""

    index: int
    caught: bool
    first_frame: int | None = None  # the first frame with a difference
    # output -> frames in which it differs
    differing: dict = field(default_factory=lambda: dict.fromkeys(COMPARED_OUTPUTS, 0))
    first_difference: dict = field(default_factory=dict)  # output -> (model, mutant) there
    failure: str | None = None  # the design broke the frame protocol (a timeout, a bad stream)
    frames: int = 0  # the frames judged
    frames_differing: int = 0  # frames in which any output differs
    # scalar output -> the largest |model - mutant| over the frames (found counts 0/1)
    max_difference: dict = field(default_factory=dict)
    # the filtered image's pixels that differ in the first frame with a difference: its
    # first_difference (matching pixels, model -> mutant) may be equal when pixels differ
    first_filtered_pixels: int = 0

    def effect(self):
        """One line: what the mutant does to the outputs."""
        if not self.caught:
            return "no output differs on the unit frames"
        if self.failure is not None:
            return f"frame {self.first_frame}: {self.failure}"
        parts = [f"{name} in {n} frame(s)" for name, n in self.differing.items() if n]
        first = ", ".join(
            f"filtered {self.first_filtered_pixels} pixel(s) differ"
            if k == "filtered"
            else f"{k} {v[0]} -> {v[1]}"
            for k, v in self.first_difference.items()
        )
        return f"differs from frame {self.first_frame}: {first}; " + ", ".join(parts)


def judge_frames(params, seed=0):
    """``[(frame, colour)]``: the unit judge's frames for ``params``'s resolution."""
    w, h, lost = params.width, params.height, params.lost_frames
    rng = synthetic.make_rng(seed)
    frames = []

    def add(name, color="red", **kw):
        s = synthetic.scenario(name, w, h, color=color, lost_frames=lost, rng=rng, **kw)
        frames.extend((f, color) for f in s.frames)

    for name in ("centre", "left", "right", "sweep", "approach", "lost"):
        add(name)
    add("sweep", color="green")
    wood = synthetic.Blob("wood", w * 0.3, h * 0.5, radius=h * 0.15)
    add("sweep", n_frames=6, distractors=(wood,))
    frames.extend((synthetic.random_frame(w, h, rng), "red") for _ in range(4))
    return frames


def golden_results(params, frames):
    """The model's results for ``frames`` from a reset."""
    model = get_backend("model", params)
    return [model.process_frame(f, color) for f, color in frames]


def reference_results(design, frames):
    """The unmutated design's results for ``frames`` from a reset (``mutsel = 0`` of the
    mutant netlist): what each mutant is compared with when no golden model is used, as in
    MCY. ``BackendError`` if the design itself breaks the frame protocol."""
    design.set_runtime(MUTATION_SELECT, 0)
    design.reset()
    return [design.process_frame(f, color) for f, color in frames]


def judge_mutant(design, index, frames, golden):
    """Run mutant ``index`` of ``design`` (a backend of the mutant netlist with ``mutsel`` as a
    ``[runtime]`` input; 0 is the unmutated design) on ``frames`` from a reset and compare
    with ``golden``; a ``UnitVerdict``."""
    design.set_runtime(MUTATION_SELECT, index)
    design.reset()
    verdict = UnitVerdict(index=index, caught=False)
    for k, ((frame, color), want) in enumerate(zip(frames, golden)):
        try:
            got = design.process_frame(frame, color)
        except BackendError as exc:  # a hang (no result strobe) or a broken stream: caught
            if not verdict.caught:
                verdict.caught, verdict.first_frame = True, k
                verdict.failure = str(exc).split(": ", 2)[-1]
            break
        verdict.frames += 1
        differ = differing_outputs(want, got)
        verdict.frames_differing += bool(differ)
        for name in differ:
            verdict.differing[name] += 1
            if name != "filtered":
                gap = abs(int(output_value(want, name)) - int(output_value(got, name)))
                verdict.max_difference[name] = max(verdict.max_difference.get(name, 0), gap)
        if differ and not verdict.caught:
            verdict.caught = True
            verdict.first_frame = k
            verdict.first_difference = {
                n: (output_value(want, n), output_value(got, n)) for n in differ
            }
            if "filtered" in differ:
                verdict.first_filtered_pixels = int((want.filtered != got.filtered).sum())
    return verdict
