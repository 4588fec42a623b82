"""Coloured floor patches (``Scene.floor_patches``) as thin flat prisms on the 3D floor.

MuJoCo takes a mesh's convex hull, so a patch is cut into triangles first (ear clipping:
any simple polygon, convex or not), each one its own thin mesh just above the floor.
"""

__all__ = ["patch_assets_and_geoms", "triangulate"]

#: The patches' top above the floor, m (above the floor plane, below anything standing on it).
LIFT = 0.002


def _area2(poly):
    return sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]))


def _inside_triangle(p, a, b, c):
    def cross(o, u, v):
        return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])

    d1, d2, d3 = cross(a, b, p), cross(b, c, p), cross(c, a, p)
    return d1 >= 0 and d2 >= 0 and d3 >= 0


def triangulate(polygon):
    """Triangles ``[(a, b, c), ...]`` covering a simple polygon (ear clipping)."""
    pts = [tuple(map(float, p)) for p in polygon]
    if _area2(pts) < 0:
        pts.reverse()  # counter-clockwise
    out = []
    while len(pts) > 3:
        for i in range(len(pts)):
            a, b, c = pts[i - 1], pts[i], pts[(i + 1) % len(pts)]
            convex = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 1e-12
            if convex and not any(_inside_triangle(p, a, b, c) for p in pts if p not in (a, b, c)):
                out.append((a, b, c))
                del pts[i]
                break
        else:  # degenerate (collinear points left): stop with what is covered
            break
    if len(pts) == 3:
        out.append(tuple(pts))
    return out


def patch_assets_and_geoms(scene):
    """``(assets, geoms)``: MJCF lines of the patch meshes and of their geoms (no contacts)."""
    assets, geoms = [], []
    for k, (polygon, color) in enumerate(scene.floor_patches):
        rgba = " ".join(f"{c:.6g}" for c in (*color, 1.0))
        for t, tri in enumerate(triangulate(polygon)):
            name = f"floor_patch{k}_{t}"
            verts = " ".join(f"{x:.6g} {y:.6g} {z:.6g}" for x, y in tri for z in (LIFT / 2, LIFT))
            assets.append(f'<mesh name="{name}" vertex="{verts}"/>')
            geoms.append(
                f'<geom type="mesh" mesh="{name}" rgba="{rgba}" contype="0" conaffinity="0"/>'
            )
    return assets, geoms
