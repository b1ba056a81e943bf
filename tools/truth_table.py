"""Every reference scene x technique (default settings) against its cached path-traced truth at
96x96, 256 spp (the quick ledger's references; nothing is rendered by Mitsuba here): relative L1 on
4x4 blocks and per pixel, per-channel energy, the worst 8x8 block (luminance), issue 12's block
target (8x8 blocks more than 15 % off among those the truth's noise allows to judge: over/judged,
skinlab/truth/compare.py judged_blocks), the truth's noise.

    python -m tools.truth_table [SCENES] [TECHNIQUES]      # comma-separated; default all

SKINLAB_SSS_MODEL=<model> overrides every material's sss_model (burley, dipole, pbd, ...).
SKINLAB_SUPERSAMPLE=N renders the frames at N x N samples per pixel (default: the ledger's,
skinlab/bench/truth_ledger.py TRUTH_SUPERSAMPLE; 1 = each pixel's centre only).
SKINLAB_TRUTH=192 compares with the 192x192, 1024-spp references instead (frames at 192x192; the
references must be cached: `skinlab reference SCENE --size 192x192 --spp 1024`), and
SKINLAB_TRUTH=SIZE:SPP:VARIANT:SEED with a reference rendered elsewhere (tools/gpu_reference.py).
SKINLAB_BOUNCES=N sets the orders of interreflection (RenderSettings.bounces; 0 = off), and
SKINLAB_BOUNCE_RAYS=N the rays per vertex (RenderSettings.bounce_rays); SKINLAB_TSD_SIZE=N the
irradiance texels of texture-space diffusion (tsd's `size`; the other techniques as they are).
Used for the before/after tables in docs/ground-truth.md."""

from __future__ import annotations

import os
import sys

import numpy as np

from skinlab.bench.sweep import QUICK
from skinlab.bench.truth_ledger import (
    REFERENCE_SCENES,
    TRUTH_SUPERSAMPLE,
    TruthSpec,
    load_truth,
    reference_scene_names,
)
from skinlab.gl.context import create_headless_context
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene
from skinlab.truth.compare import image_error, judged_blocks, relative_difference


def truth_spec(text: str) -> TruthSpec:
    """SKINLAB_TRUTH: "" (96x96, 256 spp), "192" (192x192, 1024 spp) or SIZE:SPP:VARIANT:SEED (a
    reference rendered elsewhere, e.g. 96:131072:cuda_ad_rgb:1 by tools/gpu_reference.py)."""
    if not text:
        return TruthSpec((96, 96), 256)
    if text == "192":
        return TruthSpec((192, 192), 1024)
    try:
        size, spp, variant, seed = text.split(":")
        return TruthSpec((int(size), int(size)), int(spp), variant=variant, seed=int(seed))
    except ValueError:
        raise SystemExit(f"SKINLAB_TRUTH: expected 192 or SIZE:SPP:VARIANT:SEED, got {text!r}") from None


def main(argv: list[str]) -> int:
    scenes = argv[0].split(",") if argv and argv[0] else reference_scene_names()
    techs = argv[1].split(",") if len(argv) > 1 else ["none", "tint", "tsd", "exact", "ssss"]
    model = os.environ.get("SKINLAB_SSS_MODEL") or None
    raw = os.environ.get("SKINLAB_SUPERSAMPLE") or str(TRUTH_SUPERSAMPLE)
    if not raw.isdigit():
        raise SystemExit(f"SKINLAB_SUPERSAMPLE: expected an integer in [1, 8], got {raw!r}")
    n = int(raw)
    extra = {}
    if os.environ.get("SKINLAB_BOUNCES"):
        extra["bounces"] = int(os.environ["SKINLAB_BOUNCES"])
    if os.environ.get("SKINLAB_BOUNCE_RAYS"):
        extra["bounce_rays"] = int(os.environ["SKINLAB_BOUNCE_RAYS"])
    print(f"frames at {n} x {n} samples per pixel, box-filtered", flush=True)
    spec = truth_spec(os.environ.get("SKINLAB_TRUTH", ""))
    size = spec.size[0]
    r = Renderer(create_headless_context())
    for s in scenes:
        scene = load_scene(REFERENCE_SCENES / f"{s}.toml")
        truth = load_truth(scene, spec, progress=False)
        if truth is None:
            print(f"{s}: no cached {size}x{size}, {spec.spp}-spp {spec.variant} reference (seed {spec.seed})")
            continue
        for t in techs:
            tsd_size = os.environ.get("SKINLAB_TSD_SIZE") if t == "tsd" else None
            own = {"size": int(tsd_size)} if tsd_size else {}
            rs = RenderSettings.for_technique(
                t, size, size, shadow_size=QUICK.shadow_size, sss_model=model, supersample=n, **extra, **own
            )
            img = r.render(scene, rs, readback=("hdr",)).hdr
            e = image_error(img, truth.image)
            d = relative_difference(img, truth.image, block=8)
            worst = float(np.nanmax(np.abs(d))) if np.isfinite(d).any() else float("nan")
            j = judged_blocks(img, truth.image, truth.half_a, truth.half_b)
            energy = " ".join(f"{100 * x:+6.1f}" for x in e["energy"])
            print(
                f"{s:24s} {t:6s} 4x4 {100 * e['rel_l1_block']:6.1f}%  px {100 * e['rel_l1']:6.1f}%  energy {energy}"
                f"  worst8 {100 * worst:4.0f}%  8x8>15% {j['over']:3d}/{j['judged']:<3d}"
                f"  noise {100 * truth.noise['rel_l1_block']:.1f}%",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
