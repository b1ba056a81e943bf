"""Environment maps: an HDR image of the light arriving from every direction (``[environment] map``),
loaded, checked and prepared for the frame once per file content (no GL here).

**The map.** Equirectangular (latitude-longitude), linear radiance, 2:1, at least 8 x 4 texels, in
Mitsuba 3's axes, so the path-traced truth reads the same file the same way (skinlab/truth/export.py):
a map direction d is at u = atan2(d.x, -d.z) / 2 pi, v = acos(d.y) / pi, row 0 at the top (+Y up),
the image's centre column toward +Z (behind a camera that looks down -Z), a quarter to its right
toward -X. ``rotation_deg`` turns the map about +Y, counter-clockwise seen from above (the right-hand
rule): a world direction w reads the map at R_y(-rotation) w. ``intensity`` scales its radiance.
A map with NaN or Inf texels, not 2:1, smaller than 8 x 4 (a 1 x 1 "map": use ``ambient`` for a uniform
sky), unreadable or missing is refused with one line naming the file; negative texels are set to 0
(and the plan says how many); an all-black map is no light (the plan skips it).

**Preparation** (:func:`prepare`, cached in memory and under ``$SKINLAB_CACHE_DIR/environment/`` by
the file's content and the preparation's version, since it takes a second or two):

1. *Bright small sources* (a sun, a studio lamp): a texel at 30,000 among texels near 1 would be a
   firefly in any filter with a few samples and rings in 9 SH coefficients. Texels above
   ``SOURCE_THRESHOLD`` times the map's mean radiance are grouped into connected regions (across the
   u seam too); each region that carries at least ``SOURCE_MIN_POWER`` of the map's power and
   subtends at most ``SOURCE_MAX_RADIUS_DEG`` becomes a directional light (up to ``MAX_SOURCES``, the
   brightest first): its direction the power-weighted mean of the texels', its irradiance what the
   texels above the threshold bring (each texel keeps the threshold's luminance in its own colour, so
   nothing is lost or counted twice), its angular radius that of a cap of the region's solid angle.
   The frame renders it as a light with a shadow map (the soft shadow of its size); the rest of the map
   is prefiltered.
2. *Diffuse*: the rest's irradiance for every normal, an exact cosine convolution on 64 x 32 texels
   (skinlab/scene/optics/split_sum.py ``irradiance_map``), and its radiance in 9 spherical-harmonic
   coefficients (skinlab/scene/optics/sh.py) for what the scene hides of it; and the rest convolved
   with the zonal kernels of the light a medium takes from it (``kernel_maps``: the single scattering
   of an index-matched medium toward 17 view cosines, and the t^2, t^3 kernels of the light entering
   its multiple scattering), 19 layers of 64 x 32.
3. *Specular*: the rest prefiltered into ``LEVELS`` GGX levels and the split-sum table
   (skinlab/scene/optics/split_sum.py).

A uniform map (every texel the same) needs no prefilter: one radiance is its SH and its every level.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .optics import sh, split_sum
from .optics.constants import LUMA_B, LUMA_G, LUMA_R

PREPARE_VERSION = 3  # bump when preparation changes what it makes (the disk cache's key)
MIN_WIDTH, MIN_HEIGHT = 8, 4
SOURCE_THRESHOLD = 20.0  # x the map's mean radiance: texels above it may form a source
SOURCE_MIN_POWER = 0.02  # a source carries at least this share of the map's power (luminance)
SOURCE_MAX_RADIUS_DEG = 10.0  # and subtends at most this (a cap of the same solid angle)
MAX_SOURCES = 2  # as many as the frame has shadow slots (skinlab/render/lights.py SHADOW_SLOTS)
LUMA = np.array([LUMA_R, LUMA_G, LUMA_B])
HDRI_SUFFIXES = (".exr", ".hdr")


class EnvironmentMapError(ValueError):
    """The map cannot be used (the message names the file and what was expected)."""


@dataclass
class Source:
    """A bright small region of a map, lit as a directional light (map frame)."""

    direction: np.ndarray  # (3,) unit, toward the source
    irradiance: np.ndarray  # (3,) on a surface facing it, at intensity 1
    solid_angle: float  # steradians
    texels: int

    @property
    def angular_radius(self) -> float:
        """Radians: the half-angle of a cap of the same solid angle."""
        return math.acos(max(-1.0, 1.0 - self.solid_angle / (2.0 * math.pi)))


@dataclass
class PreparedMap:
    """What the frame needs of a map (all in the map's frame, at intensity 1)."""

    key: str  # the file's content and the preparation's version (prepared_key)
    name: str
    width: int
    height: int
    sh: np.ndarray  # (9, 3) radiance coefficients of the map without its sources
    levels: list[np.ndarray]  # prefiltered radiance, level k: roughness k / (len - 1); one level when uniform
    sources: list[Source] = field(default_factory=list)
    # (h, w, 3) the irradiance on a surface of each texel's normal (exact, of the map without its
    # sources); None: from the SH coefficients
    irradiance: np.ndarray | None = None
    uniform: bool = False  # every texel the same: no prefilter
    black: bool = False  # no light at all
    negative_texels: int = 0  # set to 0 on loading
    seconds: float = 0.0  # time the preparation took (0 when it came from a cache)
    cached: str = ""  # "", "memory" or "disk"
    # (split_sum.KERNEL_LAYERS, h, w, 3) the rest's kernel maps (split_sum.kernel_maps); None: not made
    kernels: np.ndarray | None = None

    @property
    def power(self) -> float:
        """Mean luminance of the map over the sphere (sources included)."""
        e = sum(float(LUMA @ s.irradiance) for s in self.sources)
        return float(LUMA @ self.sh[0]) * sh.SH_C0 + e / (4.0 * math.pi)


# -- finding and reading a map ----------------------------------------------------------------------


def bundled_maps() -> dict[str, Path]:
    """The maps shipped with Skinlab (skinlab/assets/hdri/), by name."""
    from skinlab.resources import asset_path

    root = asset_path("hdri")
    return {p.stem: p for p in sorted(root.iterdir()) if p.suffix.lower() in HDRI_SUFFIXES} if root.is_dir() else {}


def resolve_map(value: str | Path, base: Path | None = None) -> Path:
    """A map file: a path (relative to `base`), or the name of a bundled map (``"studio"``)."""
    p = Path(value)
    if not p.suffix and str(value) in bundled_maps():
        return bundled_maps()[str(value)]
    if not p.is_absolute() and base is not None:
        p = base / p
    p = p.resolve()
    if not p.is_file():
        names = ", ".join(bundled_maps()) or "none"
        raise EnvironmentMapError(f"environment map not found: {p} (bundled maps by name: {names})")
    if p.suffix.lower() not in HDRI_SUFFIXES:
        raise EnvironmentMapError(f"environment map {p}: expected a linear HDR image (.exr or .hdr), got {p.suffix!r}")
    return p


_PIXELS: dict[tuple, tuple[np.ndarray, int]] = {}


def _stamp(path: Path) -> tuple:
    st = path.stat()
    return (str(path), st.st_mtime_ns, st.st_size)


def load_pixels(path: str | Path) -> tuple[np.ndarray, int]:
    """(H, W, 3) float32 linear radiance, row 0 at the top, and how many negative texels were set to 0."""
    path = Path(path)
    if not path.is_file():
        raise EnvironmentMapError(f"environment map not found: {path}")
    key = _stamp(path)
    if key in _PIXELS:
        return _PIXELS[key]
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise EnvironmentMapError(f"environment map {path}: cannot read it: {oiio.geterror().strip()}")
    try:
        spec = inp.spec()
        data = inp.read_image(0, 0, 0, spec.nchannels, "float")
        if data is None or inp.has_error:
            raise EnvironmentMapError(f"environment map {path}: cannot decode it: {inp.geterror().strip()}")
    finally:
        inp.close()
    img = np.asarray(data, np.float32).reshape(spec.height, spec.width, spec.nchannels)
    h, w, c = img.shape
    if c == 2 or c == 0:
        raise EnvironmentMapError(f"environment map {path}: {c} channels, expected 1 (grey), 3 (RGB) or 4 (RGBA)")
    img = np.repeat(img, 3, axis=2) if c == 1 else img[..., :3]
    if w != 2 * h:
        raise EnvironmentMapError(
            f"environment map {path}: {w}x{h} texels, expected an equirectangular (latitude-longitude) map "
            "twice as wide as it is high"
        )
    if h < MIN_HEIGHT:
        raise EnvironmentMapError(
            f"environment map {path}: {w}x{h} texels, expected at least {MIN_WIDTH}x{MIN_HEIGHT} "
            "(for a uniform sky use [environment] ambient)"
        )
    bad = ~np.isfinite(img)
    if bad.any():
        j, i, _ = np.argwhere(bad)[0]
        raise EnvironmentMapError(
            f"environment map {path}: {int(bad.any(2).sum())} texel(s) are NaN or Inf (the first at column {i}, "
            f"row {j}); expected finite linear radiance"
        )
    negative = int((img < 0).any(2).sum())
    if negative:
        img = np.maximum(img, 0.0)
    img = np.ascontiguousarray(img, np.float32)
    if len(_PIXELS) > 8:
        _PIXELS.pop(next(iter(_PIXELS)))
    _PIXELS[key] = (img, negative)
    return img, negative


_KEYS: dict[tuple, str] = {}


def map_key(path: str | Path) -> str:
    """The map file's content key (a hash of its bytes), cached per file state."""
    path = Path(path)
    stamp = _stamp(path)
    key = _KEYS.get(stamp)
    if key is None:
        key = _KEYS[stamp] = hashlib.sha256(path.read_bytes()).hexdigest()[:32]
    return key


def prepared_key(path: str | Path) -> str:
    """What a preparation depends on: the map's content and the preparation's version."""
    return f"{map_key(path)}-v{PREPARE_VERSION}"


# -- preparing ---------------------------------------------------------------------------------------


def extract_sources(img: np.ndarray, max_sources: int = MAX_SOURCES) -> tuple[list[Source], np.ndarray]:
    """The map's bright small sources (module docstring) and the map without them."""
    from scipy import ndimage

    h, w, _ = img.shape
    omega = split_sum.texel_solid_angles(w, h)
    lum = img.astype(np.float64) @ LUMA
    total = float((lum * omega).sum())
    if total <= 0.0 or max_sources <= 0:
        return [], img
    threshold = SOURCE_THRESHOLD * total / (4.0 * math.pi)
    labels, count = ndimage.label(lum > threshold, structure=np.ones((3, 3)))
    if count == 0:
        return [], img
    # regions touching across the u seam (column 0 and column W - 1) are one
    parent = np.arange(count + 1)

    def root(a: int) -> int:
        while parent[a] != a:
            a = parent[a]
        return a

    for j in range(h):
        for jj in (j - 1, j, j + 1):
            if 0 <= jj < h and labels[j, 0] and labels[jj, w - 1]:
                a, b = root(labels[j, 0]), root(labels[jj, w - 1])
                parent[max(a, b)] = min(a, b)
    labels = np.array([root(a) for a in range(count + 1)])[labels]
    keep = lum > threshold
    excess = np.where(keep, lum - threshold, 0.0)
    scale = np.where(keep, threshold / np.maximum(lum, 1e-300), 1.0)  # each kept texel: threshold luminance
    directions = split_sum.texel_directions(w, h)
    found = []
    for lab in np.unique(labels[keep]):
        m = labels == lab
        power = float((excess[m] * omega[m]).sum())
        solid = float(omega[m].sum())
        radius = math.degrees(math.acos(max(-1.0, 1.0 - solid / (2.0 * math.pi))))
        if power < SOURCE_MIN_POWER * total or radius > SOURCE_MAX_RADIUS_DEG:
            continue
        found.append((power, m))
    found.sort(key=lambda x: -x[0])
    residual = img.astype(np.float64).copy()
    sources = []
    for _, m in found[:max_sources]:
        rgb = img[m].astype(np.float64)
        removed = rgb * (1.0 - scale[m])[:, None]
        weight = excess[m] * omega[m]
        d = (directions[m] * weight[:, None]).sum(0)
        d /= np.linalg.norm(d)
        sources.append(Source(d, (removed * omega[m][:, None]).sum(0), float(omega[m].sum()), int(m.sum())))
        residual[m] = rgb - removed
    return sources, residual.astype(np.float32)


def _prepare_pixels(img: np.ndarray, key: str, name: str, negative: int) -> PreparedMap:
    t0 = time.perf_counter()
    h, w, _ = img.shape
    if not (img > 0).any():
        zero = np.zeros((1, 2, 3), np.float32)
        kernels = np.zeros((split_sum.KERNEL_LAYERS, 1, 2, 3), np.float32)
        return PreparedMap(key, name, w, h, np.zeros((9, 3)), [zero], [], zero, True, True, negative, kernels=kernels)
    if (img == img[0, 0]).all():
        c = img[0, 0].astype(np.float64)
        coeffs = np.zeros((9, 3))
        coeffs[0] = c * 4.0 * math.pi * sh.SH_C0
        level = np.broadcast_to(img[0, 0], (1, 2, 3)).astype(np.float32)
        irr = (level * np.float32(math.pi)).astype(np.float32)
        kernels = split_sum.uniform_kernel_maps(c)
        seconds = time.perf_counter() - t0
        return PreparedMap(key, name, w, h, coeffs, [level], [], irr, True, False, negative, seconds, kernels=kernels)
    sources, rest = extract_sources(img)
    directions = split_sum.texel_directions(w, h).reshape(-1, 3)
    omega = split_sum.texel_solid_angles(w, h).ravel()
    coeffs = sh.project(rest.reshape(-1, 3), directions, omega)
    levels = split_sum.prefilter(rest, width=max(64, min(split_sum.BASE_WIDTH, w)))  # no finer than the map
    irr = split_sum.irradiance_map(rest)
    kernels = split_sum.kernel_maps(rest)
    seconds = time.perf_counter() - t0
    return PreparedMap(key, name, w, h, coeffs, levels, sources, irr, False, False, negative, seconds, kernels=kernels)


_PREPARED: dict[str, PreparedMap] = {}


def cache_root() -> Path | None:
    """$SKINLAB_CACHE_DIR/environment (None when SKINLAB_CACHE_DIR=off; skinlab/cache.py)."""
    from skinlab.cache import cache_dir, disk_enabled

    return cache_dir() / "environment" if disk_enabled() else None


def _save(prepared: PreparedMap, path: Path) -> None:
    from skinlab.atomic_write import atomic_path

    assert prepared.irradiance is not None and prepared.kernels is not None  # prepare() makes them
    arrays: dict[str, Any] = {f"level{k}": lv for k, lv in enumerate(prepared.levels)}
    src = prepared.sources
    arrays["source_dir"] = np.array([s.direction for s in src]).reshape(-1, 3)
    arrays["source_e"] = np.array([s.irradiance for s in src]).reshape(-1, 3)
    arrays["source_omega"] = np.array([[s.solid_angle, s.texels] for s in src]).reshape(-1, 2)
    flags = [prepared.width, prepared.height, prepared.uniform, prepared.black, prepared.negative_texels]
    with atomic_path(path) as tmp:
        np.savez(
            tmp, sh=prepared.sh, irradiance=prepared.irradiance, kernels=prepared.kernels,
            flags=np.array(flags, np.int64), **arrays,
        )  # fmt: skip


def _load(path: Path, key: str, name: str) -> PreparedMap | None:
    try:
        with np.load(path) as z:
            w, h, uniform, black, negative = (int(x) for x in z["flags"])
            levels = [z[f"level{k}"] for k in range(split_sum.LEVELS) if f"level{k}" in z]
            sources = [
                Source(d, e, float(o[0]), int(o[1]))
                for d, e, o in zip(z["source_dir"], z["source_e"], z["source_omega"])
            ]
            coeffs = z["sh"]
            irr = z["irradiance"]
            kernels = z["kernels"]
    except Exception:  # missing, truncated, from another version: prepare again
        return None
    if coeffs.shape != (9, 3) or not levels or kernels.ndim != 4 or len(kernels) != split_sum.KERNEL_LAYERS:
        return None
    flags = bool(uniform), bool(black), negative
    return PreparedMap(key, name, w, h, coeffs, levels, sources, irr, *flags, 0.0, "disk", kernels=kernels)


def prepare(path: str | Path) -> PreparedMap:
    """The map at `path` prepared for the frame (module docstring); cached by content."""
    path = Path(path)
    key = prepared_key(path)
    hit = _PREPARED.get(key)
    if hit is not None:
        return PreparedMap(**{**hit.__dict__, "seconds": 0.0, "cached": "memory"})
    root = cache_root()
    disk = root / f"{key}.npz" if root is not None else None
    prepared = _load(disk, key, path.stem) if disk is not None and disk.is_file() else None
    if prepared is None:
        img, negative = load_pixels(path)
        prepared = _prepare_pixels(img, key, path.stem, negative)
        if disk is not None and prepared.seconds > 0.05:
            try:
                _save(prepared, disk)
            except OSError:
                pass  # a cache that cannot be written is only slower
    if len(_PREPARED) > 8:
        _PREPARED.pop(next(iter(_PREPARED)))
    _PREPARED[key] = prepared
    return prepared


def clear_cache() -> None:
    """Forget the maps read and prepared in this process (the disk cache stays)."""
    _PREPARED.clear()
    _PIXELS.clear()
    _KEYS.clear()


# -- the map in the world ------------------------------------------------------------------------------


def rotation_y(degrees: float) -> np.ndarray:
    """(3, 3) the rotation about +Y by `degrees`, counter-clockwise seen from above: map -> world."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def world_sh(prepared: PreparedMap, rotation_deg: float, intensity: float) -> np.ndarray:
    """(9, 3) the radiance coefficients in world axes, scaled by `intensity`."""
    return sh.rotation(rotation_y(rotation_deg)) @ prepared.sh * float(intensity)


def check_settings(where: str, rotation_deg, intensity) -> None:
    for name, v, lo in (("rotation_deg", rotation_deg, None), ("intensity", intensity, 0.0)):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or (lo is not None and v < lo):
            expected = "a finite number" + (f" >= {lo:g}" if lo is not None else "")
            raise EnvironmentMapError(f"{where}.{name}: expected {expected}, got {v!r}")


def environment_lights(scene) -> list:
    """The directional lights standing for the sources of the scene's map (none without a map), in
    world axes at the map's rotation and intensity, shadow-casting. The same light objects every
    frame for the same map (their uid keys what the frame reuses), turned and scaled in place."""
    from .graph import LightNode
    from .transform import look_at_rotation

    env = scene.environment
    if env.map is None:
        return []
    prepared = prepare(env.map)
    cache = env.__dict__.setdefault("_source_lights", {})
    rot = rotation_y(env.rotation_deg)
    out = []
    for k, src in enumerate(prepared.sources):
        light = cache.get((prepared.key, k))
        if light is None:
            light = cache[(prepared.key, k)] = LightNode(
                f"{prepared.name}:source{k + 1}", "directional", cast_shadow=True
            )
            light.angular_radius = src.angular_radius
        light.color = np.asarray(src.irradiance, np.float64)
        light.intensity = float(env.intensity)
        toward = rot @ src.direction
        light.rotation = look_at_rotation(np.zeros(3), -toward)
        out.append(light)
    return out


def write_map(path: str | Path, pixels: np.ndarray) -> Path:
    """Write (H, W, 3) linear radiance as a float EXR (or Radiance .hdr by the suffix), to a temporary
    name first (tests, tools)."""
    import OpenImageIO as oiio

    from skinlab.image_output import write_pixels

    px = np.ascontiguousarray(pixels, np.float32)
    path = Path(path)
    try:
        write_pixels(path, px, oiio.ImageSpec(px.shape[1], px.shape[0], px.shape[2], "float"))
    except OSError as exc:
        raise EnvironmentMapError(f"environment map {exc}") from None
    return path
