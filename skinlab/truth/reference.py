"""Render the path-traced reference of a Skinlab scene with Mitsuba 3, in independent passes, cached.

The image is the mean of ``passes`` (>= 2) independent renders with different seeds; its noise
floor is :func:`skinlab.truth.compare.image_error` between the means of the first and second half of
the passes. Each pass is rendered in chunks of at most ``CHUNK_SPP`` samples per pixel
(skinlab/truth/description.py; a progress bar counts samples).

Results are cached by a hash of everything that affects them: the exported description (world-space
geometry, media, BSDFs, baked textures, lights, camera, size), samples, passes, seed, variant,
integrator settings and the Mitsuba version. The cache lives in ``$SKINLAB_CACHE_DIR/reference`` (default
``~/.cache/skinlab/reference``): ``<key>.npz`` (mean and the two half means, float32) beside
``<key>.json`` (how it was made), each written to a temporary name and renamed.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from skinlab.atomic_write import atomic_path, write_text_atomic
from skinlab.scene.graph import Scene

from .compare import image_error, object_mask
from .description import path_trace
from .export import ReferenceDescription, describe

EXPORT_VERSION = 2  # bump when the exporter changes what a scene renders as
VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb")
INSTALL_HINT = "install it with `.venv/bin/pip install 'mitsuba>=3.5'` (make setup does: the 'truth' extra)"


class ReferenceUnavailable(RuntimeError):
    """Mitsuba or the asked-for variant cannot run here (the message says how to fix it)."""


@dataclass(frozen=True)
class ReferenceRequest:
    width: int
    height: int
    spp: int = 1024  # samples per pixel, all passes together
    passes: int = 4
    seed: int = 0
    variant: str = "scalar_rgb"
    sun_deg: float = 0.0  # > 0: directional lights as distant disks of this angular diameter
    max_depth: int = -1  # volpath path length limit (-1: none; Russian roulette ends paths)
    rr_depth: int = 64

    def __post_init__(self) -> None:
        for name, lo, hi in (("width", 1, 16384), ("height", 1, 16384), ("spp", 2, 1 << 24), ("passes", 2, 1024)):
            v = getattr(self, name)
            if not isinstance(v, int) or not lo <= v <= hi:
                raise ValueError(f"reference {name}: expected an integer in [{lo}, {hi}], got {v!r}")
        if self.spp < self.passes:
            raise ValueError(f"reference spp: {self.spp} samples cannot be split into {self.passes} passes")
        if self.variant not in VARIANTS:
            raise ValueError(f"reference variant: expected one of {', '.join(VARIANTS)}, got {self.variant!r}")
        if not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"reference seed: expected an integer >= 0, got {self.seed!r}")


@dataclass
class Reference:
    image: np.ndarray  # (H, W, 4) float32 linear radiance, alpha = coverage, row 0 = top
    half_a: np.ndarray  # mean of the first half of the passes
    half_b: np.ndarray  # mean of the second half
    key: str
    meta: dict = field(default_factory=dict)
    cached: bool = False

    @property
    def noise(self) -> dict:
        """The ledger's error measure between the two halves (the reference's noise floor)."""
        return self.meta["noise_floor"]

    @property
    def mask(self) -> np.ndarray:
        return object_mask(self.image)


def cache_dir() -> Path:
    """$SKINLAB_CACHE_DIR/reference, else $XDG_CACHE_HOME/skinlab/reference, else ~/.cache/skinlab/reference."""
    base = os.environ.get("SKINLAB_CACHE_DIR")
    if not base:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "skinlab"
    return Path(base) / "reference"


def mitsuba_module():
    """The mitsuba package (any variant), or ReferenceUnavailable saying how to install it."""
    try:
        import mitsuba as mi
    except ImportError:
        raise ReferenceUnavailable(
            f"the path-traced reference needs Mitsuba 3, which is not installed: {INSTALL_HINT}"
        ) from None
    return mi


def set_variant(variant: str):
    mi = mitsuba_module()
    try:
        mi.set_variant(variant)
    except Exception as exc:  # Dr.Jit raises ImportError/RuntimeError/AttributeError by backend
        hint = {
            "llvm_ad_rgb": "it needs a newer libLLVM than Mesa's (Debian: apt-get install libllvm19; if Dr.Jit "
            "still does not find it, export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1)",
            "cuda_ad_rgb": "it needs an NVIDIA GPU with its driver",
        }.get(variant, "")
        raise ReferenceUnavailable(f"Mitsuba variant {variant!r} cannot run here: {exc}. {hint}".strip()) from None
    return mi


def reference_key(desc: ReferenceDescription, req: ReferenceRequest, mitsuba_version: str) -> str:
    h = hashlib.sha256()
    h.update(json.dumps({"export": EXPORT_VERSION, "mitsuba": mitsuba_version, "request": asdict(req)}).encode())
    h.update(json.dumps(desc.content(), sort_keys=True, default=float).encode())
    for a in desc.arrays():
        h.update(str(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:24]


def load_cached(key: str) -> Reference | None:
    d = cache_dir()
    npz, js = d / f"{key}.npz", d / f"{key}.json"
    if not (npz.is_file() and js.is_file()):
        return None
    try:
        with np.load(npz) as z:
            img, a, b = z["image"], z["half_a"], z["half_b"]
        meta = json.loads(js.read_text())
    except (OSError, ValueError, KeyError):
        return None  # a damaged entry is rendered again
    return Reference(img, a, b, key, meta, cached=True)


def store_reference(ref: Reference) -> None:
    """File a reference in the cache under its key (atomically: a temporary name, then renamed)."""
    d = cache_dir()
    with atomic_path(d / f"{ref.key}.npz") as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, image=ref.image, half_a=ref.half_a, half_b=ref.half_b)
    write_text_atomic(d / f"{ref.key}.json", json.dumps(ref.meta, indent=1))


def render_reference(
    scene: Scene,
    req: ReferenceRequest,
    *,
    progress: bool = True,
    use_cache: bool = True,
    desc: ReferenceDescription | None = None,
) -> Reference:
    """The path-traced reference of `scene` (from the cache when an identical one was made)."""
    desc = desc or describe(
        scene, req.width, req.height, sun_deg=req.sun_deg, max_depth=req.max_depth, rr_depth=req.rr_depth
    )
    mi = set_variant(req.variant)
    key = reference_key(desc, req, mi.__version__)
    if use_cache and (hit := load_cached(key)) is not None:
        return hit
    from tqdm import tqdm

    bar = tqdm(total=req.spp, unit="spp", desc=f"path tracing {scene.name}", disable=not progress, leave=False)
    mean, a, b, seconds = path_trace(desc, req.spp, req.passes, req.seed, bar.update)
    bar.close()
    if not np.isfinite(mean).all():
        raise RuntimeError(f"scene {scene.name!r}: the path tracer returned NaN or Inf")
    noise = image_error(a, b, object_mask(mean))
    meta = {
        "scene": scene.name,
        "source": str(scene.source) if scene.source else None,
        "request": asdict(req),
        "mitsuba": mi.__version__,
        "seconds": round(seconds, 3),
        "noise_floor": noise,
        "notes": desc.notes,
        "made": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }
    ref = Reference(mean, a, b, key, meta, cached=False)
    if use_cache:
        store_reference(ref)
    return ref
