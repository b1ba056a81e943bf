"""A second shadow map fitted to what the camera sees (issue 21: close-ups).

A light's shadow map covers the whole scene as the light sees it (skinlab/render/passes/shadow.py
``light_view_proj``): on a close-up of a nose on a head 200 mm wide, a 2048-texel map gives 0.1 mm
texels, and its 3x3 PCF smooths a shadow's edge over about 0.3 mm, while a pixel is 0.3 mm and the
shadow of a sun is sharp; on marble's 2 mm slit the map resolved the slit 1.3 % narrow
(docs/ground-truth.md, "Where the targets stand"). What the camera sees is a window of that map:
rendering the window again into a map of the same texel count, shaped as the window is, makes the
texels finer by 2 / sqrt(w h) (w, h: the window's size in the full map's clip coordinates, of 2 x 2),
the crop matrix of cascaded shadow maps (Dimitrov 2007, "Cascaded Shadow Maps", NVIDIA; Engel 2006,
"Cascaded shadow maps", ShaderX5). The full map stays for every point outside the window (texels the
camera does not see still light the texture-space irradiance, the interreflection's senders and the
translucency's distance maps, which keep the full map).

The window: camera rays on a FIT_RAYS x FIT_RAYS grid over the view (Embree through trimesh, the
intersector kept per geometry), their first hits projected by the light's matrix, their bounds grown by
FIT_PAD of the window each side and by FIT_GUARD_TEXELS of the fine map's texels (what lies between two
rays, the PCF's reach); its texels square and no smaller than a FIT_SAMPLE_TEXELS-th of a screen
sample's footprint there (the median over the grid: finer adds lookups, not detail, and a screen pass
averages each lookup over its sample's footprint, lib/lights.glsl, so that a sharp shadow is box-
filtered as the truth's pixels filter it, not aliased); and snapped outward to a grid (FIT_SNAP) so that
a camera moving a little keeps the same window, and the texture-space irradiance that reads it is kept
too (its own pass, `shadow_fit[LIGHT]`; the interreflection reads only the full map). Only depth is
cropped: the window keeps the full map's near and far planes, so every occluder along the light's rays
through it is in the fine map. Where the camera sees the whole scene (every corner of its bounding box
projects into the view) or the fit gains less than FIT_MIN_GAIN, there is no fine map and the frame is
as it was. A light with a size (soft shadows from its distance map, lib/shadow_soft.glsl) keeps its one
map.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from skinlab.cache import Memo

FIT_RAYS = 17  # camera rays per side of the view that find what it sees
FIT_PAD = 0.03  # the window grows by this fraction of its size each side (what lies between the rays)
FIT_GUARD_TEXELS = 4.0  # and by this many fine-map texels (the 3x3 PCF's reach, with room)
FIT_SAMPLE_TEXELS = 8.0  # the fine texel no smaller than this share of a screen sample's footprint
# (its bounding box's longer side in the map, the median over the view): finer than the samples, for
# where an occluder's edge falls (a 2 mm slit within 1 % wants texels of 0.02 mm), not so fine that
# the screen passes' box (lib/shadow.glsl shadow_box: nine gathers) samples too few of its texels
FIT_SNAP = 8.0  # the window's corners snap to a grid this many times finer than its longer side
FIT_MIN_GAIN = 2.0  # a fine map only where its texels are at least this much smaller (per side)
FIT_MIN_TEXELS = 16  # the fine map's shortest side
FIT_MAX_TEXELS = 16384  # and its longest (GL 4.5 guarantees 16384)


class ShadowWindow(NamedTuple):
    """A fine map's window in the full map's clip coordinates (x0, y0, x1, y1 within [-1, 1], after
    the division by w), its size in texels (nx, ny) and how many times smaller its texels are than
    the full map's along the coarser of its two sides (`gain`)."""

    x0: float
    y0: float
    x1: float
    y1: float
    nx: int
    ny: int
    gain: float

    def crop(self) -> np.ndarray:
        """The 4x4 matrix taking the full map's clip coordinates (x, y, z, w) to the fine map's,
        (sx (x - cx w), sy (y - cy w), z, w): after the division by w, x / w in [x0, x1] lands on
        [-1, 1] (y alike), for an orthographic map (w = 1) and a perspective one; depth untouched."""
        sx, sy = 2.0 / (self.x1 - self.x0), 2.0 / (self.y1 - self.y0)
        cx, cy = (self.x0 + self.x1) / 2, (self.y0 + self.y1) / 2
        c = np.eye(4)
        c[0] = (sx, 0.0, 0.0, -sx * cx)
        c[1] = (0.0, sy, 0.0, -sy * cy)
        return c


def camera_rays(camera, aspect: float, n: int = FIT_RAYS) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), unit directions (n * n, 3)) of a grid of rays from the camera over its whole
    view, the outermost along the view's edges."""
    m = np.asarray(camera.world_matrix, np.float64)
    t = math.tan(camera.yfov / 2)
    s = np.linspace(-1.0, 1.0, n)
    xx, yy = np.meshgrid(s * t * aspect, s * t)
    d = np.stack([xx, yy, -np.ones_like(xx)], -1).reshape(-1, 3) @ m[:3, :3].T
    return m[:3, 3].copy(), d / np.linalg.norm(d, axis=1, keepdims=True)


def sees_everything(camera, aspect: float, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether every corner of the box lo..hi lies in front of the camera and within its view."""
    corners = np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)], np.float64)
    clip = np.c_[corners, np.ones(8)] @ (camera.projection_matrix(aspect) @ camera.view_matrix()).T
    w = clip[:, 3]
    if np.any(w <= 0.0):
        return False
    return bool(np.all(np.abs(clip[:, :2] / w[:, None]) <= 1.0))


_INTERSECTORS = Memo(2)  # scene geometry -> Embree intersector over every visible mesh
_HITS = Memo(8)  # (geometry, camera, aspect, rays) -> camera_hits: a camera that holds still casts no rays


def _intersector(nodes):
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    pos, faces, start = [], [], 0
    for node in nodes:
        m = np.asarray(node.world_matrix, np.float64)
        pos.append(node.mesh.positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3])
        faces.append(node.mesh.indices.reshape(-1, 3).astype(np.int64) + start)
        start += len(node.mesh.positions)
    return RayMeshIntersector(trimesh.Trimesh(np.concatenate(pos), np.concatenate(faces), process=False))


def camera_hits(scene, aspect: float, key, n: int = FIT_RAYS) -> np.ndarray:
    """(n, n, 3) the first surface each of the camera's grid of rays meets (NaN: none; `key`: the scene's
    geometry, under which the intersector is kept)."""
    cam = scene.camera

    def cast() -> np.ndarray:
        out = np.full((n * n, 3), np.nan)
        nodes = list(scene.mesh_nodes())
        if nodes:
            ray = _INTERSECTORS.get(key, lambda: _intersector(nodes))
            o, d = camera_rays(cam, aspect, n)
            _, idx, loc = ray.intersects_id(
                np.broadcast_to(o, d.shape).copy(), d, multiple_hits=False, return_locations=True
            )
            out[idx] = loc
        return out.reshape(n, n, 3)

    view = (key, np.asarray(cam.world_matrix, np.float64).tobytes(), float(cam.yfov), float(aspect), n)
    return _HITS.get(view, cast)


def _light_xy(light_clip: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(..., 2) the points' x, y in the light's clip coordinates after the division by w (NaN behind it)."""
    q = np.concatenate([points, np.ones((*points.shape[:-1], 1))], -1) @ np.asarray(light_clip, np.float64).T
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(q[..., 3:4] > 0.0, q[..., :2] / q[..., 3:4], np.nan)


def sample_footprint(light_clip: np.ndarray, hits: np.ndarray, samples: tuple[float, float]) -> float | None:
    """The median of the longer side of one screen sample's footprint, as the light's map sees it (the
    bounding box, in its clip units, of the parallelogram spanned by one sample along x and along y),
    over the cells of the camera's grid of rays `hits` (n, n, 3) whose corners all meet the scene;
    `samples`: the samples between neighbouring rays (along x, along y). None without such a cell."""
    xy = _light_xy(light_clip, hits)
    a = (xy[:-1, 1:] - xy[:-1, :-1]) / samples[0]  # one sample along the view's x
    b = (xy[1:, :-1] - xy[:-1, :-1]) / samples[1]  # and along its y
    side = (np.abs(a) + np.abs(b)).max(-1).ravel()
    side = side[np.isfinite(side) & (side > 0.0)]
    return float(np.median(side)) if len(side) else None


def fit_window(
    light_clip: np.ndarray, points: np.ndarray, size: int, max_size: int, footprint: float | None = None
) -> ShadowWindow | None:
    """The fine map over the points (M, 3) as the light's clip matrix `light_clip` (full map: x, y in
    [-1, 1]) projects them: square texels, at most the full map's `size` x `size` of them shaped as the
    window (each side at most `max_size`), and no smaller than a FIT_SAMPLE_TEXELS-th of a screen
    sample's `footprint` (sample_footprint; finer would add lookups, not detail); None where it would
    gain less than FIT_MIN_GAIN or no point is in the map."""
    xy = _light_xy(light_clip, np.asarray(points, np.float64).reshape(-1, 3))
    xy = xy[np.isfinite(xy).all(1)]
    if len(xy) == 0:
        return None
    x0, y0 = np.maximum(xy.min(0), -1.0)
    x1, y1 = np.minimum(xy.max(0), 1.0)
    w, h = max(x1 - x0, 1e-3), max(y1 - y0, 1e-3)  # a line or a point still gets an area
    # grown by FIT_PAD and the guard band (in texels of a map of size^2 texels over it), then snapped
    # outward to a grid of a FIT_SNAP-th of its longer side rounded down to a power of two: a camera
    # that moves a little keeps the same window, and the passes that read the map are kept
    gx = FIT_PAD * w + FIT_GUARD_TEXELS * math.sqrt(w * h) / size
    gy = FIT_PAD * h + FIT_GUARD_TEXELS * math.sqrt(w * h) / size
    step = 2.0 ** math.floor(math.log2(max(w, h) / FIT_SNAP))
    x0, y0 = (math.floor(v / step) * step for v in (x0 - gx, y0 - gy))
    x1, y1 = (math.ceil(v / step) * step for v in (x1 + gx, y1 + gy))
    x0, y0, x1, y1 = max(x0, -1.0), max(y0, -1.0), min(x1, 1.0), min(y1, 1.0)
    w, h = x1 - x0, y1 - y0
    # the texel: the full map's count over the window, or the sample's share if larger, rounded up to a
    # power of sqrt 2 (a moving camera keeps it too)
    texel = math.sqrt(w * h) / size
    if footprint is not None and footprint > 0.0:
        texel = max(texel, footprint / FIT_SAMPLE_TEXELS)
    texel = 2.0 ** (math.ceil(2.0 * math.log2(texel)) / 2.0)
    nx = int(min(max(math.ceil(w / texel), FIT_MIN_TEXELS), max_size))
    ny = int(min(max(math.ceil(h / texel), FIT_MIN_TEXELS), max_size))
    gain = min(nx / w, ny / h) / (size / 2.0)
    if gain < FIT_MIN_GAIN:
        return None
    return ShadowWindow(float(x0), float(y0), float(x1), float(y1), nx, ny, float(gain))


def shadow_window(
    scene, light_clip: np.ndarray, samples: tuple[int, int], size: int, max_size: int, key
) -> ShadowWindow | None:
    """The fine map for one light (its full map's clip matrix `light_clip`) under the scene's camera
    rendering `samples` (width, height: the screen passes' samples), or None: where the camera sees the
    whole scene, or the fit gains too little."""
    lo, hi = scene.world_bounds()
    aspect = samples[0] / samples[1]
    if sees_everything(scene.camera, aspect, lo, hi):
        return None
    hits = camera_hits(scene, aspect, key)
    n = hits.shape[0]
    per = (samples[0] / (n - 1), samples[1] / (n - 1))  # samples between neighbouring rays
    footprint = sample_footprint(light_clip, hits, per)
    return fit_window(light_clip, hits.reshape(-1, 3), size, max_size, footprint)
