"""Where scattering lives in a frame: each pixel's surface point, the edge region around shadow and
light edges, and the profile of an image across a declared line or edge (docs/ledger.md "Edges and
profiles").

* :func:`pixel_points`: the surface point (the reference frame's millimetres) each pixel centre sees,
  ray-cast through the reference description's camera and meshes (trimesh with Embree), and the
  pixel's footprint in mm;
* :func:`edge_region`: pixels within ``edge_mm`` of an edge: a declared one (the scene's ``[measure]``
  profile: the edge, or the sides of a line of ``line_width_mm``) measured along the profile axis,
  else where the plain frame's luminance changes by more than ``EDGE_RATIO`` between neighbouring
  object pixels (shadow and light edges; also albedo edges of a textured surface), grown by
  ``edge_mm`` / the pixel footprint;
* :func:`profile`: the image averaged along the line or edge: per bin of the signed distance across
  it (``profile_axis``, bins one pixel footprint wide over +-``profile_range_mm``), the mean RGB of
  the object pixels in the bin; :func:`profile_error` the relative L1 between two profiles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

EDGE_RATIO = 2.0  # neighbouring pixels whose plain-frame luminance differs by more than this factor: an edge
EDGE_DIFFUSION_LENGTHS = 3.0  # default edge region: this many diffusion lengths (1 / sigma_tr) of the longest channel
DARK = 0.01  # luminances below this fraction of the 99th percentile count as this (shadow noise is no edge)


@dataclass
class PixelPoints:
    points: np.ndarray  # (H, W, 3) float64, reference frame (mm); NaN where the pixel sees no surface
    hit: np.ndarray  # (H, W) bool
    mm_per_pixel: float  # the median distance between horizontally neighbouring surface points
    frame_origin: np.ndarray  # world point at the frame's origin
    frame_scale: float  # mm per world unit

    def to_frame(self, world_point) -> np.ndarray:
        return (np.asarray(world_point, np.float64) - self.frame_origin) * self.frame_scale


def camera_rays(desc) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), directions (H, W, 3) unit) of the pixel centres, in the description's frame
    (Mitsuba's camera frame: column 0 is Skinlab's -X, column 2 forward)."""
    m = np.asarray(desc.camera_to_world, np.float64)
    w, h = desc.width, desc.height
    t = math.tan(math.radians(desc.fov_y_deg) / 2)
    x = (2 * (np.arange(w) + 0.5) / w - 1) * t * (w / h)
    y = (1 - 2 * (np.arange(h) + 0.5) / h) * t
    xx, yy = np.meshgrid(x, y)
    d = -xx[..., None] * m[:3, 0] + yy[..., None] * m[:3, 1] + m[:3, 2]
    return m[:3, 3], d / np.linalg.norm(d, axis=-1, keepdims=True)


def pixel_points(desc) -> PixelPoints:
    import trimesh

    origin, dirs = camera_rays(desc)
    h, w = dirs.shape[:2]
    pos, faces, off = [], [], 0
    for s in desc.shapes:
        pos.append(np.asarray(s.positions, np.float64))
        faces.append(np.asarray(s.faces, np.int64) + off)
        off += len(s.positions)
    points = np.full((h, w, 3), np.nan)
    if pos:
        mesh = trimesh.Trimesh(np.concatenate(pos), np.concatenate(faces), process=False)
        d = dirs.reshape(-1, 3)
        o = np.broadcast_to(origin, d.shape)
        loc, ray, _ = mesh.ray.intersects_location(o, d, multiple_hits=False)
        flat = points.reshape(-1, 3)
        flat[ray] = loc
    hit = np.isfinite(points[..., 0])
    both = hit[:, 1:] & hit[:, :-1]
    step = np.linalg.norm(points[:, 1:] - points[:, :-1], axis=-1)[both]
    mmpp = float(np.median(step)) if step.size else math.nan
    return PixelPoints(points, hit, mmpp, np.asarray(desc.frame_origin, np.float64), float(desc.frame_scale))


def across(px: PixelPoints, spec) -> tuple[np.ndarray, np.ndarray]:
    """(s, t): per pixel the signed distance (mm) across the declared line or edge (along
    ``profile_axis`` from ``profile_origin``) and the distance along it; NaN where no surface."""
    o = px.to_frame(spec.profile_origin)
    a = np.asarray(spec.profile_axis, np.float64)
    rel = px.points - o
    s = rel @ a
    t = np.linalg.norm(rel - s[..., None] * a, axis=-1)
    return s, t


def diffusion_length_mm(scene) -> float:
    """The longest 1 / sigma_tr (mm) over the channels of the scene's scattering materials (NaN: none)."""
    from skinlab.scene.optics.material_medium import material_medium

    best = math.nan
    for n in scene.mesh_nodes():
        m = n.material
        if m is None or not m.has_subsurface:
            continue
        st = np.asarray(material_medium(m.values).sigma_tr, np.float64)
        st = st[np.isfinite(st) & (st > 0)]
        if st.size:
            best = max(float(1.0 / st.min()), best) if math.isfinite(best) else float(1.0 / st.min())
    return best


def edge_width_mm(scene, spec) -> float:
    if spec is not None and spec.edge_mm is not None:
        return float(spec.edge_mm)
    ld = diffusion_length_mm(scene)
    return EDGE_DIFFUSION_LENGTHS * ld if math.isfinite(ld) else math.nan


def light_edges(plain: np.ndarray, mask: np.ndarray, ratio: float = EDGE_RATIO) -> np.ndarray:
    """(H, W) bool: object pixels whose plain-frame luminance differs from a neighbouring object pixel's
    by more than `ratio` (both floored at DARK x the 99th percentile)."""
    from .compare import REC709

    lum = plain[..., :3].astype(np.float64) @ REC709
    if not mask.any():
        return np.zeros(mask.shape, bool)
    lum = np.maximum(lum, DARK * float(np.percentile(lum[mask], 99)) + 1e-30)
    lg = np.log(lum)
    out = np.zeros(mask.shape, bool)
    thr = math.log(ratio)
    for ax in (0, 1):
        a = tuple(slice(1, None) if k == ax else slice(None) for k in range(2))
        b = tuple(slice(None, -1) if k == ax else slice(None) for k in range(2))
        jump = (np.abs(lg[a] - lg[b]) > thr) & mask[a] & mask[b]
        out[a] |= jump
        out[b] |= jump
    return out


def edge_region(
    mask: np.ndarray, width_mm: float, px: PixelPoints | None = None, spec=None, plain: np.ndarray | None = None
) -> np.ndarray:
    """(H, W) bool: the object pixels within width_mm of the declared edge (spec with a profile and
    pixel points) or of the plain frame's light edges (else)."""
    if not math.isfinite(width_mm):
        return np.zeros(mask.shape, bool)
    if spec is not None and spec.has_profile and px is not None:
        s, _ = across(px, spec)
        half = spec.line_width_mm / 2 if spec.profile == "line" else 0.0
        with np.errstate(invalid="ignore"):
            return mask & (np.abs(np.abs(s) - half) <= width_mm if half > 0 else np.abs(s) <= width_mm)
    if plain is None:
        return np.zeros(mask.shape, bool)
    from scipy.ndimage import distance_transform_edt

    edges = light_edges(plain, mask)
    if not edges.any():
        return edges
    mmpp = px.mm_per_pixel if px is not None and math.isfinite(px.mm_per_pixel) else 1.0
    return mask & (distance_transform_edt(~edges) * mmpp <= width_mm)


@dataclass
class Profile:
    x_mm: np.ndarray  # (N,) bin centres, signed distance across the line / edge
    rgb: np.ndarray  # (N, 3) mean linear RGB of the object pixels in each bin (NaN where none)
    count: np.ndarray  # (N,) pixels per bin


def profile(img: np.ndarray, px: PixelPoints, spec, mask: np.ndarray) -> Profile:
    s, t = across(px, spec)
    ok = mask & np.isfinite(s) & (np.abs(s) <= spec.profile_range_mm)
    if spec.profile_band_mm is not None:
        ok &= t <= spec.profile_band_mm
    width = max(px.mm_per_pixel if math.isfinite(px.mm_per_pixel) else 1.0, spec.profile_range_mm / 400)
    n = max(2, int(math.ceil(2 * spec.profile_range_mm / width)))
    edges = np.linspace(-spec.profile_range_mm, spec.profile_range_mm, n + 1)
    idx = np.clip(np.digitize(s[ok], edges) - 1, 0, n - 1)
    cnt = np.bincount(idx, minlength=n).astype(np.float64)
    rgb = np.stack(
        [np.bincount(idx, weights=img[..., c][ok].astype(np.float64), minlength=n) for c in range(3)], axis=1
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = rgb / cnt[:, None]
    return Profile((edges[:-1] + edges[1:]) / 2, mean, cnt.astype(np.int64))


def profile_error(a: Profile, b: Profile) -> float:
    """sum over bins and channels of |a - b| / sum of b (the bins both have), b the truth's."""
    ok = (a.count > 0) & (b.count > 0)
    den = b.rgb[ok].sum()
    return float(np.abs(a.rgb[ok] - b.rgb[ok]).sum() / den) if den > 0 else math.nan
