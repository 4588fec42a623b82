"""What the 3D renderer draws beyond the scene: shadows, textures, lamps, shine.

Plain data, filled from a scenario's ``[camera]`` keys by the application (docs/render3d.md).
"""

from dataclasses import dataclass

__all__ = ["FLOORS", "MAX_LAMPS", "Lamp", "Render3DOptions"]

#: Floor textures (kinds of ``textures.KINDS``).
FLOORS = ("planks", "tiles", "plain")

#: Lamps MuJoCo draws: its OpenGL renderer lights with at most 8 lights, and the headlight
#: (the ambient light) and the scene's directional light take two; further ones would be
#: dropped without a word.
MAX_LAMPS = 6


@dataclass(frozen=True)
class Lamp:
    """A spot lamp: at ``pos`` (x, y, z m), shining at ``aim`` (x, y, z m), of ``color`` (its
    diffuse light, r, g, b >= 0; 1 is as strong as a directional light of intensity 1), with a
    cone of half angle ``cutoff_deg``; it casts shadows when shadows are on and ``shadows``."""

    pos: tuple
    aim: tuple
    color: tuple = (0.5, 0.5, 0.5)
    cutoff_deg: float = 45.0
    shadows: bool = True


@dataclass(frozen=True)
class Render3DOptions:
    """Options of ``MujocoRenderer``.

    Attributes
    ----------
    shadows : bool
        Lights cast shadows (the scene's directional light and the lamps).
    shadow_size : int
        Side of each light's shadow map, pixels (more: sharper shadows, slower).
    textures : bool
        Procedural textures (painted walls, the floor, wood grain); off: flat colours.
    floor : str
        The floor's texture, one of ``FLOORS``.
    shine : float
        Specular strength of clothes and wood, 0..1 (highlights; 0: matte as the raster).
    lamps : tuple of Lamp
        Spot lamps added to the scene's light, at most ``MAX_LAMPS``.
    seed : int
        Seeds the textures.
    """

    shadows: bool = True
    shadow_size: int = 256
    textures: bool = True
    floor: str = "planks"
    shine: float = 0.0
    lamps: tuple = ()
    seed: int = 0

    def __post_init__(self):
        if self.floor not in FLOORS:
            raise ValueError(f"floor must be one of {', '.join(FLOORS)}, got {self.floor!r}")
        if not 0.0 <= self.shine <= 1.0:
            raise ValueError(f"shine must be in 0..1, got {self.shine!r}")
        if not 64 <= self.shadow_size <= 8192:
            raise ValueError(f"shadow_size must be 64..8192 pixels, got {self.shadow_size!r}")
        if len(self.lamps) > MAX_LAMPS:
            raise ValueError(f"at most {MAX_LAMPS} lamps are drawn, got {len(self.lamps)}")
