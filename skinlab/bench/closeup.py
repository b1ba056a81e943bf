"""What the close-up reference scenes were made to measure (issue 21; docs/ground-truth.md "Close-ups",
docs/ledger.md "Close-ups in the ledger"), shared by the accuracy ledger (skinlab/bench/truth_ledger.py)
and tools/closeup_table.py. A scene says which apply in its ``[measure]`` table:

* ``profile = "line"`` (a slit): the tails, the share of the light in view farther than 2, 5 and 10 mm
  from the line (``TAIL_MM``), of luminance and of each channel alone (``CHANNELS``: skin's red diffuses
  about 5 times as far as its blue, which a luminance tail hides);
* ``deep_shadow = true``: the deep shadow's level: the mean luminance of camera-visible points the first
  light does not reach, more than ``DEEP_SHADOW_MM`` from a lit one (found by ray casting with Embree,
  independent of the shadow maps), as a share of the lit surface's (farther than that from the shadow);
* ``mesh_energy = true``: each visible mesh's energy apart (its pixels found by ray casting), per channel
  (light through one part and through another: the two back-lit slabs).

Every measure here is of one image; the ledger's columns are the frame's value minus the truth's, with
the standard error from the truth's passes (the jackknife, skinlab/truth/metrics.py)."""

from __future__ import annotations

import math

import numpy as np

TAIL_MM = (2.0, 5.0, 10.0)
CHANNELS = "rgb"  # the per-channel tails' column suffixes (tail_key)
DEEP_SHADOW_MM = 2.0  # deep shadow: more than this from any lit point (the red diffusion length is 2.3 mm)
EDGE_MM = 3.0  # edge region: within this of the shadow's edge, both sides
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709


def luminance(img: np.ndarray) -> np.ndarray:
    return np.asarray(img[..., :3], np.float64) @ LUMINANCE


def line_profile(img: np.ndarray) -> np.ndarray:
    """(W, 3): the image averaged along the slit (its rows)."""
    return np.asarray(img[..., :3], np.float64).mean(axis=0)


def profile_error(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).sum() / max(np.abs(b).sum(), 1e-30))


def tail_shares(values: np.ndarray, dist_mm: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """(len(TAIL_MM), ...) the share of `values` (per pixel: (H, W) or (H, W, C)) over `mask` whose
    distance from the line (`dist_mm`, (H, W), signed or not) is more than each of TAIL_MM."""
    v = np.asarray(values, np.float64)
    d = np.abs(np.asarray(dist_mm, np.float64))
    m = np.isfinite(d) if mask is None else (np.asarray(mask, bool) & np.isfinite(d))
    tot = np.maximum(v[m].sum(axis=0), 1e-30)
    return np.array([v[m & (d > t)].sum(axis=0) / tot for t in TAIL_MM])


def tail_fractions(profile: np.ndarray, mm_per_px: float) -> np.ndarray:
    """(len(TAIL_MM), 3): the fraction of each channel's light in view farther than each distance
    from the slit (the middle of the image), of a line profile (W, 3) whose columns are mm_per_px apart."""
    w = profile.shape[0]
    x = (np.arange(w) + 0.5 - w / 2) * mm_per_px
    return tail_shares(np.asarray(profile)[None], x[None])


def camera_rays(scene, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Origins and unit directions (H*W, 3) through the pixels' centres, row 0 at the top."""
    cam = scene.camera
    m = np.asarray(cam.world_matrix, np.float64)
    t = math.tan(cam.yfov / 2)
    aspect = width / height
    jj, ii = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    x = ((ii + 0.5) / width * 2 - 1) * t * aspect
    y = (1 - (jj + 0.5) / height * 2) * t
    d = np.stack([x, y, -np.ones_like(x)], -1).reshape(-1, 3) @ m[:3, :3].T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.broadcast_to(m[:3, 3], d.shape).copy(), d


def _scene_mesh(scene):
    """The visible mesh nodes as one trimesh (world space) and each triangle's node index."""
    import trimesh

    from skinlab.scene.interreflection import world_geometry

    nodes = scene.mesh_nodes()
    pos, faces, owner, start = [], [], [], 0
    for k, node in enumerate(nodes):
        p, _ = world_geometry(node)
        pos.append(p)
        faces.append(node.mesh.indices.astype(np.int64) + start)
        owner.append(np.full(len(node.mesh.indices), k))
        start += len(p)
    mesh = trimesh.Trimesh(np.concatenate(pos), np.concatenate(faces), process=False)
    return mesh, np.concatenate(owner)


def ray_geometry(scene, width: int, height: int):
    """Per pixel: the index of the visible mesh node (scene.mesh_nodes()) its centre sees (-1: none) and
    whether the first light reaches that point (a shadow ray toward it; Embree through trimesh)."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    mesh, owners = _scene_mesh(scene)
    ray = RayMeshIntersector(mesh)
    o, d = camera_rays(scene, width, height)
    tri, idx, loc = ray.intersects_id(o, d, multiple_hits=False, return_locations=True)
    node = np.full(len(o), -1)
    node[idx] = owners[tri]
    light = scene.lights()[0]
    lit = np.zeros(len(o), bool)
    if len(idx):
        nrm = mesh.face_normals[tri]
        nrm = np.where((np.einsum("ij,ij->i", nrm, d[idx]) > 0)[:, None], -nrm, nrm)
        if light.kind == "directional":
            to = np.broadcast_to(-light.direction, loc.shape)
            far = np.full(len(loc), np.inf)
        else:
            v = light.world_position - loc
            far = np.linalg.norm(v, axis=1)
            to = v / far[:, None]
        facing = np.einsum("ij,ij->i", nrm, to) > 0
        eps = 1e-4 * float(np.linalg.norm(mesh.bounds[1] - mesh.bounds[0]))
        t2, i2, l2 = ray.intersects_id(loc + nrm * eps, to, multiple_hits=False, return_locations=True)
        blocked = np.zeros(len(loc), bool)
        if len(i2):
            blocked[i2] = np.linalg.norm(l2 - loc[i2], axis=1) < far[i2]
        lit[idx] = facing & ~blocked
    return node.reshape(height, width), lit.reshape(height, width)


def mm_per_pixel(scene, width: int, height: int) -> np.ndarray:
    """Approximate millimetres per pixel at each pixel's visible point (distance x pixel angle)."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    mesh, _ = _scene_mesh(scene)
    o, d = camera_rays(scene, width, height)
    _, idx, loc = RayMeshIntersector(mesh).intersects_id(o, d, multiple_hits=False, return_locations=True)
    dist = np.full(len(o), np.nan)
    dist[idx] = np.linalg.norm(loc - o[idx], axis=1)
    return (dist * 2 * math.tan(scene.camera.yfov / 2) / height * scene.mm_per_unit).reshape(height, width)


def region_error(img, ref, mask) -> float:
    a, b = np.asarray(img[..., :3], np.float64)[mask], np.asarray(ref[..., :3], np.float64)[mask]
    return float(np.abs(a - b).sum() / max(b.sum(), 1e-30))


def region_level(img, mask, lit) -> float:
    """Mean luminance over `mask` relative to the mean over `lit` (NaN where either is empty)."""
    if not np.any(mask) or not np.any(lit):
        return math.nan
    lum = luminance(img)
    return float(lum[mask].mean() / max(lum[lit].mean(), 1e-30))


def shadow_regions(scene, size):
    """(deep shadow, lit, edge region) masks for a shadow scene at `size` (W, H)."""
    from scipy.ndimage import distance_transform_edt

    node, lit = ray_geometry(scene, *size)
    mm = np.nanmedian(mm_per_pixel(scene, *size))
    seen = node >= 0
    to_lit = distance_transform_edt(~lit) * mm
    to_shadow = distance_transform_edt(lit | ~seen) * mm
    deep = seen & ~lit & (to_lit > DEEP_SHADOW_MM)
    lit_far = lit & (to_shadow > DEEP_SHADOW_MM)
    edge = seen & (np.where(lit, to_shadow, to_lit) <= EDGE_MM)
    return deep, lit_far, edge


def mesh_energies(img: np.ndarray, ref: np.ndarray, meshes: dict[str, np.ndarray]) -> dict[str, list[float]]:
    """Per mesh (name -> its pixels): the relative difference of each channel's sum, img against ref."""
    from skinlab.truth.compare import image_error

    return {name: list(image_error(img, ref, mask=m)["energy"]) for name, m in meshes.items()}


def entry_name(node) -> str:
    """The name of the scene's top-level node a mesh node belongs to (a scene file's [[meshes]] entry)."""
    while node.parent is not None and node.parent.parent is not None:
        node = node.parent
    return node.name


def largest(values) -> float:
    """The value of largest magnitude (signed; NaN where none is finite)."""
    vals = [v for v in values if math.isfinite(v)]
    return max(vals, key=abs) if vals else math.nan


# -- the ledger's close-up regions and measures ----------------------------------------------------------


class CloseupRegions:
    """What a scene's declared close-up measures need, found once per scene at the truth's size: the
    distance across the line (tails), the deep shadow and lit masks, the visible meshes' pixels.
    ``notes``: what could not be found (no ray caster, an empty region)."""

    def __init__(self, scene, spec, size: tuple[int, int], across_mm: np.ndarray | None, mask: np.ndarray):
        self.mask = mask
        self.across = across_mm if spec is not None and spec.has_tails else None
        self.deep = self.lit = None
        self.meshes: dict[str, np.ndarray] = {}
        self.notes: list[str] = []
        if spec is None:
            return
        if spec.has_tails and across_mm is None:
            self.notes.append("tails: no ray caster for the pixels' distance across the line")
        try:
            if spec.deep_shadow:
                deep, lit, _ = shadow_regions(scene, size)
                if deep.any() and lit.any():
                    self.deep, self.lit = deep, lit
                else:
                    self.notes.append("deep shadow: no deep-shadow or no lit pixels in view")
            if spec.mesh_energy:
                node, _ = ray_geometry(scene, *size)
                for k, n in enumerate(scene.mesh_nodes()):
                    name = entry_name(n)
                    self.meshes[name] = self.meshes.get(name, np.zeros(node.shape, bool)) | (node == k)
                self.meshes = {n: m for n, m in self.meshes.items() if m.any()}
        except ImportError as exc:
            self.notes.append(f"no ray caster ({exc})")

    @property
    def any(self) -> bool:
        return self.across is not None or self.deep is not None or bool(self.meshes)

    def values(self, img: np.ndarray) -> dict[str, float]:
        """The image's own close-up measures (fractions): tail shares of luminance and of each channel (its
        own light's share: 0 for a channel without light), the deep shadow level."""
        out: dict[str, float] = {}
        if self.across is not None:
            shares = tail_shares(luminance(img), self.across, self.mask)
            out.update({tail_key(d): float(v) for d, v in zip(TAIL_MM, shares)})
            each = tail_shares(img[..., :3], self.across, self.mask)  # (len(TAIL_MM), 3)
            out.update({tail_key(d, c): float(v) for d, row in zip(TAIL_MM, each) for c, v in zip(CHANNELS, row)})
        if self.deep is not None:
            out["truth_deep_shadow"] = region_level(img, self.deep, self.lit)
        return out

    def measures(self, img: np.ndarray) -> dict:
        """The ledger's close-up measures of a frame as functions of a truth image (frame minus truth),
        for the jackknife: column -> fn(truth image) -> float."""
        mine = self.values(img)
        out = {k: (lambda t, k=k, v=v: v - self.values(t)[k]) for k, v in mine.items()}
        if self.meshes:
            # the magnitude (not signed): a signed largest flips between two channels of about equal and
            # opposite difference from one group of the truth's passes to the next (a spurious uncertainty)
            out["truth_mesh_energy"] = lambda t: abs(
                largest([x for e in mesh_energies(img, t, self.meshes).values() for x in e])
            )
        return out

    def mesh_text(self, img: np.ndarray, truth: np.ndarray) -> str:
        """Each mesh's energy against the truth's per channel, in words ("front -3.1/-2.0/-1.5 %; ...")."""
        e = mesh_energies(img, truth, self.meshes)
        return "; ".join(f"{n} " + "/".join(f"{100 * x:+.1f}" for x in v) + " %" for n, v in e.items())


def tail_key(mm: float, channel: str = "") -> str:
    """The ledger's column of the tail beyond `mm`: of luminance ("truth_tail_2mm"), or of one of CHANNELS
    alone ("truth_tail_2mm_r")."""
    assert channel in ("", *CHANNELS), channel
    return f"truth_tail_{mm:g}mm" + (f"_{channel}" if channel else "")


TAIL_KEYS = tuple(tail_key(d) for d in TAIL_MM)
TAIL_CHANNEL_KEYS = tuple(tail_key(d, c) for d in TAIL_MM for c in CHANNELS)
CLOSEUP_KEYS = (*TAIL_KEYS, *TAIL_CHANNEL_KEYS, "truth_deep_shadow", "truth_mesh_energy")
