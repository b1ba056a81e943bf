"""A one-off analysis, not a feature: every reference scene x technique (default settings) against its
cached path-traced truth, the ledger's truth measures (skinlab/bench/truth_ledger.py truth_errors)
without the ledger's sweep, timing and peers, so that a change can be checked against the truth in
seconds. Nothing is rendered by Mitsuba here. Per row: relative L1 on 4x4 blocks and per pixel,
per-channel energy, the worst 8x8 block (luminance), issue 12's block target (8x8 blocks more than
15 % off among those the truth's noise allows to judge: over/judged, skinlab/truth/compare.py
judged_blocks), the truth's noise. Used for the before/after tables in docs/ground-truth.md.

    python -m tools.truth_table [SCENES] [TECHNIQUES] [--truth SIZE:SPP[:VARIANT[:SEED]]]
        [--sss-model MODEL] [--supersample N] [--bounces N] [--bounce-rays N] [--tsd-size N]

SCENES and TECHNIQUES are comma-separated ("" or left out: every ledger scene; none, tint, tsd, exact,
ssss). --truth picks the cached references (default 96:256, the quick ledger's; 192:1024 the full
ledger's; SIZE:SPP:cuda_ad_rgb:1 one rendered elsewhere, tools/gpu_reference.py): the frames are
rendered at its size. --sss-model overrides every material's sss_model (burley, dipole, pbd, ...);
--supersample the frames' samples per pixel (default the ledger's TRUTH_SUPERSAMPLE; 1 = each
pixel's centre); --bounces and --bounce-rays the interreflection (RenderSettings); --tsd-size the
irradiance texels of texture-space diffusion (the other techniques as they are)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

DEFAULT_TECHNIQUES = "none,tint,tsd,exact,ssss"


def truth_spec(text: str):
    """--truth: SIZE:SPP[:VARIANT[:SEED]] (square references, 4 passes)."""
    from skinlab.bench.truth_ledger import TruthSpec

    parts = text.split(":")
    try:
        if not 2 <= len(parts) <= 4:
            raise ValueError
        size, spp = int(parts[0]), int(parts[1])
        variant = parts[2] if len(parts) > 2 else "scalar_rgb"
        seed = int(parts[3]) if len(parts) > 3 else 0
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected SIZE:SPP[:VARIANT[:SEED]], got {text!r}") from None
    return TruthSpec((size, size), spp, variant=variant, seed=seed)


def parser() -> argparse.ArgumentParser:
    from skinlab.bench.truth_ledger import TRUTH_SUPERSAMPLE

    ap = argparse.ArgumentParser(prog="python -m tools.truth_table", description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="?", default="", help="comma-separated reference scenes (default: the ledger's)")
    ap.add_argument("techniques", nargs="?", default=DEFAULT_TECHNIQUES, help=f"default {DEFAULT_TECHNIQUES}")
    ap.add_argument("--truth", type=truth_spec, default="96:256", help="SIZE:SPP[:VARIANT[:SEED]] (default 96:256)")
    ap.add_argument("--sss-model", default=None, help="override every material's sss_model")
    ap.add_argument("--supersample", type=int, default=TRUTH_SUPERSAMPLE, choices=range(1, 9), metavar="N")
    ap.add_argument("--bounces", type=int, default=None, help="orders of interreflection (0: off)")
    ap.add_argument("--bounce-rays", type=int, default=None, help="interreflection rays per vertex")
    ap.add_argument("--tsd-size", type=int, default=None, help="texture-space diffusion's texels per side")
    return ap


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    from skinlab.bench.sweep import QUICK
    from skinlab.bench.truth_ledger import REFERENCE_SCENES, load_truth, reference_scene_names, truth_errors
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.compare import relative_difference

    scenes = args.scenes.split(",") if args.scenes else reference_scene_names()
    techs = args.techniques.split(",")
    extra = {k: v for k, v in (("bounces", args.bounces), ("bounce_rays", args.bounce_rays)) if v is not None}
    spec = args.truth
    size = spec.size[0]
    print(f"frames at {args.supersample} x {args.supersample} samples per pixel, box-filtered", flush=True)
    r = Renderer(create_headless_context())
    try:
        for s in scenes:
            scene = load_scene(REFERENCE_SCENES / f"{s}.toml")
            truth = load_truth(scene, spec, progress=False)
            if truth is None:
                print(f"{s}: no cached {size}x{size}, {spec.spp}-spp {spec.variant} reference (seed {spec.seed})")
                continue
            for t in techs:
                own = {"size": args.tsd_size} if t == "tsd" and args.tsd_size else {}
                rs = RenderSettings.for_technique(
                    t, size, size, shadow_size=QUICK.shadow_size, sss_model=args.sss_model,
                    supersample=args.supersample, **extra, **own,
                )  # fmt: skip
                img = r.render(scene, rs, readback=("hdr",)).hdr
                e = truth_errors(img, truth)
                d = relative_difference(img, truth.image, block=8)
                worst = float(np.nanmax(np.abs(d))) if np.isfinite(d).any() else float("nan")
                energy = " ".join(f"{100 * e[f'truth_energy_{c}']:+6.1f}" for c in "rgb")
                block, px, noise = (100 * e[k] for k in ("truth_rel_l1_block", "truth_rel_l1", "truth_noise_block"))
                over, judged = e["truth_blocks8_over"], e["truth_blocks8_judged"]
                print(
                    f"{s:24s} {t:6s} 4x4 {block:6.1f}%  px {px:6.1f}%  energy {energy}"
                    f"  worst8 {100 * worst:4.0f}%  8x8>15% {over:3d}/{judged:<3d}  noise {noise:.1f}%",
                    flush=True,
                )
    finally:
        r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
