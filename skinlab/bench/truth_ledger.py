"""The accuracy ledger against the path-traced truth (`skinlab bench accuracy`, docs/ground-truth.md).

For each reference scene the ledger loads the scene's Mitsuba reference (skinlab/truth) at the sweep's
truth size from the cache (``--references`` renders the missing ones first), renders every setting
once more at that size (untimed), and records:

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
    relative_difference,
)

REFERENCE_SCENES = scenes_root() / "reference"
TRUTH_COLUMNS = [
    "truth_rel_l1",
    "truth_rel_l1_block",
    "truth_energy",
    "truth_noise",
    "truth_noise_block",
    "truth_blocks8_over",
    "truth_blocks8_judged",
    "truth_blocks8_over_frac",
]


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

    def request(self):
        from skinlab.truth.reference import ReferenceRequest

        return ReferenceRequest(
            self.size[0], self.size[1], spp=self.spp, passes=self.passes, seed=self.seed, variant=self.variant
        )


def reference_scene_names() -> list[str]:
    return sorted(p.stem for p in REFERENCE_SCENES.glob("*.toml"))


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


def truth_errors(img: np.ndarray, truth) -> dict:
    e = image_error(img, truth.image)
    finite = [abs(x) for x in e["energy"] if math.isfinite(x)]
    j = judged_blocks(img, truth.image, truth.half_a, truth.half_b)
    return {
        "truth_rel_l1": e["rel_l1"],
        "truth_rel_l1_block": e["rel_l1_block"],
        "truth_energy": max(finite) if finite else math.nan,
        "truth_noise": truth.noise["rel_l1"],
        "truth_noise_block": truth.noise["rel_l1_block"],
        "truth_blocks8_over": j["over"],
        "truth_blocks8_judged": j["judged"],
        "truth_blocks8_over_frac": j["over_fraction"],
    }


def write_error_map(path: Path, img: np.ndarray, truth) -> Path:
    from skinlab.image_output import write_image

    return write_image(path, error_map_rgb(relative_difference(img, truth.image)))


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
    fig.colorbar(sm, ax=axes, fraction=0.02, pad=0.01, label="(frame - truth) / truth, % (4x4 blocks)")
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


def _blocks(r: dict) -> str:
    over, judged = r.get("truth_blocks8_over"), r.get("truth_blocks8_judged")
    if not isinstance(over, int) or not isinstance(judged, int):
        return ""
    return f"{over} / {judged}"


def truth_markdown(rows: list[dict], meta: dict) -> list[str]:
    """The ledger's section against the truth: a table of settings x scenes (error on 4x4 blocks,
    the reference's noise floor beside it), what is missing, and the error maps."""
    t = meta.get("truth")
    if not t:
        return []
    L = [
        "## Against the path-traced truth",
        "",
        f"Each setting rendered once more at {t['size'][0]}x{t['size'][1]} (untimed; "
        + (
            f"{t['supersample']} x {t['supersample']} samples per pixel, box-filtered like the truth's pixels"
            if t.get("supersample", 1) > 1
            else "one sample at each pixel's centre"
        )
        + ") and compared with the scene "
        f"path-traced by Mitsuba 3 (volpathmis, {t['spp']} spp in {t['passes']} passes; `skinlab reference`, "
        "docs/ground-truth.md): relative L1 of linear radiance over the object on 4x4-pixel blocks (per pixel in "
        "the per-scene tables). `noise` is the reference's own noise floor: the same measure between the halves "
        "of its passes (the full reference is about half as noisy); differences below it are not resolved.",
        "",
    ]
    for scene, why in (t.get("missing") or {}).items():
        L.append(f"- **{scene}**: {why}")
    for scene, what in (t.get("quiet") or {}).items():
        L.append(f"- **{scene}**: {what}")
    if t.get("missing") or t.get("quiet"):
        L.append("")
    scenes = [s for s in dict.fromkeys(r["scene"] for r in rows) if s not in (t.get("missing") or {})]
    if not scenes:
        return [*L, ""]
    noise = {
        s: next((r.get("truth_noise_block") for r in rows if r["scene"] == s and r.get("truth_noise_block")), None)
        for s in scenes
    }
    # the time is the timed frames' (at the ledger's size, as users render them: no supersampling)
    L.append(
        "| setting | " + " | ".join(f"{s} (noise {_pct(noise[s])})" for s in scenes) + " | mean ms (timed, 1 spp) |"
    )
    L.append("|---|" + "---|" * (len(scenes) + 1))
    by_label: dict[str, dict] = {}
    for r in rows:
        by_label.setdefault(r["setting"], {})[r["scene"]] = r
    for labl, per in by_label.items():
        cells = [_pct(per[s].get("truth_rel_l1_block")) if s in per else "" for s in scenes]
        ms = [per[s].get("frame_ms_median") for s in scenes if s in per]
        ms = [m for m in ms if isinstance(m, (int, float)) and math.isfinite(m)]
        mean_ms = f"{sum(ms) / len(ms):.1f}" if ms else ""
        L.append(f"| {labl} | " + " | ".join(cells) + f" | {mean_ms} |")
    L += [
        "",
        f"{JUDGE_BLOCK}x{JUDGE_BLOCK}-pixel blocks more than {100 * JUDGE_TOL:.0f} % off the truth (luminance) of "
        f"those its noise allows to judge (half-to-half block noise below {100 * JUDGE_NOISE:.0f} %, not dark): "
        "over / judged.",
        "",
        "| setting | " + " | ".join(scenes) + " |",
        "|---|" + "---|" * len(scenes),
    ]
    for labl, per in by_label.items():
        cells = [_blocks(per[s]) if s in per else "" for s in scenes]
        L.append(f"| {labl} | " + " | ".join(cells) + " |")
    L += [
        "",
        "Error maps: `error_maps/SCENE-SETTING.png` for every setting, `error_maps.png` for one setting per "
        "technique: (frame - truth) / truth of luminance on 4x4 blocks, red brighter, blue darker, full colour "
        "at +-50 %.",
        "",
    ]
    return L
