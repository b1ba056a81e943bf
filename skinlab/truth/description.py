"""A path-traced reference's scene description and its Mitsuba objects, with no dependency on the
scene graph: numpy and (when rendering) Mitsuba alone. ``skinlab/truth/export.py`` builds descriptions from
scenes; :func:`save` / :func:`load` carry one to another machine (a GPU rendering with
``cuda_ad_rgb``: ``tools/gpu_reference.py``), and :func:`path_trace` renders one in passes."""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

CHUNK_SPP = 32  # samples per pixel per render call (a progress bar's step; bounded memory)


def _rgb(v) -> dict:
    return {"type": "rgb", "value": [float(x) for x in np.asarray(v, np.float64).reshape(3)]}


@dataclass
class ShapeDesc:
    name: str
    material: str
    positions: np.ndarray  # (N, 3) float32, world units
    normals: np.ndarray  # (N, 3) float32, world, unit length
    faces: np.ndarray  # (M, 3) uint32
    texcoords: np.ndarray | None  # (N, 2) float32, Mitsuba convention (v = 0 at the image's top row)
    bsdf: dict
    interior: dict | None = None  # homogeneous medium, for subsurface materials
    texture: np.ndarray | None = None  # baked linear base colour (H, W, 3), row 0 at the top
    opacity: np.ndarray | None = None  # (H, W, 1) the mask BSDF's opacity (alpha modes), row 0 at the top


@dataclass
class ReferenceDescription:
    width: int
    height: int
    camera_to_world: np.ndarray  # (4, 4) Mitsuba camera frame: +X left, +Y up, +Z forward
    fov_y_deg: float
    near: float
    far: float
    shapes: list[ShapeDesc]
    emitters: list[dict]
    integrator: dict
    notes: list[str] = field(default_factory=list)
    # the reference frame: x_ref = (x_world - frame_origin) * frame_scale (millimetres, centred)
    frame_origin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    frame_scale: float = 1.0
    # the environment map's pixels (H, W, 3) float32, row 0 at the top, for an "envmap" emitter
    environment: np.ndarray | None = None

    def content(self) -> dict:
        """Everything that determines the image, as JSON-able data plus arrays (for the cache key)."""
        return {
            "size": [self.width, self.height],
            "camera": np.round(self.camera_to_world, 9).tolist(),
            "frame": [np.round(self.frame_origin, 9).tolist(), self.frame_scale],
            "fov": self.fov_y_deg,
            "clip": [self.near, self.far],
            "emitters": self.emitters,
            "integrator": self.integrator,
            "shapes": [
                {"name": s.name, "bsdf": s.bsdf, "interior": s.interior, "material": s.material} for s in self.shapes
            ],
        }

    def arrays(self) -> list[np.ndarray]:
        out = []
        for s in self.shapes:
            out += [s.positions, s.normals, s.faces]
            if s.texcoords is not None:
                out.append(s.texcoords)
            if s.texture is not None:
                out.append(s.texture)
            if s.opacity is not None:
                out.append(s.opacity)
        if self.environment is not None:
            out.append(self.environment)
        return out

    def to_mitsuba(self, spp: int, seed: int = 0) -> dict:
        """The dictionary for ``mitsuba.load_dict`` (a Mitsuba variant must be set)."""
        import mitsuba as mi

        scene: dict = {"type": "scene", "integrator": dict(self.integrator)}
        scene["sensor"] = {
            "type": "perspective",
            "fov": self.fov_y_deg,
            "fov_axis": "y",
            "near_clip": self.near,
            "far_clip": self.far,
            "to_world": mi.ScalarTransform4f(self.camera_to_world.tolist()),
            "sampler": {"type": "independent", "sample_count": int(spp), "seed": int(seed)},
            "film": {
                "type": "hdrfilm",
                "width": self.width,
                "height": self.height,
                "pixel_format": "rgba",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
        }
        for i, e in enumerate(self.emitters):
            scene[f"emitter{i}"] = mitsuba_emitter(mi, e, self.environment)
        for i, s in enumerate(self.shapes):
            scene[f"shape{i}"] = _mitsuba_mesh(mi, s)
        return scene


# -- Mitsuba objects ------------------------------------------------------------------------------------


def mitsuba_emitter(mi, e: dict, environment: np.ndarray | None = None) -> dict:
    if e["kind"] == "envmap":
        # the same axes as Skinlab's (skinlab/scene/envmap.py); rotation_deg about +Y as the frame turns it
        if environment is None:
            raise ReferenceError("an envmap emitter needs the description's environment pixels")
        return {
            "type": "envmap",
            "bitmap": mi.Bitmap(np.ascontiguousarray(environment, np.float32)),
            "scale": float(e["scale"]),
            "to_world": mi.ScalarTransform4f().rotate([0.0, 1.0, 0.0], float(e["rotation_deg"])),
        }
    if e["kind"] == "directional":
        return {"type": "directional", "direction": e["direction"], "irradiance": _rgb(e["irradiance"])}
    if e["kind"] == "point":
        return {"type": "point", "position": e["position"], "intensity": _rgb(e["intensity"])}
    if e["kind"] == "spot":
        p, d = np.asarray(e["position"]), np.asarray(e["direction"])
        return {
            "type": "spot",
            "to_world": mi.ScalarTransform4f().look_at(origin=p.tolist(), target=(p + d).tolist(), up=_any_up(d)),
            "intensity": _rgb(e["intensity"]),
            "cutoff_angle": float(e["cutoff_deg"]),
            "beam_width": float(e["beam_deg"]),
        }
    black = {"type": "diffuse", "reflectance": _rgb([0.0, 0.0, 0.0])}
    if e["kind"] == "sphere":
        return {
            "type": "sphere",
            "center": list(e["centre"]),
            "radius": float(e["radius"]),
            "bsdf": black,
            "emitter": {"type": "area", "radiance": _rgb(e["radiance"])},
        }
    if e["kind"] == "rect":
        return {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f(rect_to_world(e).tolist()),
            "bsdf": black,
            "emitter": {"type": "area", "radiance": _rgb(e["radiance"])},
        }
    if e["kind"] == "constant":
        return {"type": "constant", "radiance": _rgb(e["radiance"])}
    if e["kind"] == "sun_disk":
        c, n = np.asarray(e["centre"]), np.asarray(e["normal"])
        # Mitsuba's disk lies in z = 0 facing +z: scale by the radius, turn +z onto n, move to c
        to_world = mi.ScalarTransform4f().look_at(origin=c.tolist(), target=(c + n).tolist(), up=_any_up(n))
        to_world = to_world @ mi.ScalarTransform4f().scale([e["radius"]] * 3)
        return {"type": "disk", "to_world": to_world, "emitter": {"type": "area", "radiance": _rgb(e["radiance"])}}
    raise ReferenceError(f"emitter kind {e['kind']!r} unknown")


def rect_to_world(e: dict) -> np.ndarray:
    """(4, 4) the transform of Mitsuba's rectangle ([-1, 1]^2 in z = 0, emitting toward +z) onto a rect
    light: columns the half-width and half-height vectors and the way it shines (right-handed), the centre."""
    ex, ey, n = (np.asarray(e[k], np.float64) for k in ("ex", "ey", "normal"))
    if np.dot(np.cross(ex, ey), n) < 0:
        ey = -ey
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = ex, ey, n / np.linalg.norm(n), e["centre"]
    return m


def _any_up(n: np.ndarray) -> list[float]:
    return [0.0, 0.0, 1.0] if abs(n[1]) > 0.9 else [0.0, 1.0, 0.0]


def _mitsuba_bsdf(mi, s: ShapeDesc) -> dict:
    b = dict(s.bsdf)
    if b["type"] == "mask":  # alpha modes: the opacity (a value or the baked texture) around the surface's BSDF
        inner = _mitsuba_bsdf(mi, ShapeDesc(**{**s.__dict__, "bsdf": b["bsdf"]}))
        op = b["opacity"]
        if isinstance(op, dict) and op.get("type") == "opacity_ref":
            op = {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(s.opacity)), "raw": True}
        return {"type": "mask", "opacity": op, "bsdf": inner}
    if b["type"] == "twosided" and b["bsdf"].get("base_color", {}).get("type") == "texture_ref":
        inner = dict(b["bsdf"])
        inner["base_color"] = {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(s.texture)), "raw": True}
        b = {"type": "twosided", "bsdf": inner}
    return b


def _mitsuba_mesh(mi, s: ShapeDesc):
    has_uv = s.texcoords is not None
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(_mitsuba_bsdf(mi, s))
    if s.interior is not None:
        props["interior"] = mi.load_dict(s.interior)
    mesh = mi.Mesh(
        s.name, vertex_count=len(s.positions), face_count=len(s.faces), props=props,
        has_vertex_normals=True, has_vertex_texcoords=has_uv,
    )  # fmt: skip
    p = mi.traverse(mesh)
    fl, ui = type(p["vertex_positions"]), type(p["faces"])
    p["vertex_positions"] = fl(np.ascontiguousarray(s.positions, np.float32).ravel())
    p["vertex_normals"] = fl(np.ascontiguousarray(s.normals, np.float32).ravel())
    p["faces"] = ui(np.ascontiguousarray(s.faces, np.uint32).ravel())
    if has_uv:
        p["vertex_texcoords"] = fl(np.ascontiguousarray(s.texcoords, np.float32).ravel())
    p.update()
    return mesh


# -- carrying a description to another machine -------------------------------------------------------

_ARRAYS = ("positions", "normals", "faces", "texcoords", "texture", "opacity")


def save(desc: ReferenceDescription, path: Path) -> None:
    """Everything :func:`load` needs, in one .npz (arrays and a JSON header)."""
    header = {
        "width": desc.width,
        "height": desc.height,
        "camera_to_world": np.asarray(desc.camera_to_world).tolist(),
        "fov_y_deg": desc.fov_y_deg,
        "near": desc.near,
        "far": desc.far,
        "emitters": desc.emitters,
        "integrator": desc.integrator,
        "notes": desc.notes,
        "frame_origin": np.asarray(desc.frame_origin).tolist(),
        "frame_scale": desc.frame_scale,
        "shapes": [
            {"name": s.name, "material": s.material, "bsdf": s.bsdf, "interior": s.interior} for s in desc.shapes
        ],
    }
    arrays: dict[str, Any] = {"header": np.frombuffer(json.dumps(header, default=float).encode(), np.uint8)}
    if desc.environment is not None:
        arrays["environment"] = desc.environment
    for i, s in enumerate(desc.shapes):
        for a in _ARRAYS:
            v = getattr(s, a)
            if v is not None:
                arrays[f"shape{i}_{a}"] = v
    with open(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)


def load(path: Path) -> ReferenceDescription:
    with np.load(path) as z:
        header = json.loads(bytes(z["header"]).decode())
        shapes = []
        for i, s in enumerate(header["shapes"]):
            arr: dict[str, Any] = {a: (z[f"shape{i}_{a}"] if f"shape{i}_{a}" in z else None) for a in _ARRAYS}
            shapes.append(ShapeDesc(s["name"], s["material"], bsdf=s["bsdf"], interior=s["interior"], **arr))
        environment = z["environment"] if "environment" in z else None
    return ReferenceDescription(
        header["width"],
        header["height"],
        np.asarray(header["camera_to_world"]),
        header["fov_y_deg"],
        header["near"],
        header["far"],
        shapes,
        header["emitters"],
        header["integrator"],
        header["notes"],
        np.asarray(header["frame_origin"]),
        header["frame_scale"],
        environment,
    )


# -- rendering -------------------------------------------------------------------------------------------


def chunk_plan(spp: int, passes: int, chunk: int = CHUNK_SPP) -> list[tuple[int, int]]:
    """(pass index, samples) per render call: each pass gets spp // passes samples (the first
    spp % passes passes one more), split into chunks of at most `chunk`."""
    out = []
    for p in range(passes):
        n = spp // passes + (1 if p < spp % passes else 0)
        k = max(1, math.ceil(n / chunk))
        out += [(p, n // k + (1 if i < n % k else 0)) for i in range(k)]
    return out


def pass_seed(seed: int, index: int, chunk: int) -> int:
    """Mitsuba's sampler seed for render call `chunk` of pass `index` of a series seeded `seed`: a pass
    is the same whatever else the series holds (so passes saved by different runs add up)."""
    return (seed * 1_000_003 + index * 65_537 + chunk) % (1 << 32)


def render_pass(desc: ReferenceDescription, spp: int, seed: int, index: int, progress=None, chunk: int = CHUNK_SPP,
                mscene=None):  # fmt: skip
    """(image, seconds): pass `index` of the series seeded `seed`, `spp` samples per pixel in render calls
    of at most `chunk` (Mitsuba's variant already set; `mscene` a scene loaded from `desc` to reuse).
    The image is the pass's mean, float32 (H, W, 4)."""
    import mitsuba as mi

    t0 = time.perf_counter()
    if mscene is None:
        mscene = mi.load_dict(desc.to_mitsuba(CHUNK_SPP, seed))
    k = max(1, math.ceil(spp / chunk))
    acc = np.zeros((desc.height, desc.width, 4), np.float64)
    for c in range(k):
        n = spp // k + (1 if c < spp % k else 0)
        # Mitsuba's stubs type the seed as drjit's UInt32; it takes a Python int (pass_seed: below 2^32)
        img = mi.render(mscene, spp=n, seed=pass_seed(seed, index, c))  # type: ignore[arg-type]
        acc += np.asarray(img, np.float64) * n
        if progress is not None:
            progress(n)
    return (acc / spp).astype(np.float32), time.perf_counter() - t0


def path_trace(desc: ReferenceDescription, spp: int, passes: int, seed: int, progress=None, chunk: int = CHUNK_SPP):
    """(mean, half_a, half_b, seconds): `desc` rendered by Mitsuba (its variant already set) in
    `passes` passes of different seeds, each in render calls of at most `chunk` samples per pixel;
    the halves are the means of the first and the second half of the passes (the noise floor).
    ``progress(n)`` is called after each call of n samples."""
    import mitsuba as mi

    t0 = time.perf_counter()
    mscene = mi.load_dict(desc.to_mitsuba(CHUNK_SPP, seed))
    sums = np.zeros((passes, desc.height, desc.width, 4), np.float64)
    counts = np.zeros(passes, np.int64)
    for i, (p, n) in enumerate(chunk_plan(spp, passes, chunk)):
        img = np.asarray(mi.render(mscene, spp=n, seed=seed * 1_000_003 + i), np.float64)  # type: ignore[arg-type]
        sums[p] += img * n
        counts[p] += n
        if progress is not None:
            progress(n)
    half = passes // 2
    mean = (sums.sum(0) / counts.sum()).astype(np.float32)
    a = (sums[:half].sum(0) / counts[:half].sum()).astype(np.float32)
    b = (sums[half:].sum(0) / counts[half:].sum()).astype(np.float32)
    return mean, a, b, time.perf_counter() - t0
