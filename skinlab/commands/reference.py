"""`skinlab reference [SCENE] --out PATH.exr --size WxH --spp N [--passes P] [--seed S] [--variant V]`:
the scene path-traced volumetrically by Mitsuba 3 (the image ground truth; docs/ground-truth.md)."""

from __future__ import annotations

import json

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
    p.add_argument("--no-cache", action="store_true", help="render even when an identical reference is cached")
    p.add_argument("--json", action="store_true", help="print the result (path, noise floor, time, notes) as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    from skinlab.cli import UserError
    from skinlab.image_output import check_output_path, image_format, write_image
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.reference import ReferenceRequest, ReferenceUnavailable, render_reference

    out = check_output_path(args.out, "--out")  # before minutes of path tracing
    check_output_path(out.with_suffix(".png"), "--out")
    if image_format(out) != "exr":
        raise ValueError(f"--out: the reference is linear radiance: expected a .exr path, got {out}")
    w, h = parse_size(args.size)
    req = ReferenceRequest(
        w, h, spp=args.spp, passes=args.passes, seed=args.seed, variant=args.variant,
        sun_deg=args.sun_deg, max_depth=args.max_depth,
    )  # fmt: skip
    scene = load_scene(args.scene)
    try:
        ref = render_reference(scene, req, progress=not args.json, use_cache=not args.no_cache)
    except ReferenceUnavailable as exc:
        raise UserError(str(exc)) from None
    written = [str(write_image(out, ref.image).resolve())]
    png = out.with_suffix(".png")
    written.append(str(write_image(png, tone_mapped(ref.image, scene.environment.exposure)).resolve()))
    nf = ref.noise
    result = {
        "scene": scene.name,
        "outputs": written,
        "size": [w, h],
        "spp": req.spp,
        "passes": req.passes,
        "variant": req.variant,
        "cached": ref.cached,
        "render_seconds": ref.meta["seconds"],
        "noise_floor": nf,
        "notes": ref.meta["notes"],
        "key": ref.key,
    }
    if args.json:
        print(json.dumps(result, indent=1))
        return 0
    for n in ref.meta["notes"]:
        print(f"note: {n}")
    how = "from the cache" if ref.cached else f"in {ref.meta['seconds']:.1f} s"
    print(f"{scene.name}: {w}x{h}, {req.spp} spp in {req.passes} passes ({req.variant}), {how}")
    print(
        f"noise floor (between halves of the passes): {100 * nf['rel_l1']:.2f} % per pixel, "
        f"{100 * nf['rel_l1_block']:.2f} % on 4x4 blocks ({nf['pixels']} object pixels)"
    )
    for path in written:
        print(f"wrote {path}")
    return 0


def tone_mapped(hdr, exposure: float = 1.0):
    """8-bit sRGB like the tone-mapping pass (ACES fit, then sRGB), alpha kept."""
    import numpy as np

    from skinlab.scene.optics.color import srgb_encode, tonemap_aces

    rgb = srgb_encode(tonemap_aces(np.asarray(hdr[..., :3], np.float64) * exposure))
    a = np.asarray(hdr[..., 3:4], np.float64)
    return (np.clip(np.concatenate([rgb, a], axis=2), 0, 1) * 255 + 0.5).astype(np.uint8)
