"""A plane with a known UV cut for the UV-seam tests: a finely tessellated square whose UVs are one
chart, or two charts split along x = 0 (vertices duplicated along the cut, the right half rotated by
90 degrees, or mirrored, and placed apart in UV), lit by a narrow stripe that crosses the cut
obliquely (the shadow of a slit in an occluder outside the camera's view)."""

from __future__ import annotations

import numpy as np

from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.mesh import Mesh
from tests.tsd_scenes import light_from, skin

UV_SCALE = 0.25  # UV units per scene unit in every layout (the same mm per texel)
TEXELS = 512  # the default irradiance size: chart offsets sit on its texel grid


def _t(n: int) -> float:
    return n / TEXELS


def plane_mesh(cut: str | None = None, n: int = 32, phase: float = 0.0) -> Mesh:
    """A 2 x 2 plane in z = 0 tessellated into n x n quads (n even). cut None: one chart at
    u, v in [0.25, 0.75]. cut "rotate" / "mirror": the left half (x < 0) at u in [26/512, ...], the right
    half rotated by -90 degrees / mirrored about u = v, placed in the lower right of the layout.
    phase: every chart moved by `phase` texels across the cut (along +x, in its own UV frame), so that
    every layout still samples the surface at the same points, and the cut x = 0 crosses texels
    `phase` of a texel from their left edge (0: it runs along texel edges)."""
    xs = np.linspace(-1.0, 1.0, n + 1)
    gx, gy = np.meshgrid(xs, xs, indexing="xy")  # [row = y][col = x]
    pos = np.stack([gx, gy, np.zeros_like(gx)], -1).reshape(-1, 3)
    vid = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    quads = [(vid[j, i], vid[j, i + 1], vid[j + 1, i + 1], vid[j + 1, i]) for j in range(n) for i in range(n)]
    tris = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.int64)
    if cut is None:
        uv = np.stack([_t(128 + phase) + UV_SCALE * (pos[:, 0] + 1), _t(128) + UV_SCALE * (pos[:, 1] + 1)], 1)
        return Mesh("plane", pos, tris, normals=np.tile([0, 0, 1.0], (len(pos), 1)), uvs=uv)
    # duplicate the vertices on x = 0 for the right half's triangles
    mid = n // 2
    right_tri = np.array([i >= mid for j in range(n) for i in range(n) for _ in (0, 1)])
    on_cut = np.isclose(pos[:, 0], 0.0)
    dup = {v: len(pos) + k for k, v in enumerate(np.flatnonzero(on_cut))}
    pos2 = np.concatenate([pos, pos[on_cut]])
    tris2 = tris.copy()
    for t in np.flatnonzero(right_tri):
        tris2[t] = [dup.get(v, v) for v in tris[t]]
    right_v = np.zeros(len(pos2), bool)
    right_v[np.unique(tris2[right_tri])] = True
    x, y = pos2[:, 0], pos2[:, 1]
    uv = np.stack([_t(26 + phase) + UV_SCALE * (x + 1), _t(128) + UV_SCALE * (y + 1)], 1)  # left half: u from 26/512
    if cut == "rotate":  # (x, y) -> (y, -x): a proper rotation
        ur, vr = _t(230) + UV_SCALE * (y + 1), _t(154 - phase) - UV_SCALE * x
    elif cut == "mirror":  # (x, y) -> (y, x): a reflection
        ur, vr = _t(230) + UV_SCALE * (y + 1), _t(26 + phase) + UV_SCALE * x
    else:
        raise ValueError(f"cut: expected None, 'rotate' or 'mirror', got {cut!r}")
    uv[right_v] = np.stack([ur, vr], 1)[right_v]
    return Mesh("plane", pos2, tris2, normals=np.tile([0, 0, 1.0], (len(pos2), 1)), uvs=uv)


def _quad(name, corners, z) -> Mesh:
    p = np.array([[x, y, z] for x, y in corners], np.float32)
    return Mesh(name, p, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), normals=np.tile([0, 0, 1.0], (4, 1)))


def stripe_scene(mesh: Mesh, material: Material | None = None, angle_deg: float = 30.0, width: float = 0.1) -> Scene:
    """`mesh` (the plane) at 20 mm per unit seen straight from above, lit by light travelling along
    (1, 0, -1) through a slit in a black occluder at height 3 (x in [-4.5, -1.05], outside the view): a lit
    stripe `width` units wide through the origin at `angle_deg` to the x axis, crossing the cut x = 0."""
    s = Scene("stripe", 20.0)
    s.environment.ambient = np.zeros(3)
    s.add(MeshNode("plane", mesh, material or skin(radius=(2.0, 1.0, 0.5))))
    h, x0, x1 = 3.0, -4.5, -1.05
    k = np.tan(np.radians(angle_deg))
    half = 0.5 * width / np.cos(np.radians(angle_deg))

    def y(x):  # the slit's centre line in the occluder: the stripe's, shifted by -h along x
        return k * (x + h)

    black = Material("black", {"base_color": (0, 0, 0), "specular": 0.0})
    top = [(x0, y(x0) + half), (x1, y(x1) + half), (x1, 6.0), (x0, 6.0)]
    bottom = [(x0, -6.0), (x1, -6.0), (x1, y(x1) - half), (x0, y(x0) - half)]
    s.add(MeshNode("occluder_top", _quad("occluder_top", top, h), black))
    s.add(MeshNode("occluder_bottom", _quad("occluder_bottom", bottom, h), black))
    s.add(light_from((1.0, 0.0, -1.0), shadow=True))
    dist = 1.0 / np.tan(np.radians(1.0))
    cam = CameraNode("cam", yfov=np.radians(2.0), znear=0.5 * dist, zfar=2.0 * dist)
    cam.look_at((0, 0, dist), (0, 0, 0))
    s.add(cam)
    return s


def backlit_plate_scene(
    mesh: Mesh,
    material: Material | None = None,
    thickness_mm: tuple = (1.0, 1.0),
    light: tuple = (0.5, 0.0, 0.866),
    view: float = 0.1,
) -> Scene:
    """`mesh` (the plane, 20 mm per unit) as the front of a thin plate lit only from behind: grey
    opaque sheets below it (separate nodes, hidden behind the plane), thickness_mm = (x < 0, x > 0)
    below, are where the light enters, so the plane's translucency sees a plate of that thickness
    (from the shadow pass's distance map; a step at the cut x = 0 when the two differ); the light
    travels along `light`, toward the camera. Seen straight from above, zoomed on the cut: the view
    spans x, y in [-view, view]."""
    s = Scene("backlit_plate", 20.0)
    s.environment.ambient = np.zeros(3)
    s.add(MeshNode("plane", mesh, material or skin(radius=(2.0, 1.0, 0.5))))
    for name, (x0, x1), t in (("back_left", (-1.5, 0.0), thickness_mm[0]), ("back_right", (0.0, 1.5), thickness_mm[1])):
        z = -t / s.mm_per_unit
        corners = np.array([[x0, 1.5, z], [x1, 1.5, z], [x1, -1.5, z], [x0, -1.5, z]], np.float32)
        back = Mesh(name, corners, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), normals=np.tile([0, 0, -1.0], (4, 1)))
        s.add(MeshNode(name, back, Material("back", {"specular": 0.0})))  # facing -z, the light
    s.add(light_from(light, shadow=True))
    dist = view / np.tan(np.radians(1.0))
    cam = CameraNode("cam", yfov=np.radians(2.0), znear=0.5 * dist, zfar=2.0 * dist)
    cam.look_at((0, 0, dist), (0, 0, 0))
    s.add(cam)
    return s
