"""`skinlab reference [SCENE] --out PATH.exr --size WxH --spp N [--passes P] [--seed S] [--variant V]
[--until-noise X] [--time S]`: the scene path-traced volumetrically by Mitsuba 3 (the image ground truth;
docs/ground-truth.md), in passes saved as they finish (a killed run resumes; skinlab/truth/passes.py)."""

from __future__ import annotations

import json

from skinlab.commands.scene_options import add_scene_edit_options, scene_edits_from_args
from skinlab.render.settings import parse_size


def register(sub) -> None:
    p = sub.add_parser(
        "reference",
        help="path-trace a scene volumetrically with Mitsuba 3 (the ground truth the ledger measures against)",
        description="Path-traces the scene with Mitsuba 3's volumetric path tracer with spectral MIS "
        "(volpathmis): subsurface materials become homogeneous media with the medium Skinlab derives from "
        "them, inside their boundary (none at index 1, a rough dielectric otherwise). Renders in independent "
        "passes and reports the noise floor (relative L1 between the halves of the passes, per pixel and on "
        "4x4 blocks). Cached by content in $SKINLAB_CACHE_DIR/reference (default ~/.cache/skinlab/reference). "
        "See docs/ground-truth.md.",
    )
    p.add_argument("scene", nargs="?", help="scene file (TOML); default: the Lee Perry-Smith head")
    p.add_argument(
        "--out", default="out/reference.exr", help="linear EXR with alpha (default out/reference.exr); a .png "
        "beside it is tone mapped like skinlab render's"
    )  # fmt: skip
    p.add_argument("--size", default="192x192", help="WIDTHxHEIGHT in pixels (default 192x192)")
    p.add_argument("--spp", type=int, default=1024, help="samples per pixel over all passes (default 1024)")
    p.add_argument("--passes", type=int, default=4, help="independent passes, >= 2, for the noise floor (default 4)")
    p.add_argument("--seed", type=int, default=0, help="random seed, >= 0 (default 0)")
    p.add_argument(
        "--variant", default="scalar_rgb", choices=("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb"),
        help="Mitsuba variant (default scalar_rgb: any CPU; llvm_ad_rgb needs libllvm19; cuda_ad_rgb an NVIDIA GPU)",
    )  # fmt: skip
    p.add_argument(
        "--sun-deg", type=float, default=0.0, help="angular diameter of directional lights in degrees, 0-10 "
        "(default 0: a delta light as in the realtime frame; e.g. 0.53 for the sun: makes lights behind a "
        "dielectric boundary reachable by BSDF sampling)"
    )  # fmt: skip
    p.add_argument("--max-depth", type=int, default=-1, help="path length limit (default -1: none)")
    p.add_argument(
        "--until-noise", type=noise_level, default=None, metavar="X",
        help="add passes (of SPP/PASSES samples each) until the noise floor is at most X (a fraction, 0.01, "
        "or a percentage, 1%%), measured as --noise-on says; passes already cached count",
    )  # fmt: skip
    p.add_argument(
        "--time", type=float, default=None, metavar="S",
        help="add passes for S seconds (with --until-noise: whichever comes first); every pass is saved as it "
        "finishes, so the reference only gets quieter from run to run",
    )  # fmt: skip
    p.add_argument(
        "--noise-on", choices=("block", "pixel"), default="block",
        help="the noise --until-noise reads: block (relative L1 between the halves on 4x4 blocks, the ledger's) or "
        "pixel (per pixel) (default block)",
    )  # fmt: skip
    p.add_argument(
        "--rr-depth", type=int, default=64, help="path depth from which Russian roulette ends paths (default 64; "
        "media with a single-scattering albedo near 1, whose light travels hundreds of scattering events, need "
        "about 1 / (1 - albedo) or more: the slit-marble reference takes 1024)"
    )  # fmt: skip
    p.add_argument("--no-cache", action="store_true", help="render even when an identical reference is cached")
    p.add_argument("--json", action="store_true", help="print the result (path, noise floor, time, notes) as JSON")
    p.add_argument(
        "--export-xml",
        metavar="DIR",
        help="write the path tracer's scene as a Mitsuba 3 scene file, DIR/scene.xml with its meshes (PLY) and "
        "textures (EXR), for Mitsuba alone (`mitsuba DIR/scene.xml`), instead of rendering (default: render)",
    )
    add_scene_edit_options(p)  # --preset, --set KEY=VALUE, --mm-per-unit, as skinlab render's
    p.set_defaults(func=run)


SEED_LIMIT = 1 << 32  # Mitsuba's sampler seed is a 32-bit unsigned integer
DEPTH_LIMIT = (1 << 31) - 1  # and its path depths 32-bit signed ones


def _check_path_options(args) -> None:
    """--seed and --max-depth in what Mitsuba takes (past it: its RuntimeError, a traceback)."""
    if not 0 <= args.seed < SEED_LIMIT:
        raise ValueError(f"--seed: expected an integer in [0, {SEED_LIMIT - 1}], got {args.seed}")
    if not (args.max_depth == -1 or 1 <= args.max_depth <= DEPTH_LIMIT):
        raise ValueError(
            f"--max-depth: expected -1 (no limit) or a path length in [1, {DEPTH_LIMIT}], got {args.max_depth}"
        )


def run(args) -> int:
    from skinlab.cli import UserError
    from skinlab.image_output import check_output_path, image_format, write_image
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.reference import ReferenceRequest, ReferenceUnavailable, render_reference

    _check_path_options(args)
    if args.export_xml:
        return export_xml(args)
    out = check_output_path(args.out, "--out")  # before minutes of path tracing
    check_output_path(out.with_suffix(".png"), "--out")
    if image_format(out) != "exr":
        raise ValueError(f"--out: the reference is linear radiance: expected a .exr path, got {out}")
    w, h = parse_size(args.size)
    req = ReferenceRequest(
        w, h, spp=args.spp, passes=args.passes, seed=args.seed, variant=args.variant,
        sun_deg=args.sun_deg, max_depth=args.max_depth, rr_depth=args.rr_depth,
    )  # fmt: skip
    scene = load_scene(args.scene, scene_edits_from_args(args))
    try:
        ref = render_reference(
            scene, req, progress=not args.json, use_cache=not args.no_cache, until_noise=args.until_noise,
            time_s=args.time, noise_measure=args.noise_on,
        )  # fmt: skip
    except ReferenceUnavailable as exc:
        raise UserError(str(exc)) from None
    written = [str(write_image(out, ref.image).resolve())]
    png = out.with_suffix(".png")
    written.append(str(write_image(png, tone_mapped(ref.image, scene.environment.exposure)).resolve()))
    noise_png = out.with_name(out.stem + "-noise.png")
    written.append(str(write_image(noise_png, noise_map_rgb(ref)).resolve()))
    nf = ref.noise
    result = {
        "scene": scene.name,
        "outputs": written,
        "size": [w, h],
        "spp": ref.meta.get("spp", req.spp),
        "passes": ref.meta.get("passes", req.passes),
        "variant": req.variant,
        "rr_depth": req.rr_depth,
        "cached": ref.cached,
        "render_seconds": ref.meta["seconds"],
        "seconds_this_run": ref.meta.get("seconds_this_run", 0.0),
        "passes_rendered": ref.meta.get("passes_rendered", 0),
        "noise_floor": nf,
        "pixel_standard_error": ref.meta.get("pixel_standard_error"),
        "notes": ref.meta["notes"],
        "key": ref.key,
    }
    if args.json:
        from skinlab.commands.compare import finite_json

        print(json.dumps(finite_json(result), indent=1, allow_nan=False))  # NaN (nothing in view) as null
        return 0
    for n in ref.meta["notes"]:
        print(f"note: {n}")
    how = (
        "all from the cache"
        if ref.cached
        else f"{result['passes_rendered']} passes rendered now in {result['seconds_this_run']:.1f} s"
    )
    print(
        f"{scene.name}: {w}x{h}, {result['spp']} spp in {result['passes']} passes ({req.variant}; "
        f"{ref.meta['seconds']:.1f} s of path tracing in all), {how}"
    )
    print(
        f"noise floor (between halves of the passes): {100 * nf['rel_l1']:.2f} % per pixel, "
        f"{100 * nf['rel_l1_block']:.2f} % on 4x4 blocks ({nf['pixels']} object pixels)"
    )
    se = result["pixel_standard_error"] or {}
    if se:
        print(
            f"the full reference's own noise per pixel (standard error over the passes / luminance): median "
            f"{100 * se['median']:.2f} %, 90th percentile {100 * se['p90']:.2f} % (map: {noise_png.name})"
        )
    for path in written:
        print(f"wrote {path}")
    return 0


def noise_level(text: str) -> float:
    """'0.01' or '1%' -> 0.01 (argparse type of --until-noise)."""
    import argparse
    import math

    t = text.strip()
    try:
        v = float(t[:-1]) / 100 if t.endswith("%") else float(t)
    except ValueError:
        want = "expected a fraction such as 0.01 or a percentage such as 1%"
        raise argparse.ArgumentTypeError(f"{want}, got {text!r}") from None
    if not (v > 0 and math.isfinite(v)):
        raise argparse.ArgumentTypeError(f"expected a noise level > 0, got {text!r}")
    return v


def noise_map_rgb(ref):
    """uint8 RGB: the full reference's relative standard error per pixel (magma, 0 to 10 %), grey outside."""
    import numpy as np

    from skinlab.truth.compare import REC709, magma_rgb, object_mask

    se = ref.pass_set.standard_error()
    lum = ref.image[..., :3].astype(np.float64) @ REC709
    m = object_mask(ref.image) & (lum > 0)
    rel = np.where(m, se / np.where(m, lum, 1.0), np.nan)
    rgb = magma_rgb(np.nan_to_num(rel) / 0.1)
    rgb[~m] = (40, 40, 40)
    return rgb


def export_xml(args) -> int:
    """--export-xml DIR: the description the reference would render, as Mitsuba XML and meshes."""
    from pathlib import Path

    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.export import describe
    from skinlab.truth.mitsuba_xml import write_mitsuba_xml
    from skinlab.truth.reference import ReferenceRequest

    folder = Path(args.export_xml)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"--export-xml: {folder} exists and is not a folder")
    w, h = parse_size(args.size)
    req = ReferenceRequest(w, h, spp=args.spp, passes=args.passes, seed=args.seed, sun_deg=args.sun_deg,
                           max_depth=args.max_depth)  # fmt: skip
    scene = load_scene(args.scene, scene_edits_from_args(args))
    desc = describe(scene, w, h, sun_deg=req.sun_deg, max_depth=req.max_depth, rr_depth=req.rr_depth)
    path = write_mitsuba_xml(desc, folder, spp=req.spp)
    if args.json:
        print(json.dumps({"scene": scene.name, "xml": str(path.resolve()), "notes": desc.notes}, indent=1))
        return 0
    for n in desc.notes:
        print(f"note: {n}")
    print(f"wrote {path.resolve()} ({len(desc.shapes)} shape(s); render it with: mitsuba {path})")
    return 0


def tone_mapped(hdr, exposure: float = 1.0):
    """8-bit sRGB like the tone-mapping pass (ACES fit, then sRGB), alpha kept."""
    import numpy as np

    from skinlab.scene.optics.color import srgb_encode, tonemap_aces

    rgb = srgb_encode(tonemap_aces(np.asarray(hdr[..., :3], np.float64) * exposure))
    a = np.asarray(hdr[..., 3:4], np.float64)
    return (np.clip(np.concatenate([rgb, a], axis=2), 0, 1) * 255 + 0.5).astype(np.uint8)
