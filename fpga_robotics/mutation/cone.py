"""The robot judge's verdict without a run, for a mutant whose fault cannot reach what the
closed loop reads.

A closed-loop run reads every output of the design (the result strobe ``frame_done``, which
decides when results are sampled and the cycle count, included) but the pixel bits of the
filtered video stream: the harness checks that stream's framing (its valid, its first and
last flags, ``filtered.payload`` bits 12 and 13) and hands its pixels, bits 0 to 11, only to
the viewer. A mutant whose fan-out cone (``sim.mutation.mutant_cones``: through any cells,
flip-flops included, bit by bit) reaches none of the read outputs runs every judging run
exactly as the unmutated design does, so its verdict is known: not caught, its closest run
the unmutated design's closest. Anything unsure counts as read: every output port but those
pixel bits, any cell that acts beyond the outputs, and all of the filtered image in a run
that compares it with a shadow design (``--shadow``).
"""

from ..sim.backends.port_map import load_port_map

__all__ = ["PIXEL_BITS", "cone_verdict", "describe_reach", "settled_by_cone", "unread_outputs"]

#: The pixel bits of a filtered stream's payload (data[11:0]); bits 12 and 13 (first, last)
#: are checked by the harness, so they are read.
PIXEL_BITS = range(12)


def unread_outputs(port_map):
    """The output bits ``(port, bit)`` no closed-loop run reads, for a ``PortMap``."""
    if not port_map.filtered_payload:
        return frozenset()
    return frozenset((port_map.filtered_payload, b) for b in PIXEL_BITS)


def describe_reach(reach):
    """What a cone reaches as sorted names: ``filtered__payload[5]``, ``cell $print$3``."""
    return sorted(f"cell {b}" if p == "cell" else f"{p}[{b}]" for p, b in reach)


def settled_by_cone(cones, port_map_path, argvs):
    """``{index: [what its cone reaches]}`` of the mutants (``cones``: ``{index: reach}``
    from ``mutant_cones``) whose cone reaches no output the runs ``argvs`` read, with the
    design's port map at ``port_map_path``. None when a run compares the design with a
    shadow design: that compares the filtered image too."""
    if any("--shadow" in argv for argv in argvs):
        return {}
    unread = unread_outputs(load_port_map(port_map_path))
    return {k: describe_reach(reach) for k, reach in cones.items() if reach <= unread}


def cone_verdict(reached, closest):
    """The robot judge's verdict of a mutant settled by its cone (``reached``: what the cone
    reaches; ``closest``: the index, among the judging runs, of the unmutated design's run
    nearest to failing): what its runs in full give, without running them."""
    return {
        "caught": False,
        "run": None,
        "status": "pass",
        "message": "",
        "failed_checks": [],
        "closest": closest,
        "runs": 0,
        "wall_s": 0.0,
        "judged_by": "cone",
        "cone_outputs": list(reached),
    }
