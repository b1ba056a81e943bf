"""The accuracy ledger against the path-traced truth (`skinlab bench accuracy`, docs/ground-truth.md).

For each reference scene the ledger loads the scene's Mitsuba reference (skinlab/truth) at the sweep's
truth size and samples, or the scene's own where its ``[measure]`` declares them (``truth_size``,
``truth_spp``, ``truth_rr_depth``: the close-ups, ``scene_truth_spec``), from the cache
(``--references`` renders the missing ones first), renders every setting once more at that size
(untimed), and records:

* ``truth_rel_l1`` / ``truth_rel_l1_block``: relative L1 of linear radiance over the object against
  the truth, per pixel and on 4 x 4 pixel blocks (skinlab/truth/compare.py); the block figure is the
  ledger's first error axis (robust to the reference's noise);
* ``truth_energy``: the largest per-channel energy difference over the object;
* ``truth_noise`` / ``truth_noise_block``: the reference's own noise floor (the same measures
  between the halves of its passes), printed beside each figure: differences below it are noise;
* ``truth_blocks8_over`` / ``truth_blocks8_judged`` / ``truth_blocks8_over_frac``: issue 12's block
  target, the 8 x 8 blocks more than 15 % off the truth among those its noise allows to judge
  (skinlab/truth/compare.py ``judged_blocks``: half-to-half block noise below 5 %, not dark), their
  number and their fraction;
* the frames compared with the truth are supersampled (``TruthSpec.supersample``, default
  ``TRUTH_SUPERSAMPLE``; ``RenderSettings.supersample``): the truth averages each pixel over its area
  (Mitsuba's box pixel filter), a frame without antialiasing samples each pixel's centre, which
  differs on the object's outline by far more than the scattering errors the ledger is for;
* the close-up measures a scene declares (skinlab/bench/closeup.py): ``truth_tail_2mm`` ... for a line
  profile (of luminance, and ``truth_tail_2mm_r`` ... of each channel alone), ``truth_deep_shadow``,
  ``truth_mesh_energy`` (frame minus truth, with their standard errors);
* a signed relative-difference image per setting (red: brighter than the truth, blue: darker, one
  scale for all), and a contact sheet of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.resources import scenes_root
from skinlab.truth.compare import (
    JUDGE_BLOCK,
    JUDGE_NOISE,
    JUDGE_TOL,
    MAP_SCALE,
    error_map_rgb,
    image_error,
    judged_blocks,
)

from .closeup import CHANNELS, CLOSEUP_KEYS, TAIL_KEYS, TAIL_MM, CloseupRegions, tail_key
from .ledger_row import LedgerRow, finite

REFERENCE_SCENES = scenes_root() / "reference"
# the errors measured with their uncertainty (the jackknife over the truth's passes, skinlab/truth/metrics.py)
JACKKNIFED = (
    "truth_rel_l1", "truth_rel_l1_block", "truth_flip", "truth_edge_rel_l1", "truth_profile_err", *CLOSEUP_KEYS,
)  # fmt: skip


# samples per pixel side of the frames compared with the truth (box-filtered like the truth's pixels;
# docs/ground-truth.md "The truth's pixel filter" has the measured effect of 1, 2 and 4)
TRUTH_SUPERSAMPLE = 4


@dataclass(frozen=True)
class TruthSpec:
    size: tuple[int, int]  # reference (and comparison frame) size
    spp: int  # samples per pixel of the reference
    passes: int = 4
    # RenderSettings.supersample of the frames compared with the reference (not part of its cache key)
    supersample: int = TRUTH_SUPERSAMPLE
    variant: str = "scalar_rgb"  # Mitsuba variant it was rendered with (cuda_ad_rgb: tools/gpu_reference.py)
    seed: int = 0
    rr_depth: int = 64  # ReferenceRequest.rr_depth (part of the cache key)

    def request(self):
        from skinlab.truth.reference import ReferenceRequest

        return ReferenceRequest(
            self.size[0], self.size[1], spp=self.spp, passes=self.passes, seed=self.seed, variant=self.variant,
            rr_depth=self.rr_depth,
        )  # fmt: skip

    @property
    def command_options(self) -> str:
        """`skinlab reference`'s options for this truth."""
        rr = f" --rr-depth {self.rr_depth}" if self.rr_depth != 64 else ""
        passes = f" --passes {self.passes}" if self.passes != 4 else ""
        return f"--size {self.size[0]}x{self.size[1]} --spp {self.spp}{passes}{rr}"


def scene_truth_spec(scene, spec: TruthSpec) -> TruthSpec:
    """The sweep's truth `spec` with the scene's own size, spp and Russian roulette depth where its
    ``[measure]`` declares them (the close-ups: a slit's 256x16, marble's depth 1024)."""
    from dataclasses import replace

    m = getattr(scene, "measure", None)
    if m is None:
        return spec
    return replace(
        spec,
        size=m.truth_size or spec.size,
        spp=m.truth_spp or spec.spp,
        rr_depth=m.truth_rr_depth or spec.rr_depth,
    )


def reference_scene_names(every: bool = False) -> list[str]:
    """The bundled reference scenes the ledger measures by default: those whose ``[measure]`` does not
    say ``ledger = false`` (read from the TOML alone, no scene built); ``every``: all of them."""
    import tomllib

    names = []
    for p in sorted(REFERENCE_SCENES.glob("*.toml")):
        if not every:
            measure = tomllib.loads(p.read_text(encoding="utf-8")).get("measure", {})
            if isinstance(measure, dict) and measure.get("ledger", True) is False:
                continue
        names.append(p.stem)
    return names


# Quieter references some scenes have, rendered elsewhere (tools/gpu_reference.py on a lent GPU, see
# docs/ground-truth.md "Known hard case"): where one of the asked size is in the cache, the ledger
# compares with it instead (its noise floor is reported beside every figure, as always).
QUIET_REFERENCES: dict[str, tuple[TruthSpec, ...]] = {
    "head-skin1": (
        TruthSpec((96, 96), 131072, variant="cuda_ad_rgb", seed=1),
        TruthSpec((192, 192), 114688, variant="cuda_ad_rgb", seed=1),
    ),
}


def load_truth(scene, spec: TruthSpec, render: bool = False, progress: bool = True, quiet: bool = True):
    """The scene's reference at `spec`: from the cache, or rendered (and cached) when `render`.
    None when it is not cached and not to be rendered, or Mitsuba is missing. With `quiet`, a cached
    quieter reference of the same size (QUIET_REFERENCES) is taken first."""
    if quiet and scene.source:
        for q in QUIET_REFERENCES.get(Path(scene.source).stem, ()):
            if q.size == spec.size and q != spec:
                hit = load_truth(scene, q, quiet=False)
                if hit is not None:
                    return hit
    from skinlab.truth.reference import ReferenceUnavailable, render_reference

    try:
        # not rendering: Mitsuba's version is part of the key, the variant need not run here (a GPU's reference)
        return render_reference(scene, spec.request(), progress=progress, render=render)
    except ReferenceUnavailable:
        return None


@dataclass
class TruthContext:
    """What every setting of one scene is measured against: the truth, the leave-one-group-out truths
    of its passes, the object and edge regions, the declared profile (and the truth's)."""

    truth: object  # skinlab.truth.reference.Reference
    groups: list  # the truth with each group of passes left out (jackknife)
    mask: np.ndarray
    edge: np.ndarray  # the edge region (bool (H, W))
    edge_mm: float
    edge_from: str  # "declared" | "plain frame" | ""
    exposure: float = 1.0
    spec: object = None  # the scene's MeasureSpec, if any
    points: object = None  # skinlab.truth.regions.PixelPoints
    profile: object = None  # the truth's Profile
    group_profiles: list = None
    closeup: object = None  # skinlab.bench.closeup.CloseupRegions, where the scene declares close-up measures


def truth_context(scene, truth, plain: np.ndarray | None) -> TruthContext:
    """The scene's measuring context; `plain` the plain frame at the truth's size (the edge region
    where the scene declares no edge)."""
    from skinlab.truth import regions
    from skinlab.truth.compare import object_mask
    from skinlab.truth.export import describe

    h, w = truth.image.shape[:2]
    mask = object_mask(truth.image)
    spec = getattr(scene, "measure", None)
    try:
        px = regions.pixel_points(describe(scene, w, h))
    except Exception:  # no ray caster: no profile, the edge region in pixels of 1 mm
        px = None
    width = regions.edge_width_mm(scene, spec)
    edge = regions.edge_region(mask, width, px, spec, plain)
    declared = spec is not None and spec.has_profile and px is not None
    ctx = TruthContext(
        truth, truth.pass_set.jackknife_groups(), mask, edge, width,
        "declared" if declared else ("plain frame" if plain is not None else ""),
        scene.environment.exposure, spec, px,
    )  # fmt: skip
    if declared:
        ctx.profile = regions.profile(truth.image, px, spec, mask)
        ctx.group_profiles = [regions.profile(g, px, spec, mask) for g in ctx.groups]
    across = regions.across(px, spec)[0] if declared and spec.has_tails else None
    cu = CloseupRegions(scene, spec, (w, h), across, mask)
    ctx.closeup = cu if cu.any or cu.notes else None
    return ctx


def closeup_truth(tc: TruthContext) -> dict:
    """The truth's own close-up measures, each (value, standard error from its passes), and the notes
    on what could not be measured."""
    from skinlab.truth import metrics

    cu = tc.closeup
    if cu is None:
        return {}
    out: dict = {}
    for key in cu.values(tc.truth.image):
        v, sigma, _ = metrics.jackknife(lambda t, key=key: cu.values(t)[key], tc.truth.image, tc.groups)
        out[key] = [v, sigma]
    if cu.meshes:
        out["meshes"] = sorted(cu.meshes)
    if cu.notes:
        out["notes"] = list(cu.notes)
    return out


def truth_errors(img: np.ndarray, tc) -> dict:
    """The row's truth columns; with a TruthContext also each error's uncertainty (``_sigma``) and,
    under ``"jackknife"``, the per-group values (for paired comparisons) and ``"profile"`` (the
    frame's profile across the declared line or edge)."""
    from skinlab.truth import metrics, regions

    if not isinstance(tc, TruthContext):  # a bare reference: no edges, no profile
        tc = TruthContext(tc, tc.pass_set.jackknife_groups(), tc.mask, np.zeros(tc.mask.shape, bool), math.nan, "")
    truth = tc.truth
    e = image_error(img, truth.image)
    finite = [abs(x) for x in e["energy"] if math.isfinite(x)]
    j = judged_blocks(img, truth.image, truth.half_a, truth.half_b)
    out = {
        "truth_energy": max(finite) if finite else math.nan,
        **{f"truth_energy_{c}": v for c, v in zip("rgb", e["energy"])},
        "truth_noise": truth.noise["rel_l1"],
        "truth_noise_block": truth.noise["rel_l1_block"],
        "truth_spp": int(truth.meta.get("spp") or 0),
        "truth_passes": int(truth.pass_set.count),
        "truth_edge_pixels": int(tc.edge.sum()),
        "truth_blocks8_over": j["over"],
        "truth_blocks8_judged": j["judged"],
        "truth_blocks8_over_frac": j["over_fraction"],
    }
    measures = {
        "truth_rel_l1": lambda t: metrics.rel_l1(img, t, tc.mask),
        "truth_rel_l1_block": lambda t: image_error(img, t, tc.mask)["rel_l1_block"],
        "truth_flip": lambda t: _flip(img, t, tc),
    }
    if tc.edge.any():
        measures["truth_edge_rel_l1"] = lambda t: metrics.rel_l1(img, t, tc.edge)
    if tc.closeup is not None:
        measures.update(tc.closeup.measures(img))
        if tc.closeup.meshes:
            out["truth_mesh_energy_each"] = tc.closeup.mesh_text(img, truth.image)
    jk = {}
    for key, fn in measures.items():
        v, sigma, loo = metrics.jackknife(fn, truth.image, tc.groups)
        out[key], out[f"{key}_sigma"], jk[key] = v, sigma, loo
    for key in JACKKNIFED:
        out.setdefault(key, math.nan)
        out.setdefault(f"{key}_sigma", math.nan)
    if tc.profile is not None:
        p = regions.profile(img, tc.points, tc.spec, tc.mask)
        loo = [regions.profile_error(p, g) for g in tc.group_profiles]
        out["truth_profile_err"] = regions.profile_error(p, tc.profile)
        out["truth_profile_err_sigma"] = metrics.jackknife_sigma(loo)
        jk["truth_profile_err"] = loo
        out["profile"] = p
    out["jackknife"] = jk
    return out


def _flip(img, t, tc) -> float:
    from skinlab.truth import metrics

    return metrics.flip_mean(img, t, tc.mask, tc.exposure)


def write_error_map(path: Path, img: np.ndarray, truth) -> Path:
    """The full-resolution signed relative difference per pixel (skinlab/truth/metrics.py relative_map)."""
    from skinlab.image_output import write_image
    from skinlab.truth.metrics import relative_map

    return write_image(path, error_map_rgb(relative_map(img, truth.image)))


def write_flip_map(path: Path, img: np.ndarray, tc: TruthContext) -> Path:
    from skinlab.image_output import write_image
    from skinlab.truth.compare import magma_rgb
    from skinlab.truth.metrics import flip_map

    return write_image(path, magma_rgb(flip_map(img, tc.truth.image, tc.exposure)))


def error_map_sheet(maps: dict[str, dict[str, np.ndarray]], path: Path, title: str = "") -> Path:
    """One labelled figure: a row per scene, a column per setting, of relative-difference maps
    (maps[scene][setting] = signed difference image), with the colour scale."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skinlab.atomic_write import atomic_path

    scenes = list(maps)
    cols = list(dict.fromkeys(c for s in scenes for c in maps[s]))
    fig, axes = plt.subplots(
        len(scenes), len(cols), figsize=(1.9 * len(cols) + 0.8, 1.9 * len(scenes) + 0.6), squeeze=False
    )
    for i, s in enumerate(scenes):
        for j, c in enumerate(cols):
            ax = axes[i][j]
            ax.set_xticks([])
            ax.set_yticks([])
            if c in maps[s]:
                ax.imshow(error_map_rgb(maps[s][c]), interpolation="nearest")
            if i == 0:
                ax.set_title(c, fontsize=8)
            if j == 0:
                ax.set_ylabel(s, fontsize=7)
    sm = plt.cm.ScalarMappable(cmap="RdBu_r", norm=plt.Normalize(-100 * MAP_SCALE, 100 * MAP_SCALE))
    fig.colorbar(sm, ax=axes, fraction=0.02, pad=0.01, label="(frame - truth) / truth, % (per pixel)")
    if title:
        fig.suptitle(title, fontsize=9)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=90)
    finally:
        plt.close(fig)
    return Path(path)


def _pct(v) -> str:
    return "" if v is None or not isinstance(v, (int, float)) or not math.isfinite(v) else f"{100 * v:.1f} %"


TRUTH_BLOCK_KEY = "truth_rel_l1_block"


def _pm(r: LedgerRow, key: str, pct: bool, pm: str = "+-") -> str:
    v, s = r.get(key), r.get(f"{key}_sigma")
    if not finite(v):
        return ""
    mark = "= " if r.ties_best in ("best", "tie") and key == TRUTH_BLOCK_KEY else ""
    if pct:
        return mark + f"{100 * v:.1f}" + (f" {pm} {100 * s:.1f}" if finite(s) else "") + " %"
    return mark + f"{v:.3f}" + (f" {pm} {s:.3f}" if finite(s) else "")


def _blocks(r: LedgerRow) -> str:
    over, judged = r.truth_blocks8_over, r.truth_blocks8_judged
    if not isinstance(over, int) or not isinstance(judged, int):
        return ""
    return f"{over} / {judged}"


TRUTH_TABLES = (  # ledger.md's tables against the truth: column, what it measures, shown in per cent
    ("truth_rel_l1_block", "relative L1 on 4x4 blocks", True),
    ("truth_rel_l1", "relative L1 per pixel", True),
    ("truth_flip", "FLIP mean (tone-mapped)", False),
    ("truth_edge_rel_l1", "relative L1 per pixel within the edge region", True),
    ("truth_profile_err", "relative L1 of the profile across the declared line or edge", True),
)


def _intro_lines(t: dict) -> list[str]:
    """How the compared frames were rendered and the truths measured; which scenes lack one (and why),
    which were compared with a quieter one."""
    L = [
        "## Against the path-traced truth",
        "",
        f"Each setting rendered once more at {t['size'][0]}x{t['size'][1]} (a scene's own truth size where its "
        "`[measure]` declares one: the truths table has each; untimed; "
        + (
            f"{t['supersample']} x {t['supersample']} samples per pixel, box-filtered like the truth's pixels"
            if t.get("supersample", 1) > 1
            else "one sample at each pixel's centre"
        )
        + ") and compared with the scene "
        f"path-traced by Mitsuba 3 (volpathmis, at least {t['spp']} spp in {t['passes']} passes: every pass cached "
        "for it counts, the table below has each truth's own; `skinlab reference`, "
        "docs/ground-truth.md): relative L1 of linear radiance over the object on 4x4-pixel blocks (per pixel in "
        "the per-scene tables). `noise` is the reference's own noise floor: the same measure between the halves "
        "of its passes (the full reference is about half as noisy); differences below it are not resolved. Every "
        "error is given with its standard error from the truth's passes (the delete-a-group jackknife over up to "
        "8 groups of passes, skinlab/truth/metrics.py); two settings are told apart when their errors differ by "
        "more than twice the standard error of the difference.",
        "",
    ]
    for scene, why in (t.get("missing") or {}).items():
        L.append(f"- **{scene}**: {why}")
    for scene, what in (t.get("quiet") or {}).items():
        L.append(f"- **{scene}**: {what}")
    if t.get("missing") or t.get("quiet"):
        L.append("")
    return L


def _truths_table(per_scene: dict) -> list[str]:
    """Per scene what its truth took (spp, passes, time), its noise and its edge region."""
    if not per_scene:
        return []
    L = [
        "The truths (each the mean of its passes; spp and path-tracing time are what the cached reference took, "
        "summed over the runs that rendered its passes; the edge region is where the edge errors are measured):",
        "",
        "| scene | tests | size | spp | passes | path tracing s | noise px | noise 4x4 | edge region |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for sc, d in per_scene.items():
        edge = (
            f"{d['edge_pixels']} px within {d['edge_mm']:.1f} mm of the {d['edge_from']} edges"
            if d.get("edge_pixels")
            else "none found"
        )
        sec = d.get("seconds")
        size = "x".join(str(x) for x in d["size"]) if d.get("size") else ""
        if d.get("rr_depth", 64) != 64:
            size += f" (rr_depth {d['rr_depth']})"
        L.append(
            f"| {sc} | {d.get('tests') or ''} | {size} | {d.get('spp')} | {d.get('passes')} | "
            f"{'' if sec is None else f'{sec:.0f}'} | {_pct(d.get('noise'))} | {_pct(d.get('noise_block'))} | "
            f"{edge} |"
        )
    return [*L, ""]


def _error_table(rows: list[LedgerRow], scenes: list[str], key: str, what: str, pct: bool) -> list[str]:
    """Settings x scenes of one error against the truth (each +- its standard error, the best and its ties
    marked), with the mean timed frame; nothing where no scene measured it."""
    have = [s for s in scenes if any(finite(r[key]) for r in rows if r.scene == s)]
    if not have:
        return []
    noise = {
        s: next((r.truth_noise_block for r in rows if r.scene == s and finite(r.truth_noise_block)), None) for s in have
    }
    L = [f"**{what}** (+- its standard error from the truth's passes; `=` marks the best and the settings "
         "the noise cannot tell from it):", ""]  # fmt: skip
    head = " | ".join(f"{s} (noise {_pct(noise[s])})" if key == TRUTH_BLOCK_KEY else s for s in have)
    # the time is the timed frames' (at the ledger's size, as users render them: no supersampling)
    L.append("| setting | " + head + " | mean ms (timed, 1 spp) |")
    L.append("|---|" + "---|" * (len(have) + 1))
    for labl, per in _by_label(rows).items():
        cells = [_pm(per[s], key, pct) if s in per else "" for s in have]
        ms = [per[s].frame_ms_median for s in have if s in per]
        ms = [m for m in ms if finite(m)]
        mean_ms = f"{sum(ms) / len(ms):.1f}" if ms else ""
        L.append(f"| {labl} | " + " | ".join(cells) + f" | {mean_ms} |")
    return [*L, ""]


CLOSEUP_TABLES = (  # ledger.md's close-up tables (skinlab/bench/closeup.py): the columns, what they measure
    (TAIL_KEYS, "the share of the light (luminance) in view beyond "
     + ", ".join(f"{d:g}" for d in TAIL_MM) + " mm from the line"),
    (("truth_deep_shadow",), "the deep shadow's level: its mean luminance as a share of the lit surface's "
     "(regions found by ray casting)"),
)  # fmt: skip


def _measure_table(rows: list[LedgerRow], cols: list[tuple[str, str]], keys: tuple[str, ...], what: str,
                   per_scene: dict, pm: str) -> tuple:  # fmt: skip
    """closeup_tables' table of one measure over `cols` (scene, column)."""
    title = (f"Close-ups: {what}", f" (the frame's; in brackets frame minus truth {pm} its standard error from "
             "the truth's passes, in percentage points; the truth's in the header)")  # fmt: skip
    head = []
    for s, k in cols:
        tv = ((per_scene.get(s) or {}).get("closeup") or {}).get(k)
        name = s if len(keys) == 1 else f"{s} > {k.removeprefix('truth_tail_')}"
        head.append(name + (f" (truth {100 * tv[0]:.2f} {pm} {100 * tv[1]:.2f} %)" if tv and finite(tv[0]) else ""))
    body = []
    for labl, per in _by_label(rows).items():
        cells = []
        for s, k in cols:
            r = per.get(s)
            tv = ((per_scene.get(s) or {}).get("closeup") or {}).get(k)
            if r is None or not finite(r[k]) or not tv:
                cells.append("")
                continue
            sig = r.get(f"{k}_sigma")
            cells.append(
                f"{100 * (tv[0] + r[k]):.2f} % ({100 * r[k]:+.2f}"
                + (f" {pm} {100 * sig:.2f}" if finite(sig) else "")
                + ")"
            )
        body.append([labl, *cells])
    return title, ["setting", *head], body


def closeup_tables(rows: list[LedgerRow], scenes: list[str], per_scene: dict, pm: str = "+-") -> list[tuple]:
    """Per declared close-up measure one table of settings x (scene, measure), as (title, header, body):
    the frame's value and, in brackets, frame minus truth `pm` its standard error, the truth's value `pm` its
    own in the header; the per-mesh energies as text. Shared by ledger.md and ledger.html (which passes
    one scene at a time); nothing for a measure no scene here declares."""
    out: list[tuple] = []
    for keys, what in CLOSEUP_TABLES:
        cols = [(s, k) for s in scenes for k in keys if any(finite(r[k]) for r in rows if r.scene == s)]
        if cols:
            out.append(_measure_table(rows, cols, keys, what, per_scene, pm))
        if keys == TAIL_KEYS:  # the tails per channel after the luminance's
            out += channel_tail_table(rows, scenes, per_scene, pm)
    have = [s for s in scenes if any(finite(r.truth_mesh_energy) for r in rows if r.scene == s)]
    if have:
        title = ("Close-ups: each visible mesh's energy", " (relative difference of its R/G/B sums against the "
                 f"truth's; the largest magnitude {pm} its standard error)")  # fmt: skip
        body = []
        for labl, per in _by_label(rows).items():
            cells = [
                f"{per[s].truth_mesh_energy_each} (largest {_pm(per[s], 'truth_mesh_energy', True, pm)})"
                if s in per and finite(per[s].truth_mesh_energy) else ""
                for s in have
            ]  # fmt: skip
            body.append([labl, *cells])
        out.append((title, ["setting", *have], body))
    return out


def channel_tail_table(rows: list[LedgerRow], scenes: list[str], per_scene: dict, pm: str = "+-") -> list[tuple]:
    """The tails per channel (closeup_tables' form, one table or none): settings x (scene, distance), each
    cell the R/G/B frame minus truth of each channel's own share beyond the distance, in percentage points,
    `pm` the largest of the three standard errors; the truth's R/G/B in the header. Only the scenes whose
    rows have them (a line profile; an older ledger.csv has none)."""

    def keys(d: float) -> list[str]:
        return [tail_key(d, c) for c in CHANNELS]

    def have(r: LedgerRow, d: float) -> bool:
        return all(finite(r[k]) for k in keys(d))

    cols = [(s, d) for s in scenes for d in TAIL_MM if any(have(r, d) for r in rows if r.scene == s)]
    if not cols:
        return []
    title = ("Close-ups: the tails per channel", " (each channel's own share of its light in view beyond "
             + ", ".join(f"{d:g}" for d in TAIL_MM) + f" mm from the line: frame minus truth, R/G/B, in percentage "
             f"points, {pm} the largest of the three standard errors from the truth's passes; the truth's R/G/B in "
             "the header)")  # fmt: skip
    head = []
    for s, d in cols:
        closeup = (per_scene.get(s) or {}).get("closeup") or {}
        tv = [closeup.get(k) for k in keys(d)]
        known = all(t and finite(t[0]) for t in tv)
        head.append(f"{s} > {d:g}mm" + (f" (truth {'/'.join(f'{100 * t[0]:.2f}' for t in tv)} %)" if known else ""))
    body = []
    for labl, per in _by_label(rows).items():
        cells = []
        for s, d in cols:
            r = per.get(s)
            if r is None or not have(r, d):
                cells.append("")
                continue
            sig = [r[f"{k}_sigma"] for k in keys(d) if finite(r[f"{k}_sigma"])]
            cells.append(
                "/".join(f"{100 * r[k]:+.2f}" for k in keys(d)) + (f" {pm} {100 * max(sig):.2f}" if sig else "")
            )
        body.append([labl, *cells])
    return [(title, ["setting", *head], body)]


def closeup_notes(per_scene: dict) -> dict[str, list[str]]:
    """Per scene the close-up measures it declares but could not measure, and why."""
    return {s: d["closeup"]["notes"] for s, d in per_scene.items() if (d.get("closeup") or {}).get("notes")}


def _closeup_tables(rows: list[LedgerRow], scenes: list[str], per_scene: dict) -> list[str]:
    """ledger.md's close-up tables (closeup_tables) and the measures not measured."""
    L: list[str] = []
    for (what, how), head, body in closeup_tables(rows, scenes, per_scene):
        L += [f"**{what}**{how}:", "", "| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
        L += ["| " + " | ".join(b) + " |" for b in body]
        L.append("")
    notes = closeup_notes(per_scene)
    L += [f"- **{s}**: not measured: {'; '.join(n)}" for s, n in notes.items()]
    return [*L, ""] if notes else L


def _blocks_table(rows: list[LedgerRow], scenes: list[str]) -> list[str]:
    """Issue 12's block target per setting and scene: 8x8 blocks off the truth, of those judged."""
    L = [
        f"{JUDGE_BLOCK}x{JUDGE_BLOCK}-pixel blocks more than {100 * JUDGE_TOL:.0f} % off the truth (luminance) of "
        f"those its noise allows to judge (half-to-half block noise below {100 * JUDGE_NOISE:.0f} %, not dark): "
        "over / judged.",
        "",
        "| setting | " + " | ".join(scenes) + " |",
        "|---|" + "---|" * len(scenes),
    ]
    for labl, per in _by_label(rows).items():
        cells = [_blocks(per[s]) if s in per else "" for s in scenes]
        L.append(f"| {labl} | " + " | ".join(cells) + " |")
    return L


def _by_label(rows: list[LedgerRow]) -> dict[str, dict[str, LedgerRow]]:
    """Setting label -> scene -> row (in the rows' order)."""
    by_label: dict[str, dict[str, LedgerRow]] = {}
    for r in rows:
        by_label.setdefault(r.setting, {})[r.scene] = r
    return by_label


ERROR_MAPS = (
    "Error maps: `error_maps/SCENE-SETTING.png` for every setting, `error_maps.png` for one setting per "
    "technique: (frame - truth) / truth of luminance per pixel (at the truth's size; the truth floored at 1 % "
    "of its 99th percentile), red brighter, blue darker, full colour at +-50 %; `flip_maps/SCENE-SETTING.png`: "
    "the FLIP map of the tone-mapped frames (magma, 0 to 1). Per-pixel errors include the truth's own "
    "per-pixel noise (about half the `noise px` between the halves): a bias the jackknife does not remove."
)


def truth_markdown(rows: list[LedgerRow], meta: dict) -> list[str]:
    """The ledger's section against the truth: what the truths took, a table of settings x scenes per
    error (4x4 blocks with the reference's noise floor beside it, per pixel, FLIP, the edge region, the
    profile), the block target, what is missing, and the error maps."""
    t = meta.get("truth")
    if not t:
        return []
    L = _intro_lines(t)
    scenes = [s for s in dict.fromkeys(r.scene for r in rows) if s not in (t.get("missing") or {})]
    if not scenes:
        return [*L, ""]
    L += _truths_table(t.get("scenes") or {})
    for key, what, pct in TRUTH_TABLES:
        L += _error_table(rows, scenes, key, what, pct)
    L += _closeup_tables(rows, scenes, t.get("scenes") or {})
    return [*L, *_blocks_table(rows, scenes), "", ERROR_MAPS, ""]
