"""Render the path-traced reference of a Skinlab scene with Mitsuba 3: progressive, resumable, cached.

The image is the mean of independent passes (skinlab/truth/passes.py), each saved as it finishes, so
a killed run resumes from its saved passes and a later run adds to them. A request asks for at least
``spp`` samples in at least ``passes`` passes (each pass ``spp // passes`` samples); with
``until_noise`` and/or ``time_s`` passes are added until the noise floor (below) is under that value
or the time is spent. Every pass already saved for the same series is used: the reference only gets
quieter. The noise floor is :func:`skinlab.truth.compare.image_error` between the means of the first
and the second half of the samples (per pixel and on 4x4 blocks); ``Reference.passes`` keeps the
passes for the uncertainty of errors measured against it (skinlab/truth/metrics.py).

A series is keyed by a hash of everything that affects a pass: the exported description (world-space
geometry, media, BSDFs, baked textures, lights, camera, size), seed, variant, integrator settings and
the Mitsuba version (not the samples: they only decide how many passes there are). The cache lives in
``$SKINLAB_CACHE_DIR/reference`` (default ``~/.cache/skinlab/reference``): ``passes/<key>/pass-NNNNN.npz``
and ``series.json``. A whole reference filed from elsewhere (tools/gpu_reference.py ``store``) is
``<key>.npz`` (mean and the two half means) beside ``<key>.json``, keyed by its request including
samples and passes; it is found first.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from skinlab.atomic_write import atomic_path, write_text_atomic
from skinlab.declare import Field, declared_fields
from skinlab.scene.graph import Scene

from .compare import image_error, object_mask
from .export import SUN_DEG, ReferenceDescription, describe
from .passes import Pass, PassSet, PassStore

EXPORT_VERSION = 2  # bump when the exporter changes what a scene renders as
VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb")
INSTALL_HINT = "install it with `.venv/bin/pip install 'mitsuba>=3.5'` (make setup does: the 'truth' extra)"


class ReferenceUnavailable(RuntimeError):
    """Mitsuba or the asked-for variant cannot run here (the message says how to fix it)."""


SEED_LIMIT = 1 << 32  # Mitsuba's sampler seed is a 32-bit unsigned integer
DEPTH_LIMIT = (1 << 31) - 1  # and its path depths 32-bit signed ones


def _declared(default, doc: str, kind: str = "int", **kw):
    """A request field declared by a Field (its range is what the request checks, and `skinlab
    reference`'s option of the same name is made from it)."""
    f = Field("", kind, default, doc=doc, **kw)
    if default is None:
        return field(metadata={"declared": f})
    return field(default=default, metadata={"declared": f})


@dataclass(frozen=True)
class ReferenceRequest:
    width: int = _declared(None, "image width in pixels", range=(1, 16384), unit="px")
    height: int = _declared(None, "image height in pixels", range=(1, 16384), unit="px")
    spp: int = _declared(1024, "samples per pixel over all passes", range=(2, 1 << 24))
    passes: int = _declared(4, "independent passes, for the noise floor", range=(2, 1024))
    seed: int = _declared(0, "random seed (Mitsuba's: 32 bits)", range=(0, SEED_LIMIT - 1))
    variant: str = _declared(
        "scalar_rgb",
        "Mitsuba variant (scalar_rgb: any CPU; llvm_ad_rgb needs libllvm19; cuda_ad_rgb an NVIDIA GPU)",
        "choice",
        choices=VARIANTS,
    )
    sun_deg: float = field(default=SUN_DEG.default, metadata={"declared": SUN_DEG})  # describe() checks it too
    max_depth: int = _declared(-1, "path length limit (-1: none, Russian roulette ends paths; 0 is refused)",
                               range=(-1, DEPTH_LIMIT))  # fmt: skip
    rr_depth: int = _declared(
        64,
        "path depth from which Russian roulette ends paths (media with a single-scattering albedo near 1, whose "
        "light travels hundreds of scattering events, need about 1 / (1 - albedo) or more: the slit-marble "
        "reference takes 1024)",
        range=(1, 1 << 20),
    )

    @property
    def pass_spp(self) -> int:
        return max(1, self.spp // self.passes)

    @classmethod
    def fields(cls) -> dict[str, Field]:
        """The request's declared fields, by name."""
        return declared_fields(cls)

    def __post_init__(self) -> None:
        for name, f in self.fields().items():
            f.check(getattr(self, name), f"reference {name}")
        check_max_depth(self.max_depth, "reference max_depth")
        if self.spp < self.passes:
            raise ValueError(f"reference spp: {self.spp} samples cannot be split into {self.passes} passes")


def check_max_depth(value: int, label: str) -> None:
    """0 lies in max_depth's declared range (-1 is no limit) but is no path: refused, naming `label`."""
    if value == 0:
        raise ValueError(f"{label}: expected -1 (no limit) or a path length in [1, {DEPTH_LIMIT}], got 0")


# how a reference's passes are added (render_reference's keywords; `skinlab reference`'s options)
UNTIL_NOISE = Field(
    "until_noise",
    "float",
    None,
    (0.0, math.inf),
    lo_open=True,
    doc="add passes (of SPP/PASSES samples each) until the noise floor is at most this (a fraction, 0.01, or a "
    "percentage, 1%), measured as --noise-on says; passes already cached count",
    shown="none: the samples and passes asked for",
)
TIME_S = Field(
    "time",
    "float",
    None,
    (0.0, math.inf),
    lo_open=True,
    unit="s",
    doc="add passes for this many seconds (with --until-noise: whichever comes first); every pass is saved as "
    "it finishes, so the reference only gets quieter from run to run",
    shown="none: the samples and passes asked for",
)
NOISE_MEASURES = {"block": "rel_l1_block", "pixel": "rel_l1"}
NOISE_ON = Field(
    "noise_on",
    "choice",
    "block",
    choices=tuple(NOISE_MEASURES),
    doc="the noise --until-noise reads: block (relative L1 between the halves on 4x4 blocks, the ledger's) or "
    "pixel (per pixel)",
)


@dataclass
class Reference:
    image: np.ndarray  # (H, W, 4) float32 linear radiance, alpha = coverage, row 0 = top
    half_a: np.ndarray  # mean of the first half of the passes
    half_b: np.ndarray  # mean of the second half
    key: str
    meta: dict = field(default_factory=dict)
    cached: bool = False  # nothing was rendered: every pass came from the cache
    passes: PassSet | None = None  # the passes (None: a whole reference from elsewhere: its halves stand in)

    @property
    def pass_set(self) -> PassSet:
        """The passes, or the two halves as two passes of half the samples each."""
        if self.passes is not None:
            return self.passes
        spp = int(self.meta.get("spp") or self.meta.get("request", {}).get("spp") or 2)
        return PassSet(np.stack([self.half_a, self.half_b]), np.array([max(spp // 2, 1)] * 2))

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
    if base:
        return Path(base) / "reference"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "skinlab" / "reference"


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


def _content_key(desc: ReferenceDescription, head: dict) -> str:
    h = hashlib.sha256()
    h.update(json.dumps(head).encode())
    h.update(json.dumps(desc.content(), sort_keys=True, default=float).encode())
    for a in desc.arrays():
        h.update(str(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:24]


def reference_key(desc: ReferenceDescription, req: ReferenceRequest, mitsuba_version: str) -> str:
    return _content_key(desc, {"export": EXPORT_VERSION, "mitsuba": mitsuba_version, "request": asdict(req)})


def load_cached(key: str, shape: tuple[int, int, int] | None = None) -> Reference | None:
    """A whole reference filed under `key` (``<key>.npz`` and ``<key>.json``), or None. An entry that
    does not read back (truncated, emptied, garbage), whose arrays are not finite float32 images of
    `shape` (H, W, 4) or whose record lacks what a reference says (its noise floor, seconds)
    is discarded with a one-line warning and rendered again, never used."""
    d = cache_dir()
    npz, js = d / f"{key}.npz", d / f"{key}.json"
    if not (npz.is_file() and js.is_file()):
        return None
    try:
        with np.load(npz, allow_pickle=False) as z:
            img, a, b = z["image"], z["half_a"], z["half_b"]
        meta = json.loads(js.read_text())
    except Exception as exc:  # BadZipFile, EOFError, ValueError, KeyError, UnicodeDecodeError...: damaged
        _discard(npz, js, f"it does not read back ({type(exc).__name__})")
        return None
    problem = _whole_problem(img, a, b, meta, shape)
    if problem:
        _discard(npz, js, problem)
        return None
    return Reference(img, a, b, key, meta, cached=True)


def _whole_problem(img, a, b, meta, shape) -> str | None:
    """What is wrong with a whole reference's arrays and record, or None."""
    for name, arr in (("image", img), ("half_a", a), ("half_b", b)):
        if arr.dtype != np.float32 or arr.ndim != 3 or arr.shape[2] != 4:
            return f"{name} is {arr.dtype} {arr.shape}, not a float32 (H, W, 4) image"
        if shape is not None and arr.shape != tuple(shape):
            return f"{name} is {arr.shape[1]}x{arr.shape[0]}, the request {shape[1]}x{shape[0]}"
        if not np.isfinite(arr).all():
            return f"{name} holds NaN or Inf"
    if a.shape != img.shape or b.shape != img.shape:
        return "its halves differ in size from its image"
    if not isinstance(meta, dict):
        return f"its record is {type(meta).__name__}, not a table"
    nf = meta.get("noise_floor")
    if not isinstance(nf, dict) or not all(k in nf for k in ("rel_l1", "rel_l1_block", "pixels")):
        return "its record has no noise floor"
    if not isinstance(meta.get("seconds"), int | float):
        return "its record lacks the seconds it took"
    if not isinstance(meta.setdefault("notes", []), list):  # tools/gpu_reference.py files none
        return "its notes are not a list"
    return None


def _discard(npz: Path, js: Path, why: str) -> None:
    import sys

    print(f"warning: {npz}: discarded a cached reference ({why}); it is rendered again", file=sys.stderr)
    for f in (npz, js):
        f.unlink(missing_ok=True)
    return None


def series_key(desc: ReferenceDescription, req: ReferenceRequest, mitsuba_version: str) -> str:
    """The key of the pass series `req` belongs to: everything but the samples and the passes."""
    what = {k: v for k, v in asdict(req).items() if k not in ("spp", "passes")}
    return _content_key(desc, {"series": 1, "export": EXPORT_VERSION, "mitsuba": mitsuba_version, "request": what})


def pass_store(desc: ReferenceDescription, req: ReferenceRequest, mitsuba_version: str, use_cache: bool = True):
    key = series_key(desc, req, mitsuba_version)
    folder = cache_dir() / "passes" / key if use_cache else None
    return key, PassStore(folder, (req.height, req.width, 4))


def store_reference(ref: Reference) -> None:
    """File a reference in the cache under its key (atomically: a temporary name, then renamed)."""
    d = cache_dir()
    with atomic_path(d / f"{ref.key}.npz") as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, image=ref.image, half_a=ref.half_a, half_b=ref.half_b)
    write_text_atomic(d / f"{ref.key}.json", json.dumps(ref.meta, indent=1))


def _noise_of(ps: PassSet) -> dict:
    if ps.count < 2:
        return {"rel_l1": float("inf"), "rel_l1_block": float("inf"), "energy": [float("nan")] * 3, "pixels": 0}
    a, b = ps.halves()
    return image_error(a, b, object_mask(ps.mean()))


def assemble(scene_name: str, key: str, passes: list[Pass], req: ReferenceRequest, extra: dict) -> Reference:
    """A Reference from its passes (mean, halves, noise floor, what it took)."""
    ps = PassSet.of(passes)
    mean = ps.mean()
    a, b = ps.halves()
    se = ps.standard_error()
    m = object_mask(mean)
    lum = mean[..., :3].astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(m & (lum > 0), se / lum, np.nan)
    meta = {
        "scene": scene_name,
        "request": asdict(req),
        "spp": int(ps.spp.sum()),
        "passes": ps.count,
        "pass_spp": sorted({int(x) for x in ps.spp}),
        "seconds": round(float(sum(p.seconds for p in passes)), 3),
        "noise_floor": image_error(a, b, m),
        # the full mean's own noise per pixel: the standard error of its luminance over the passes
        "pixel_standard_error": {
            "median": float(np.nanmedian(rel)) if np.isfinite(rel).any() else float("nan"),
            "p90": float(np.nanpercentile(rel, 90)) if np.isfinite(rel).any() else float("nan"),
        },
        **extra,
    }
    return Reference(mean, a, b, key, meta, cached=False, passes=ps)


def render_reference(
    scene: Scene,
    req: ReferenceRequest,
    *,
    progress: bool = True,
    use_cache: bool = True,
    desc: ReferenceDescription | None = None,
    until_noise: float | None = None,
    time_s: float | None = None,
    noise_measure: str = "block",
    max_passes: int = 1024,
    render: bool = True,
) -> Reference | None:
    """The path-traced reference of `scene`: every pass of its series already in the cache, and new
    passes of ``req.pass_spp`` samples (each saved as it finishes) until there are at least
    ``req.spp`` samples in ``req.passes`` passes and, where given, the noise floor (``noise_measure``
    "block": 4x4 blocks, "pixel") is at most ``until_noise`` or this call has spent ``time_s``
    seconds. ``render=False``: only what the cache holds (None if it holds too few passes)."""
    if until_noise is not None:
        UNTIL_NOISE.check(until_noise, "until_noise")
    if time_s is not None:
        TIME_S.check(time_s, "time_s")
    NOISE_ON.check(noise_measure, "noise_measure")
    desc = desc or describe(
        scene, req.width, req.height, sun_deg=req.sun_deg, max_depth=req.max_depth, rr_depth=req.rr_depth
    )
    mi = set_variant(req.variant) if render else mitsuba_module()
    shape = (req.height, req.width, 4)
    if use_cache and (hit := load_cached(reference_key(desc, req, mi.__version__), shape)) is not None:
        return hit
    key, store = pass_store(desc, req, mi.__version__, use_cache)
    have = store.load() if use_cache else []
    measure = NOISE_MEASURES[noise_measure]
    t0 = time.perf_counter()

    def enough() -> bool:
        n, spp = len(have), sum(p.spp for p in have)
        if n < req.passes or spp < req.spp:
            return False
        if n >= max_passes:
            return True
        if time_s is not None and time.perf_counter() - t0 >= time_s:
            return True
        if until_noise is not None:
            return n % 2 == 0 and _noise_of(PassSet.of(have))[measure] <= until_noise
        return time_s is None

    rendered = 0
    if not render:
        if len(have) < max(req.passes, 2) or sum(p.spp for p in have) < req.spp:
            return None
    elif not enough():
        from tqdm import tqdm

        from .description import CHUNK_SPP, render_pass

        mscene = mi.load_dict(desc.to_mitsuba(CHUNK_SPP, req.seed))
        goal = max(req.spp - sum(p.spp for p in have), 0) or None
        bar = tqdm(total=goal, unit="spp", desc=f"path tracing {scene.name}", disable=not progress, leave=False)
        index = max((p.index for p in have), default=-1) + 1
        while not enough():
            img, sec = render_pass(desc, req.pass_spp, req.seed, index, bar.update, mscene=mscene)
            if not np.isfinite(img).all():
                raise RuntimeError(f"scene {scene.name!r}: the path tracer returned NaN or Inf")
            p = Pass(index, img, req.pass_spp, sec)
            store.save(p)  # saved as it finishes: a killed run resumes from here
            have.append(p)
            index += 1
            rendered += 1
            if len(have) >= 2 and progress:
                bar.set_postfix_str(f"noise {100 * _noise_of(PassSet.of(have))[measure]:.2f} % ({noise_measure})")
        bar.close()
    ref = assemble(
        scene.name,
        key,
        have,
        req,
        {
            "source": str(scene.source) if scene.source else None,
            "variant": req.variant,
            "mitsuba": mi.__version__,
            "seconds_this_run": round(time.perf_counter() - t0, 3) if rendered else 0.0,
            "passes_rendered": rendered,
            "notes": desc.notes,
            "made": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        },
    )
    ref.cached = rendered == 0
    store.write_info({k: ref.meta[k] for k in ("scene", "source", "spp", "passes", "seconds", "variant", "made")})
    return ref
