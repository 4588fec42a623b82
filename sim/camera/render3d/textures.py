"""Procedural surface textures, made with numpy from a seed (no image files).

Each texture is a *modulation* ``m`` (H, W) with mean about 1: a surface of albedo ``a`` is
drawn as ``clip(a * m)``, so the surface's average colour stays the scenario's colour and
the raster renderer (flat colours) and the 3D one agree on it. Every pattern tiles: the
noise is built in the frequency domain, so it is periodic over the texture.
"""

import numpy as np

__all__ = ["KINDS", "modulation", "texture_rgb"]

#: Texture kinds and what they look like.
KINDS = {
    "paint": "painted plaster: faint blotches and a fine speckle",
    "planks": "a wooden floor: planks with grain, each plank a little lighter or darker",
    "tiles": "floor tiles with darker grout lines, each tile a little different",
    "grain": "wood grain: wavy stripes along the length (the divider)",
    "plain": "no pattern",
}


def _periodic_noise(rng, size, falloff):
    """Zero-mean, unit-std tiling noise (size, size) with a ``1/f**falloff`` spectrum."""
    f = np.fft.fftfreq(size)
    fx, fy = np.meshgrid(f, f)
    radius = np.hypot(fx, fy)
    radius[0, 0] = np.inf
    spectrum = rng.standard_normal((size, size)) + 1j * rng.standard_normal((size, size))
    noise = np.fft.ifft2(spectrum / radius**falloff).real
    return (noise - noise.mean()) / (noise.std() + 1e-12)


def modulation(kind, size, seed):
    """The brightness pattern of ``kind`` (``KINDS``) as a float (size, size) array around 1."""
    if kind not in KINDS:
        raise ValueError(f"texture kind must be one of {', '.join(KINDS)}, got {kind!r}")
    rng = np.random.default_rng([seed, list(KINDS).index(kind)])
    u = (np.arange(size) + 0.5) / size
    if kind == "plain":
        return np.ones((size, size))
    if kind == "paint":
        return (
            1.0
            + 0.035 * _periodic_noise(rng, size, 1.6)
            + 0.015 * rng.standard_normal((size, size))
        )
    if kind == "tiles":
        n = 4  # tiles per texture side
        cell = (u * n).astype(int)
        shade = 1.0 + 0.05 * rng.standard_normal((n, n))
        m = shade[cell[:, None], cell[None, :]]
        m = m + 0.02 * _periodic_noise(rng, size, 1.2)
        edge = np.minimum((u * n) % 1.0, 1.0 - (u * n) % 1.0)
        grout = (edge[:, None] < 0.025) | (edge[None, :] < 0.025)
        m[grout] = 0.6
        return m / m.mean()
    if kind == "planks":
        n = 6  # planks across the texture (rows), each with its own shade and grain offset
        plank = (u * n).astype(int)
        shade = 1.0 + 0.09 * rng.standard_normal(n)
        phase = rng.uniform(0, 2 * np.pi, n)
        warp = 0.8 * _periodic_noise(rng, size, 2.2)
        grain = np.sin(2 * np.pi * 24 * u[:, None] + phase[plank][:, None] + 3.0 * warp)
        m = shade[plank][:, None] * (1.0 + 0.06 * grain)
        m += 0.02 * _periodic_noise(rng, size, 1.0)
        edge = (u * n) % 1.0
        m[(edge < 0.02) | (edge > 0.98)] *= 0.7  # the gaps between planks
        return m / m.mean()
    # grain: stripes along u (the length of the board), warped, with darker late wood.
    warp = _periodic_noise(rng, size, 2.4)
    rings = np.sin(2 * np.pi * 10 * u[:, None] + 2.5 * warp)
    m = 1.0 + 0.10 * np.sign(rings) * np.abs(rings) ** 0.6
    m += 0.03 * _periodic_noise(rng, size, 0.8)
    return m / m.mean()


def texture_rgb(kind, albedo, size, seed):
    """An RGB888 texture (size, size, 3) uint8: ``albedo`` (r, g, b in 0..1) times the
    pattern of ``kind``."""
    m = modulation(kind, size, seed)
    rgb = np.clip(m[:, :, None] * np.asarray(albedo, dtype=float)[None, None, :], 0.0, 1.0)
    return np.rint(rgb * 255.0).astype(np.uint8)
