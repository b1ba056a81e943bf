"""The accuracy/time ledger (`skinlab bench accuracy`): what each way of rendering subsurface
scattering costs in frame time and what it gets wrong, on the head and the bunny.

For every setting of the sweep (no scattering; the per-pixel tint; texture-space diffusion over K,
irradiance size and tap count; screen-space SSS over its tap presets; the brute-force exact
texture-space convolution, which is the image reference):

* **time**: ``warmup`` frames first (program compiles, uploads, stretch maps), then the median,
  10th and 90th percentile of ``FrameTimings.frame_ms`` over the timed frames of
  ``renderer.render(scene, settings, readback=False)``: the sum of the per-pass times, from GPU timer
  queries where the GPU has them, else (Mesa llvmpipe) wall time with ``glFinish`` after each pass
  (the ``clock`` column says which). Per-pass medians are kept too.
* **image error** against the exact reference of the same scene and image size, on linear HDR
  (``FrameResult.hdr``) over the lit surface pixels: reference coverage alpha > 0 and reference
  luminance above ``LUM_FRACTION`` of its 99th percentile. ``image_rel_l1`` = sum |img - ref| /
  sum ref (RGB summed over those pixels); ``image_max_rel`` / ``image_p95_rel``: the largest / 95th
  percentile per-pixel sum_c |img - ref| / sum_c ref.
* **profile error** against the Monte Carlo random walk (scene/optics/montecarlo.py) for the
  scattering material's medium, as the relative L1 of the *edge response* (the fraction of a
  lit half-plane's light leaving at signed distance x past the shadow edge, per channel):
  ``int |E_tech - E_mc| dx / int |H - E_mc| dx`` over x in [-L, L] (L = 50 mean free paths of the
  channel), H the hard step of no scattering; averaged over the scattering channels. No scattering
  (and the tint, which does not spread light) scores exactly 1; a perfect profile 0. The edge
  response is what a shadow boundary shows on screen, it accepts a delta (identity weight), a
  Gaussian sum and a tabulated radial profile alike, and it integrates the MC noise away.
  For "tsd" the technique's profile is the Gaussian kernel the frame actually used (after the
  planner folded sub-texel Gaussians into the unblurred term; no blur pass at all = a delta), for
  "exact" the material's model profile, for "none"/"tint" a delta (the tint shifts colour but moves
  no light), for "ssss" the frame's 1-D screen-space kernel (scene/optics/ssss.py
  separable_edge_response; an edge along a screen axis, the separable kernel's best case).
  ``profile_err_model`` is the same measure against the material's own model profile instead of
  Monte Carlo: the technique's approximation error alone, without the model's.

A technique the renderer does not implement yet either raises (recorded as an ``error`` row; the
sweep goes on) or is silently rendered as texture-space diffusion: every non-tsd setting is
compared with the tsd frame of the same settings, and an identical image is recorded as
``ignored``. Without a working exact reference the most accurate tsd setting (largest irradiance
texture, largest K) stands in as a *proxy* reference, named in the ``reference`` column.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from app.bench.truth_ledger import (
    REFERENCE_SCENES,
    TRUTH_COLUMNS,
    TruthSpec,
    error_map_sheet,
    load_truth,
    reference_scene_names,
    truth_errors,
    truth_markdown,
    write_error_map,
)
from app.truth.compare import relative_difference

ASSETS = Path(__file__).resolve().parents[2] / "assets" / "scenes"
SCENE_ALIASES = {"head": None, "bunny": ASSETS / "bunny-skimmilk.toml"}
REFERENCE_SCENE_NAMES = tuple(reference_scene_names())
LUM_FRACTION = 0.05  # lit pixels: reference luminance above 5 % of its 99th percentile
REC709 = np.array([0.2126, 0.7152, 0.0722])
EDGE_RANGE_MFP = 50.0  # the edge-response integral spans +-50 mean free paths per channel
MC_SEED = 1
RECOMMEND_THRESHOLDS = (0.01, 0.02, 0.05)

CSV_COLUMNS = [
    "scene",
    "setting",
    "technique",
    "model",
    "K",
    "tsd_size",
    "taps",
    "ssss_taps",
    "width",
    "height",
    "blur_levels",
    "frames",
    "frame_ms_median",
    "frame_ms_p10",
    "frame_ms_p90",
    "wall_ms_median",
    "tsd_ms_median",
    "clock",
    "image_rel_l1",
    "image_max_rel",
    "image_p95_rel",
    "pixels",
    "image_rel_l1_same_size",
    "profile_err_mc",
    "profile_err_model",
    "reference",
    *TRUTH_COLUMNS,
    "status",
    "error",
    "passes_ms",
]
NUMERIC_COLUMNS = [
    "frames",
    "frame_ms_median",
    "frame_ms_p10",
    "frame_ms_p90",
    "wall_ms_median",
    "tsd_ms_median",
    "image_rel_l1",
    "image_max_rel",
    "image_p95_rel",
    "pixels",
    "image_rel_l1_same_size",
    "profile_err_mc",
    "profile_err_model",
    *TRUTH_COLUMNS,
]


# -- the sweep ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Sweep:
    name: str
    size: tuple[int, int]
    shadow_size: int
    k_size: int  # irradiance size of the K and tap sweeps
    ks: tuple[int, ...]  # K at k_size
    sizes: tuple[int, ...]  # irradiance sizes at K = max(ks)
    taps: tuple  # tap counts (None = auto) at k_size, K = max(ks)
    ssss: tuple[int, ...]
    exact_size: int  # irradiance size of the exact reference
    frames: int  # timed frames per setting (fewer if over budget_s)
    warmup: int
    budget_s: float  # rough time budget of the timed frames of one setting
    photons: int  # Monte Carlo photons per channel
    peer_frames: int
    scenes: tuple[str, ...] = ("head", "bunny")
    extra: tuple = ()  # extra settings (tiny sweep)
    # the path-traced truth: reference size and samples (app/bench/truth_ledger.py); None: not measured
    truth: TruthSpec | None = None


FULL = Sweep(
    "full",
    (640, 640),
    2048,
    1024,
    (1, 2, 3, 4, 5, 6),
    (256, 512, 1024, 2048),
    (None, 7, 15, 31),
    (11, 17, 25),
    1024,
    frames=10,
    warmup=2,
    budget_s=25.0,
    photons=200_000,
    peer_frames=30,
    scenes=REFERENCE_SCENE_NAMES,
    truth=TruthSpec((192, 192), 1024),
)
QUICK = Sweep(
    "quick",
    (160, 160),
    1024,
    256,
    (1, 3, 6),
    (256, 512),
    (None, 7),
    (11, 25),
    256,  # the exact convolution at 512 texels took half of the quick run; the truth is the first axis now
    frames=5,
    warmup=2,
    budget_s=2.0,
    photons=20_000,
    peer_frames=5,
    scenes=("head-skin1-matched", "bunny-skimmilk", "slab-edge-skin1"),
    truth=TruthSpec((96, 96), 256),
)
# for the tests: four settings on the head at 64x64
TINY = Sweep(
    "tiny",
    (64, 64),
    256,
    256,
    (1, 6),
    (256,),
    (None,),
    (),
    256,
    frames=2,
    warmup=2,
    budget_s=0.5,
    photons=4_000,
    peer_frames=1,
    scenes=("head-skin1-matched",),
    truth=TruthSpec((32, 32), 16, passes=2),
)
SWEEPS = {"full": FULL, "quick": QUICK, "tiny": TINY}


@dataclass(frozen=True)
class Setting:
    technique: str  # ledger technique: none | tint | tsd | ssss | exact
    K: int | None = None
    tsd_size: int | None = None
    taps: int | None = None  # tsd taps; None = auto (only meaningful for tsd)
    ssss_taps: int | None = None

    @property
    def label(self) -> str:
        if self.technique == "tsd":
            return f"tsd K{self.K} {self.tsd_size} {self.taps or 'auto'}"
        if self.technique == "ssss":
            return f"ssss {self.ssss_taps}"
        if self.technique == "exact":
            return f"exact {self.tsd_size}"
        return self.technique

    def render_settings(self, sweep: Sweep, size=None):
        from app.render.settings import RenderSettings

        w, h = size or sweep.size
        base = dict(width=w, height=h, shadow_size=sweep.shadow_size)
        if self.technique == "none":
            return RenderSettings(**base, sss_model="none")
        # tint and ssss do not use the irradiance texture: tsd_size = the sweep's K-sweep size only
        # keeps the comparison frame (a renderer that ignores the technique draws tsd) affordable
        if self.technique == "tint":
            return RenderSettings(**base, technique="tint", tsd_size=sweep.k_size)
        if self.technique == "tsd":
            return RenderSettings(
                **base, technique="tsd", tsd_size=self.tsd_size, tsd_gaussians=self.K, tsd_taps=self.taps
            )
        if self.technique == "ssss":
            return RenderSettings(**base, technique="ssss", ssss_taps=self.ssss_taps, tsd_size=sweep.k_size)
        if self.technique == "exact":
            return RenderSettings(**base, technique="exact", tsd_size=self.tsd_size)
        raise ValueError(f"unknown ledger technique {self.technique!r}")

    def cells(self) -> dict:
        """The parameter columns; empty where the parameter does not apply to the technique."""
        return {
            "K": self.K if self.technique == "tsd" else "",
            "tsd_size": self.tsd_size if self.technique in ("tsd", "exact") else "",
            "taps": (self.taps or "auto") if self.technique == "tsd" else "",
            "ssss_taps": self.ssss_taps if self.technique == "ssss" else "",
        }


def sweep_settings(sweep: Sweep) -> list[Setting]:
    """The reference first, then the rest, without duplicates (in order)."""
    kmax = max(sweep.ks)
    out = [Setting("exact", tsd_size=sweep.exact_size), Setting("none"), Setting("tint")]
    out += [Setting("tsd", K=k, tsd_size=sweep.k_size) for k in sweep.ks]
    out += [Setting("tsd", K=kmax, tsd_size=s) for s in sweep.sizes]
    out += [Setting("tsd", K=kmax, tsd_size=sweep.k_size, taps=t) for t in sweep.taps]
    out += [Setting("ssss", ssss_taps=n) for n in sweep.ssss]
    # the exact convolution at the smaller swept sizes: the irradiance texture's own resolution error
    out += [Setting("exact", tsd_size=s) for s in sweep.sizes if s < sweep.exact_size]
    out += list(sweep.extra)
    seen, uniq = set(), []
    for s in out:
        if s not in seen:
            seen.add(s)
            uniq.append(s)
    return uniq


def sheet_settings(settings: list[Setting]) -> list[Setting]:
    """One setting per technique for the error-map contact sheet: the default-like one (tsd at
    RenderSettings' K and size with automatic taps, ssss at its default taps) where swept, else the
    technique's first; the exact reference at its largest size."""
    from app.render.settings import RenderSettings

    d = RenderSettings()
    prefer = {
        "tsd": Setting("tsd", K=d.tsd_gaussians, tsd_size=d.tsd_size),
        "ssss": Setting("ssss", ssss_taps=d.ssss_taps),
    }
    out = []
    for tech in ("none", "tint", "tsd", "ssss", "exact"):
        cands = [s for s in settings if s.technique == tech]
        if not cands:
            continue
        if tech == "exact":
            out.append(max(cands, key=lambda s: s.tsd_size))
        else:
            out.append(prefer[tech] if prefer.get(tech) in cands else cands[0])
    return out


def proxy_reference(settings: list[Setting]) -> Setting | None:
    """The most accurate tsd setting: largest irradiance texture, then largest K, auto taps first."""
    tsd = [s for s in settings if s.technique == "tsd"]
    if not tsd:
        return None
    return max(tsd, key=lambda s: (s.tsd_size, s.K, s.taps is None, s.taps or 0))


def resolve_scene(name: str):
    """'head', 'bunny' (skim milk), 'bunny-marble'... (assets/scenes/NAME.toml) or a path to a scene file."""
    if name in SCENE_ALIASES:
        return SCENE_ALIASES[name]
    for folder in (REFERENCE_SCENES, ASSETS):
        p = folder / f"{name}.toml"
        if p.is_file():
            return p
    p = Path(name)
    if p.suffix == ".toml" and p.is_file():
        return p
    known = ", ".join(list(SCENE_ALIASES) + sorted(x.stem for x in ASSETS.glob("*.toml")) + list(REFERENCE_SCENE_NAMES))
    raise ValueError(f"--scenes: unknown scene {name!r}; expected one of {known} or a .toml path")


def scene_label(name: str) -> str:
    return Path(name).stem if name.endswith(".toml") else name


# -- statistics, image error ---------------------------------------------------------------------------------


def percentile(values, q: float) -> float:
    return float(np.percentile(np.asarray(values, np.float64), q)) if len(values) else math.nan


def lit_mask(ref: np.ndarray, lum_fraction: float = LUM_FRACTION) -> np.ndarray:
    """Pixels that count: reference coverage > 0 and luminance above lum_fraction x its 99th percentile."""
    cover = ref[..., 3] > 0
    lum = ref[..., :3].astype(np.float64) @ REC709
    if not cover.any():
        return cover
    thr = lum_fraction * float(np.percentile(lum[cover], 99))
    return cover & (lum > thr)


def image_error(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> dict:
    """Relative L1 and per-pixel relative errors of linear HDR `img` against `ref` over `mask`."""
    if img.shape != ref.shape:
        raise ValueError(f"image error: shapes differ ({img.shape} vs {ref.shape})")
    mask = lit_mask(ref) if mask is None else mask
    n = int(mask.sum())
    if n == 0:
        return {"image_rel_l1": math.nan, "image_max_rel": math.nan, "image_p95_rel": math.nan, "pixels": 0}
    d = np.abs(img[..., :3].astype(np.float64) - ref[..., :3].astype(np.float64)).sum(axis=-1)[mask]
    s = ref[..., :3].astype(np.float64).sum(axis=-1)[mask]
    per = d / s
    return {
        "image_rel_l1": float(d.sum() / s.sum()),
        "image_max_rel": float(per.max()),
        "image_p95_rel": float(np.percentile(per, 95)),
        "pixels": n,
    }


# -- profile error against Monte Carlo -------------------------------------------------------------------


def _atomic_bytes(path: Path, data: bytes) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def write_text_atomic(path: Path, text: str) -> Path:
    return _atomic_bytes(path, text.encode("utf-8"))


def mc_profile(alpha: float, eta: float, photons: int, cache_dir: Path | None, seed: int = MC_SEED):
    """(r_edges, R, total) of the random walk in mean-free-path units (normal incidence, isotropic
    reduced phase function, per entering photon), cached as .npz under cache_dir."""
    from scene.optics.montecarlo import simulate

    path = None
    if cache_dir is not None:
        path = Path(cache_dir) / f"mc-a{alpha:.8f}-eta{eta:.6f}-n{photons}-s{seed}.npz"
        if path.is_file():
            try:
                d = np.load(path)
                return d["r_edges"], d["R"], float(d["total"])
            except Exception:
                pass  # a corrupt cache entry is recomputed
    res = simulate(alpha, eta, 0.0, "normal", photons, seed, progress=False, workers=min(2, os.cpu_count() or 1))
    if path is not None:
        buf = io.BytesIO()
        np.savez(buf, r_edges=res.r_edges, R=res.R, R_se=res.R_se, total=res.total, total_se=res.total_se)
        _atomic_bytes(path, buf.getvalue())
    return res.r_edges, res.R, res.total


@dataclass
class ProfileReference:
    """Monte Carlo edge responses of one medium, per scattering channel, on a fixed x grid (mm)."""

    medium: object
    scatter: np.ndarray  # (3,) bool
    x: list  # per channel: x grid (mm) or None
    e_mc: list  # per channel: MC edge response on x
    denom: list  # per channel: int |H - E_mc| dx
    photons: int
    cache: dict = field(default_factory=dict)


def _edge_grid(mfp: float) -> np.ndarray:
    pos = np.geomspace(1e-3, EDGE_RANGE_MFP, 700) * mfp
    return np.concatenate([-pos[::-1], [0.0], pos])


def _step(x: np.ndarray) -> np.ndarray:
    return np.where(x < 0, 1.0, np.where(x == 0, 0.5, 0.0))


def _scattering(medium) -> np.ndarray:
    from scene.optics.constants import MIN_MFP_MM

    return (medium.mfp_arr >= MIN_MFP_MM) & (medium.alpha_arr > 0)


def _reference(medium, edge_of_channel, photons: int = 0) -> ProfileReference:
    """Edge responses of a reference per scattering channel: edge_of_channel(c, x_mm) -> (N,)."""
    scatter = _scattering(medium)
    xs, es, dens = [], [], []
    for c in range(3):
        if not scatter[c]:
            xs.append(None), es.append(None), dens.append(None)
            continue
        x = _edge_grid(float(medium.mfp_arr[c]))
        e = np.asarray(edge_of_channel(c, x), np.float64)
        xs.append(x), es.append(e), dens.append(float(np.trapezoid(np.abs(_step(x) - e), x)))
    return ProfileReference(medium, scatter, xs, es, dens, photons)


def profile_reference(medium, photons: int, cache_dir: Path | None) -> ProfileReference:
    """The Monte Carlo edge responses of `medium` (one random walk per scattering channel)."""
    from scene.optics.tsd import edge_response

    def edge(c, x):
        mfp = float(medium.mfp_arr[c])
        edges, R, _ = mc_profile(float(medium.alpha_arr[c]), float(medium.eta), photons, cache_dir)
        r_mid = np.sqrt(0.5 * (edges[:-1] ** 2 + edges[1:] ** 2)) * mfp
        R_mm = R / mfp**2
        r_max = edges[-1] * mfp
        fn = lambda r: np.where(np.asarray(r) <= r_max, np.interp(r, r_mid, R_mm), 0.0)[:, None]
        return edge_response(x, fn, "profile")[:, 0]

    return _reference(medium, edge, photons)


def model_reference(model: str, medium) -> ProfileReference | None:
    """The edge responses of the material's exact model profile (what the techniques approximate)."""
    fn = technique_edge_fn("exact", model, medium)
    if fn is None:
        return None
    return _reference(medium, lambda c, x: fn(x)[:, c])


def edge_error(ref: ProfileReference, edge_fn) -> float:
    """Mean over scattering channels of int |E - E_mc| dx / int |H - E_mc| dx, where
    edge_fn(x_mm) -> (N, 3) is the technique's edge response."""
    errs = []
    for c in range(3):
        if ref.x[c] is None or not ref.denom[c] > 0:
            continue
        e = np.asarray(edge_fn(ref.x[c]), np.float64)[:, c]
        errs.append(float(np.trapezoid(np.abs(e - ref.e_mc[c]), ref.x[c])) / ref.denom[c])
    return float(np.mean(errs)) if errs else math.nan


def technique_edge_fn(technique: str, model: str, medium, kernel=None, ssss=None):
    """The technique's edge response x_mm -> (N, 3), or None where the ledger has no profile for it.
    ``kernel``: the tsd DiffusionKernel the frame used; ``ssss``: (offsets_mm, weights) of the
    screen-space kernel the frame used."""
    from scene.optics.profiles import get_profile
    from scene.optics.tsd import MODEL_PROFILES, edge_response

    if technique in ("none", "tint") or model == "none":
        return lambda x: np.repeat(_step(np.asarray(x))[:, None], 3, axis=1)
    if technique == "tsd":
        if kernel is None:
            return None
        return lambda x: edge_response(x, kernel, "gaussians")
    if technique == "ssss":
        if ssss is None:
            return None
        from scene.optics.ssss import separable_edge_response

        offsets, weights = ssss
        return lambda x: separable_edge_response(x, np.asarray(offsets), np.asarray(weights))
    if technique == "exact":
        if model not in MODEL_PROFILES:
            return None
        scatter = _scattering(medium)
        prof = get_profile(MODEL_PROFILES[model])
        fn = lambda r: prof.evaluate(np.asarray(r, np.float64), medium) * scatter[None, :]
        return lambda x: edge_response(x, fn, "profile")
    return None


def fit_kernel(model: str, medium, K: int):
    """The K-Gaussian fit as a kernel with every Gaussian kept (no texel folding)."""
    from scene.optics.tsd import design_kernel, profile_fit

    return design_kernel(profile_fit(model, medium, K), 1e-12, 1e-12)


# -- measuring one setting -------------------------------------------------------------------------------


def _clock(timings) -> str:
    if not timings.software_gl and timings.passes and all(p.gpu_ms is not None for p in timings.passes):
        return "gpu-timer"
    return "cpu-synchronised"


def _subsurface_node(scene, renderer):
    """The first mesh node whose frame used texture-space diffusion, with its kernel."""
    frame = getattr(renderer, "last_frame", None)
    tsd = getattr(frame, "tsd", None) or {}
    for n in scene.mesh_nodes():
        t = tsd.get(id(n))
        if t is not None and getattr(t, "kernel", None) is not None:
            return n, t.kernel
    return None, None


def measure_setting(renderer, scene, rs, warmup: int, frames: int, budget_s: float) -> dict:
    """Warm up, time `frames` frames (fewer, at least 3, if they would take over budget_s), then one
    frame with HDR and LDR read back."""
    t_warm = 0.0
    for _ in range(max(warmup, 1)):
        t0 = time.perf_counter()
        renderer.render(scene, rs, readback=False)
        t_warm = time.perf_counter() - t0
    n = frames
    if t_warm * frames > budget_s:
        n = max(min(3, frames), int(budget_s / max(t_warm, 1e-9)))
    fm, wall, tsd_ms, passes, clocks = [], [], [], {}, set()
    for _ in range(n):
        res = renderer.render(scene, rs, readback=False)
        fm.append(res.timings.frame_ms)
        wall.append(res.cpu_ms)
        clock = _clock(res.timings)
        clocks.add(clock)
        t_tsd = 0.0
        for p in res.timings.passes:
            v = p.gpu_ms if clock == "gpu-timer" else p.cpu_ms
            passes.setdefault(p.name, []).append(v)
            if p.name.startswith("tsd"):
                t_tsd += v
        tsd_ms.append(t_tsd)
    final = renderer.render(scene, rs, readback=("hdr", "ldr"))
    levels = sum(1 for p in final.plan.passes if p.kind == "tsd_blur")
    pm = {k: statistics.median(v) for k, v in passes.items()}
    return {
        "frames": n,
        "frame_ms_median": statistics.median(fm),
        "frame_ms_p10": percentile(fm, 10),
        "frame_ms_p90": percentile(fm, 90),
        "wall_ms_median": statistics.median(wall),
        "tsd_ms_median": statistics.median(tsd_ms),
        "clock": "+".join(sorted(clocks)),
        "passes": pm,
        "blur_levels": levels,
        "hdr": final.hdr,
        "ldr": final.ldr,
        "plan": final.plan.names(),
        "kinds": [p.kind for p in final.plan.passes],
        "ssss": _ssss_kernel(final.plan),
    }


def _ssss_kernel(plan):
    """(offsets_mm, weights) of the frame's screen-space kernel, or None."""
    for p in plan.passes:
        k = p.params.get("ssss") if p.kind == "ssss_blur" else None
        if k is not None and getattr(k, "offsets_mm", None) is not None:
            return np.asarray(k.offsets_mm), np.asarray(k.weights)
    return None


# -- the run ---------------------------------------------------------------------------------------------


def _loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def _first_line(exc: BaseException) -> str:
    text = f"{type(exc).__name__}: {exc}".strip()
    return text.splitlines()[0][:300] if text else type(exc).__name__


def run_sweep(
    sweep: Sweep,
    out: Path,
    scenes: tuple[str, ...] | None = None,
    peer: bool = True,
    progress: bool = True,
    images: bool = True,
    command: str | None = None,
    references: bool = False,
) -> dict:
    """Run the whole ledger and write DIR/ledger.csv, ledger.md, ledger.json, pareto.png and cost.png;
    with the sweep's truth, error_maps/ and error_maps.png. references: path-trace the references
    that are not cached yet (else a scene without a cached reference has no truth columns)."""
    from tqdm import tqdm

    from app.gl.context import create_headless_context, describe
    from app.render.plan_tsd import effective_material
    from app.render.renderer import Renderer
    from scene.optics.tsd import material_medium
    from scene.scenefile import load_scene

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = tuple(scenes or sweep.scenes)
    paths = {s: resolve_scene(s) for s in scenes}
    settings = sweep_settings(sweep)
    t_start = time.perf_counter()
    load_start = _loadavg()
    ctx = create_headless_context()
    gl = describe(ctx)
    renderer = Renderer(ctx)
    rows: list[dict] = []
    truth_notes: dict[str, str] = {}
    sheet: dict[str, dict[str, np.ndarray]] = {}
    bar = tqdm(
        total=len(settings) * len(scenes),
        file=sys.stderr,
        unit="setting",
        disable=not progress,
        desc="ledger",
        dynamic_ncols=True,
    )
    try:
        for sname in scenes:
            label = scene_label(sname)
            scene = load_scene(paths[sname])
            # the scene's (first) scattering material, as the scene file has it: its medium is what the
            # profile errors are measured for, its own model is the model reference
            base_node = next((n for n in scene.mesh_nodes() if n.material.has_subsurface), None)
            base_mat = base_node.material if base_node is not None else None
            pref = mref = base_medium = None
            if base_mat is not None:
                base_medium = material_medium(base_mat.values)
                bar.set_postfix_str(f"{label}: Monte Carlo reference")
                try:
                    pref = profile_reference(base_medium, sweep.photons, out / "mc_cache")
                    mref = model_reference(base_mat["sss_model"], base_medium)
                except Exception as exc:
                    print(f"profile references for {label} failed: {_first_line(exc)}", file=sys.stderr)
                    base_mat = None
            truth = None
            if sweep.truth is not None:
                bar.set_postfix_str(f"{label}: path-traced reference")
                try:
                    truth = load_truth(scene, sweep.truth, render=references, progress=progress)
                except Exception as exc:
                    truth_notes[label] = f"the path-traced reference failed: {_first_line(exc)}"
                if truth is None and label not in truth_notes:
                    truth_notes[label] = (
                        "no cached path-traced reference at "
                        f"{sweep.truth.size[0]}x{sweep.truth.size[1]}, {sweep.truth.spp} spp: run with --references"
                    )
            hdrs: dict[Setting, np.ndarray] = {}
            scene_rows: dict[Setting, dict] = {}
            tsd_images: dict = {}
            for st in settings:
                bar.set_postfix_str(f"{label}: {st.label}")
                row = {
                    "scene": label,
                    "setting": st.label,
                    "technique": st.technique,
                    **st.cells(),
                    "width": sweep.size[0],
                    "height": sweep.size[1],
                    "status": "ok",
                    "error": "",
                }
                try:
                    rs = st.render_settings(sweep)
                    row["model"] = effective_material(base_node, rs)["sss_model"] if base_node is not None else ""
                    m = measure_setting(renderer, scene, rs, sweep.warmup, sweep.frames, sweep.budget_s)
                    _, kernel = _subsurface_node(scene, renderer)
                    if st.technique in ("exact", "tint", "ssss"):
                        # a technique the renderer does not know yet may be rendered as tsd: compare
                        twin = replace(rs, technique="tsd")
                        key = (twin.tsd_size, twin.tsd_gaussians, twin.tsd_taps)
                        if key not in tsd_images:
                            tsd_images[key] = renderer.render(scene, twin, readback=("hdr",)).hdr
                        if np.array_equal(tsd_images[key], m["hdr"]):
                            row["status"] = "ignored"
                            row["error"] = (
                                f"the renderer drew technique {st.technique!r} exactly as 'tsd' (not implemented yet?)"
                            )
                    row.update(
                        {
                            k: m[k]
                            for k in (
                                "frames",
                                "frame_ms_median",
                                "frame_ms_p10",
                                "frame_ms_p90",
                                "wall_ms_median",
                                "tsd_ms_median",
                                "clock",
                                "blur_levels",
                            )
                        }
                    )
                    row["passes"] = m["passes"]
                    hdrs[st] = m["hdr"]
                    if truth is not None:
                        # an untimed frame at the reference's size, compared with the truth
                        small = renderer.render(scene, st.render_settings(sweep, truth.image.shape[1::-1]),
                                                readback=("hdr",)).hdr  # fmt: skip
                        row.update(truth_errors(small, truth))
                        safe = st.label.replace(" ", "-")
                        write_error_map(out / "error_maps" / f"{label}-{safe}.png", small, truth)
                        if st in sheet_settings(settings):
                            sheet.setdefault(label, {})[st.label] = relative_difference(small, truth.image)
                    if images:
                        from app.image_output import write_image

                        safe = st.label.replace(" ", "-")
                        write_image(out / "images" / f"{label}-{safe}.png", m["ldr"])
                    # profile error against Monte Carlo and against the material's own model profile
                    if base_mat is not None:
                        tech = "none" if row["model"] == "none" else st.technique
                        if tech in ("tsd", "exact") and not {"tsd_blur", "tsd_exact"} & set(m["kinds"]):
                            tech = "none"  # every Gaussian folded into the unblurred term: plain diffuse
                        fn = technique_edge_fn(tech, row["model"], base_medium, kernel, m["ssss"])
                        row["profile_err_mc"] = edge_error(pref, fn) if fn is not None else math.nan
                        row["profile_err_model"] = (
                            edge_error(mref, fn) if (fn is not None and mref is not None) else math.nan
                        )
                except Exception as exc:  # a failing technique is a row, not the end of the sweep
                    row["status"] = "error"
                    row["error"] = _first_line(exc)
                scene_rows[st] = row
                rows.append(row)
                bar.update(1)
            # image errors against the reference (the exact one, else the proxy)
            ref_st = settings[0] if scene_rows[settings[0]]["status"] == "ok" else proxy_reference(settings)
            if ref_st is not None and scene_rows[ref_st]["status"] != "ok":
                ref_st = None
            ref = hdrs.get(ref_st) if ref_st is not None else None
            mask = lit_mask(ref) if ref is not None else None
            # and against the exact convolution at the same irradiance size, where there is one: the
            # technique's own error without the texture-resolution error of the reference
            exact_at = {
                st.tsd_size: hdrs[st]
                for st, r in scene_rows.items()
                if st.technique == "exact" and r["status"] == "ok" and st in hdrs
            }
            for st, row in scene_rows.items():
                row["reference"] = ref_st.label if ref_st is not None else ""
                if ref is not None and st in hdrs:
                    row.update(image_error(hdrs[st], ref, mask))
                same = exact_at.get(st.tsd_size) if st.technique == "tsd" else None
                if same is not None and st in hdrs:
                    row["image_rel_l1_same_size"] = image_error(hdrs[st], same)["image_rel_l1"]
            del hdrs
    finally:
        bar.close()
        renderer.release()
    sweep_s = time.perf_counter() - t_start
    if sheet:
        error_map_sheet(
            sheet,
            out / "error_maps.png",
            "signed relative difference against the path-traced truth (red: brighter, blue: darker)",
        )
    peer_res = None
    if peer:
        try:
            from app.commands.bench import peer_bench

            peer_res = peer_bench(sweep.size, sweep.peer_frames)
        except Exception as exc:
            peer_res = {"error": _first_line(exc)}
    meta = {
        "sweep": sweep.name,
        "gl": gl,
        "cpus": os.cpu_count(),
        "size": list(sweep.size),
        "shadow_size": sweep.shadow_size,
        "warmup": sweep.warmup,
        "frames": sweep.frames,
        "budget_s": sweep.budget_s,
        "photons": sweep.photons,
        "scenes": [scene_label(s) for s in scenes],
        "truth": None
        if sweep.truth is None
        else {
            "size": list(sweep.truth.size),
            "spp": sweep.truth.spp,
            "passes": sweep.truth.passes,
            "missing": truth_notes,
        },
        "sweep_s": sweep_s,
        "total_s": time.perf_counter() - t_start,
        "peer": peer_res,
        "loadavg_start": load_start,
        "loadavg_end": _loadavg(),
        "command": command,
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    }
    return write_ledger(rows, meta, out)


# -- outputs -----------------------------------------------------------------------------------------------


def _fmt(v, digits=4) -> str:
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.{digits}g}"
    return str(v)


def csv_text(rows: list[dict]) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, CSV_COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        cells = {}
        for c in CSV_COLUMNS:
            if c == "passes_ms":
                cells[c] = ";".join(f"{k}={v:.3f}" for k, v in (r.get("passes") or {}).items())
            elif c in NUMERIC_COLUMNS:
                v = r.get(c, math.nan)
                cells[c] = (
                    "nan"
                    if v in (None, "") or (isinstance(v, float) and math.isnan(v))
                    else (str(v) if isinstance(v, int) else f"{float(v):.6g}")
                )
            else:
                cells[c] = _fmt(r.get(c, ""), 6)
        w.writerow(cells)
    return buf.getvalue()


TRUTH_KEY = "truth_rel_l1_block"  # the first error axis where the path-traced truth was measured
ERROR_LABELS = {
    TRUTH_KEY: "error vs path-traced truth (rel-L1, 4x4 blocks)",
    "image_rel_l1": "image rel-L1 vs exact convolution",
}


def _finite(v) -> bool:
    return isinstance(v, (int, float, np.floating)) and bool(np.isfinite(v))


def usable(r: dict, key: str = "image_rel_l1") -> bool:
    return r.get("status") == "ok" and _finite(r.get("frame_ms_median", math.nan)) and _finite(r.get(key, math.nan))


def error_key(rows: list[dict]) -> str:
    """The truth where every scene of `rows` has it, else the exact convolution."""
    scenes = set(r["scene"] for r in rows)
    with_truth = {r["scene"] for r in rows if usable(r, TRUTH_KEY)}
    return TRUTH_KEY if scenes and with_truth == scenes else "image_rel_l1"


def pareto_front(rows: list[dict], key: str = "image_rel_l1") -> list[dict]:
    """Rows not dominated in (frame_ms_median, key): sorted by time, each strictly more accurate
    than every cheaper one."""
    pts = sorted((r for r in rows if usable(r, key)), key=lambda r: (r["frame_ms_median"], r[key]))
    front, best = [], math.inf
    for r in pts:
        if r[key] < best:
            front.append(r)
            best = r[key]
    return front


def log_slope(x, y) -> tuple[float, float, int]:
    """Least-squares slope and intercept of log y against log x (finite positive points only)."""
    x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return math.nan, math.nan, int(ok.sum())
    b, a = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return float(b), float(a), int(ok.sum())


def cost_series(rows: list[dict], sweep_like: dict) -> dict:
    """Per scene: the size series (K = kmax, auto taps) and the K series (at k_size, auto taps)."""
    out = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        tsd = [
            r
            for r in rows
            if r["scene"] == scene and r["technique"] == "tsd" and r["status"] == "ok" and r["taps"] == "auto"
        ]
        if not tsd:
            continue
        kmax = max(r["K"] for r in tsd)
        by_size = sorted((r for r in tsd if r["K"] == kmax), key=lambda r: r["tsd_size"])
        k_size = sweep_like.get("k_size")
        # the cost of K where texture-space diffusion runs at all (K whose Gaussians all fold into the
        # unblurred term render plain diffuse: a step, not a power law)
        by_k = sorted(
            (r for r in tsd if r["tsd_size"] == k_size and (r.get("blur_levels") or 0) > 0), key=lambda r: r["K"]
        )
        out[scene] = {"size": by_size, "K": by_k, "kmax": kmax, "k_size": k_size}
    return out


def slopes(series: dict) -> dict:
    res = {}
    for scene, s in series.items():
        tex = [r["tsd_size"] ** 2 for r in s["size"]]
        ks = [r["K"] for r in s["K"]]
        lv = [r.get("blur_levels") for r in s["K"]]
        res[scene] = {
            "frame_vs_texels": log_slope(tex, [r["frame_ms_median"] for r in s["size"]]),
            "tsd_vs_texels": log_slope(tex, [r["tsd_ms_median"] for r in s["size"]]),
            "frame_vs_K": log_slope(ks, [r["frame_ms_median"] for r in s["K"]]),
            "tsd_vs_K": log_slope(ks, [r["tsd_ms_median"] for r in s["K"]]),
            "tsd_vs_levels": log_slope(lv, [r["tsd_ms_median"] for r in s["K"]]),
            "sizes": [r["tsd_size"] for r in s["size"]],
            "Ks": ks,
            "levels": lv,
            "kmax": s["kmax"],
            "k_size": s["k_size"],
        }
    return res


def recommendations(rows: list[dict], thresholds=RECOMMEND_THRESHOLDS, key: str = "image_rel_l1") -> list[dict]:
    """For each error budget tau: the cheapest setting (cost: mean over scenes of the median frame
    time) within it in every scene, overall and among tsd settings only. Against the exact
    convolution the budget is absolute (error <= tau); against the truth, where every setting keeps
    the error the techniques share, it is relative to the best setting of each scene (error <= the
    scene's smallest error + tau)."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    by_label: dict[str, dict] = {}
    for r in rows:
        by_label.setdefault(r["setting"], {})[r["scene"]] = r
    floor = {s: 0.0 for s in scenes}
    if key == TRUTH_KEY:
        for s in scenes:
            errs = [r[key] for r in rows if r["scene"] == s and usable(r, key)]
            floor[s] = min(errs) if errs else math.inf
    out = []
    for tau in thresholds:
        ok = []
        for labl, per in by_label.items():
            if len(per) != len(scenes) or not all(usable(r, key) and r[key] <= floor[s] + tau for s, r in per.items()):
                continue
            cost = float(np.mean([r["frame_ms_median"] for r in per.values()]))
            ok.append((cost, labl, per))
        ok.sort(key=lambda t: t[0])
        best = ok[0] if ok else None
        # a tsd setting that blurs nothing in some scene (every Gaussian sub-texel) is the plain frame there
        best_tsd = next(
            (
                t
                for t in ok
                if next(iter(t[2].values()))["technique"] == "tsd"
                and all((r.get("blur_levels") or 0) > 0 for r in t[2].values())
            ),
            None,
        )
        out.append({"threshold": tau, "best": best, "best_tsd": best_tsd, "key": key, "floor": floor})
    return out


def markdown(rows: list[dict], meta: dict, sl: dict, recs: list[dict], fronts: dict) -> str:
    L = [f"# Accuracy/time ledger ({meta['sweep']} sweep)", ""]
    L.append(f"- GL: {meta['gl']}; {meta['cpus']} CPU(s); {meta['date']}")
    L.append(
        f"- image {meta['size'][0]}x{meta['size'][1]}, shadow maps {meta['shadow_size']}; "
        f"{meta['warmup']} warm-up frames, then the median (p10/p90) of up to {meta['frames']} frames "
        f"of `render(readback=False)` per setting (fewer, at least 3, where they would take over "
        f"{meta['budget_s']:g} s); Monte Carlo {meta['photons']:,} photons per channel"
    )
    clocks = sorted({r.get("clock") for r in rows if r.get("clock")})
    L.append(
        f"- clock: {', '.join(clocks) or 'n/a'} (cpu-synchronised: wall time with glFinish after each "
        "pass, Mesa llvmpipe's GPU timer queries see only command submission; gpu-timer: GL timer queries)"
    )
    L.append(f"- sweep took {meta['sweep_s']:.1f} s, the whole run (with the pyrender peer) {meta['total_s']:.1f} s")
    if meta.get("loadavg_start") is not None:
        L.append(
            f"- load average (1/5/15 min) at the start {meta['loadavg_start']}, at the end "
            f"{meta.get('loadavg_end')}: other processes on the machine share its cores and lengthen frames"
        )
    if meta.get("command"):
        L.append(f"- command: `{meta['command']}`")
    L += [
        "",
        "image error: against the scene's reference image (the `reference` column) on linear HDR over "
        f"lit surface pixels (coverage > 0, luminance > {LUM_FRACTION:.0%} of the 99th percentile); "
        "rel-L1 = sum|img - ref| / sum ref; max/p95: per-pixel sum_c|img - ref| / sum_c ref. "
        "`rel-L1 vs exact same size`: a tsd setting against the exact convolution at its own irradiance "
        "size (the fit/blur error without the texture-resolution error). "
        "profile error: relative L1 of the edge response against the Monte Carlo random walk, "
        "int|E - E_mc| dx / int|step - E_mc| dx (no scattering = 1); `vs model`: the same against the "
        "material's own model profile (the technique's approximation alone). `truth 4x4` / `truth px`: "
        "relative L1 against the path-traced truth on 4x4 blocks / per pixel, beside the truth's noise floor "
        "(4x4) and the largest per-channel energy difference.",
        "",
        *truth_markdown(rows, meta),
    ]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        srows = [r for r in rows if r["scene"] == scene]
        ref = next((r["reference"] for r in srows if r.get("reference")), "")
        proxy = bool(ref) and not ref.startswith("exact")
        L.append(f"## {scene}")
        L.append("")
        if not ref:
            L.append(
                "**No reference image**: neither the exact convolution nor a tsd proxy rendered; "
                "image errors are empty."
            )
        elif proxy:
            L.append(
                f"**Proxy reference**: the exact technique did not render (see its row), so `{ref}` "
                "stands in as the image reference; image errors are relative to it, not to the exact "
                "profile."
            )
        else:
            L.append(f"Reference image: `{ref}`.")
        ref_size = next((r.get("tsd_size") for r in srows if r["setting"] == ref), None)
        finer = [
            r["setting"] for r in srows if ref_size and r.get("tsd_size") not in ("", None) and r["tsd_size"] > ref_size
        ]
        if finer:
            L.append(
                f"Settings with a finer irradiance texture than the reference's {ref_size} texels "
                f"({', '.join(finer)}) are compared with a coarser image: their error includes the "
                "reference's own texture-resolution error (compare the exact rows at smaller sizes)."
            )
        L.append("")
        L.append(
            "| setting | technique | model | K | tsd size | taps | ssss taps | blur levels | frames | "
            "frame ms median | p10 | p90 | tsd ms | image rel-L1 | image max | image p95 | rel-L1 vs exact same size | "
            "profile err vs MC | profile err vs model | truth 4x4 | truth px | truth noise 4x4 | truth energy | "
            "status |"
        )
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in srows:
            status = r["status"] + (f": {r['error']}" if r.get("error") else "")
            pct = lambda v: "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{100 * v:.2f} %"
            L.append(
                "| "
                + " | ".join(
                    [
                        r["setting"],
                        r["technique"],
                        r.get("model", ""),
                        _fmt(r.get("K")),
                        _fmt(r.get("tsd_size")),
                        _fmt(r.get("taps")),
                        _fmt(r.get("ssss_taps")),
                        _fmt(r.get("blur_levels", "")),
                        _fmt(r.get("frames", "")),
                        _fmt(r.get("frame_ms_median"), 4),
                        _fmt(r.get("frame_ms_p10"), 4),
                        _fmt(r.get("frame_ms_p90"), 4),
                        _fmt(r.get("tsd_ms_median"), 4),
                        pct(r.get("image_rel_l1")),
                        pct(r.get("image_max_rel")),
                        pct(r.get("image_p95_rel")),
                        pct(r.get("image_rel_l1_same_size")),
                        pct(r.get("profile_err_mc")),
                        pct(r.get("profile_err_model")),
                        pct(r.get("truth_rel_l1_block")),
                        pct(r.get("truth_rel_l1")),
                        pct(r.get("truth_noise_block")),
                        pct(r.get("truth_energy")),
                        status.replace("|", "/"),
                    ]
                )
                + " |"
            )
        L.append("")
        fr = fronts.get(scene, [])
        if fr:
            key = error_key(rows)
            L.append(
                f"Pareto front (time, {ERROR_LABELS[key]}): "
                + " -> ".join(f"`{r['setting']}` ({r['frame_ms_median']:.1f} ms, {100 * r[key]:.2f} %)" for r in fr)
            )
            L.append("")
    L += [
        "## Cost slopes",
        "",
        "Least-squares slopes of log(time) against log(irradiance texels = tsd_size^2) over the size sweep "
        "(K = max, auto taps) and against log(K) over the K sweep (auto taps; only the K for which at least "
        "one blur pass runs: where every Gaussian folds into the unblurred term the frame is plain diffuse); "
        "`tsd` is the sum of the "
        "texture-space passes (stretch when it runs, irradiance, dilation, blurs). Slope 1 = linear.",
        "",
        "| scene | frame vs texels | tsd passes vs texels | frame vs K | tsd passes vs K "
        "| tsd passes vs blur levels | sizes | K | blur levels per K |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scene, s in sl.items():
        f = lambda t: "n/a" if math.isnan(t[0]) else f"{t[0]:.3f}"
        L.append(
            f"| {scene} | {f(s['frame_vs_texels'])} | {f(s['tsd_vs_texels'])} | {f(s['frame_vs_K'])} | "
            f"{f(s['tsd_vs_K'])} | {f(s['tsd_vs_levels'])} | {', '.join(map(str, s['sizes']))} | "
            f"{', '.join(map(str, s['Ks']))} (at {s['k_size']}) | {', '.join(map(str, s['levels']))} |"
        )
    if not sl:
        L.append("| (no tsd series measured) | | | | | | | | |")
    L.append("")
    L += ["## Peer: pyrender", ""]
    p = meta.get("peer")
    if p is None:
        L.append("Not run (--no-peer).")
    elif "error" in p:
        L.append(f"The pyrender peer failed: {p['error']}")
    else:
        L.append(
            f"`skinlab bench peer --size {p['size'][0]}x{p['size'][1]} --frames {p['frames']}` "
            f"({p['gl']}): the head, shadows off, colour+depth read back on both sides, median of "
            f"{p['frames']} whole frames (no glFinish between passes); pyrender's frame is plain PBR, "
            "Skinlab's plain-PBR frame has sss_model none, its default frame the default "
            "RenderSettings (texture-space diffusion on the skin)."
        )
        L.append("")
        L.append("| renderer | ms/frame | / pyrender |")
        L.append("|---|---|---|")
        L.append(f"| skinlab, plain PBR | {p['skinlab_ms']:.2f} | {p['ratio_skinlab_over_pyrender']:.2f} |")
        if p.get("skinlab_default_ms") is not None:
            L.append(
                f"| skinlab, default settings (tsd) | {p['skinlab_default_ms']:.2f} | "
                f"{p['ratio_default_over_pyrender']:.2f} |"
            )
        L.append(f"| pyrender | {p['pyrender_ms']:.2f} | 1 |")
    L.append("")
    key = recs[0]["key"] if recs else "image_rel_l1"
    rule = (
        "whose error against the path-traced truth (4x4 blocks) is within tau of the scene's best setting in "
        "*every* scene (every technique keeps the error they share, so the budget is relative to the best)"
        if key == TRUTH_KEY
        else "whose image rel-L1 against the reference is <= tau in *every* scene; the reference itself "
        "qualifies trivially"
    )
    L += [
        "## Recommended defaults",
        "",
        f"Rule: for each error budget tau, the cheapest setting (mean over the scenes of its median frame time) "
        f"{rule}. `tsd only` restricts this to texture-space diffusion settings that blur in every scene (what "
        "RenderSettings' tsd_size / tsd_gaussians / tsd_taps defaults choose among; one whose Gaussians are all "
        "narrower than a texel renders the plain frame). A setting must have been measured in every scene.",
        "",
        "| budget tau | cheapest setting | mean ms | errors per scene "
        "| cheapest tsd setting | mean ms | errors per scene |",
        "|---|---|---|---|---|---|---|",
    ]
    for rec in recs:

        def cell(t):
            if t is None:
                return ["none qualifies", "", ""]
            cost, labl, per = t
            return [
                f"`{labl}`",
                f"{cost:.1f}",
                ", ".join(f"{s} {100 * r[key]:.2f} %" for s, r in per.items()),
            ]

        L.append(f"| {100 * rec['threshold']:g} % | " + " | ".join(cell(rec["best"]) + cell(rec["best_tsd"])) + " |")
    if any(r.get("reference") and not r["reference"].startswith("exact") for r in rows):
        L += [
            "",
            "These recommendations are relative to a proxy reference (see above), not to the exact "
            "convolution: re-run once the exact technique renders.",
        ]
    L.append("")
    return "\n".join(L)


def write_ledger(rows: list[dict], meta: dict, out: Path) -> dict:
    from app.bench.ledger_plots import cost_plot, pareto_plot

    out = Path(out)
    key = error_key(rows)
    fronts = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        fronts[scene] = pareto_front([r for r in rows if r["scene"] == scene], key)
    k_sizes = [r["tsd_size"] for r in rows if r["technique"] == "tsd"]
    # the K sweep's size: the size with the most distinct K
    k_size = None
    if k_sizes:
        counts = {}
        for r in rows:
            if r["technique"] == "tsd" and r["taps"] == "auto":
                counts.setdefault(r["tsd_size"], set()).add(r["K"])
        k_size = max(counts, key=lambda s: (len(counts[s]), s)) if counts else None
    series = cost_series(rows, {"k_size": k_size})
    sl = slopes(series)
    recs = recommendations(rows, key=key)
    write_text_atomic(out / "ledger.csv", csv_text(rows))
    pareto_plot(rows, fronts, out / "pareto.png", key=key, label=ERROR_LABELS[key])
    cost_plot(series, sl, out / "cost.png")
    md = markdown(rows, meta, sl, recs, fronts)
    write_text_atomic(out / "ledger.md", md)

    def clean(v):
        if isinstance(v, (np.floating, float)):
            return None if math.isnan(float(v)) else float(v)
        if isinstance(v, (np.integer,)):
            return int(v)
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    rec_json = [
        {
            "threshold": r["threshold"],
            "best": r["best"][1] if r["best"] else None,
            "best_tsd": r["best_tsd"][1] if r["best_tsd"] else None,
        }
        for r in recs
    ]
    doc = {
        "meta": meta,
        "rows": rows,
        "slopes": {s: {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()} for s, d in sl.items()},
        "pareto": {s: [r["setting"] for r in f] for s, f in fronts.items()},
        "recommendations": rec_json,
        "error_axis": key,
    }
    write_text_atomic(out / "ledger.json", json.dumps(clean(doc), indent=1))
    names = ["ledger.csv", "ledger.md", "ledger.json", "pareto.png", "cost.png"]
    if (out / "error_maps.png").is_file() and key == TRUTH_KEY:
        names.append("error_maps.png")
    return {
        "rows": rows,
        "meta": meta,
        "slopes": sl,
        "recommendations": recs,
        "fronts": fronts,
        "error_axis": key,
        "files": [str(out / n) for n in names],
    }
