"""`skinlab reference [SCENE] --out PATH.exr --size WxH --spp N [--passes P] [--seed S] [--variant V]
[--until-noise X] [--time S]`: the scene path-traced volumetrically by Mitsuba 3 (the image ground truth;
docs/ground-truth.md), in passes saved as they finish (a killed run resumes; skinlab/truth/passes.py)."""

from __future__ import annotations

import json

from skinlab.commands.field_options import IMAGE_SIZE, add_command_options, check_command_options, own_default
from skinlab.commands.scene_options import add_scene_edit_options, scene_edits_from_args
from skinlab.declare import Field
from skinlab.render.settings import parse_size


def reference_options() -> tuple[Field, ...]:
    """The command's options: the request's fields (skinlab/truth/reference.py ReferenceRequest: their
    ranges are what the request checks), how passes are added, and the command's own."""
    from skinlab.truth.reference import NOISE_ON, TIME_S, UNTIL_NOISE, ReferenceRequest

    request = ReferenceRequest.fields()
    return (
        Field(
            "out",
            "string",
            "out/reference.exr",
            doc="linear EXR with alpha; a .png beside it is tone mapped like skinlab render's",
        ),
        own_default(
            IMAGE_SIZE,
            "192x192",
            f"this command's own default, smaller than a render's {IMAGE_SIZE.default}: path tracing takes minutes",
        ),  # fmt: skip
        *(request[name] for name in ("spp", "passes", "seed", "variant", "sun_deg", "max_depth")),
        UNTIL_NOISE,
        TIME_S,
        NOISE_ON,
        request["rr_depth"],
        Field("no_cache", "bool", False, doc="render even when an identical reference is cached"),
        Field("json", "bool", False, doc="print the result (path, noise floor, time, notes) as JSON"),
        Field(
            "export_xml",
            "string",
            doc="write the path tracer's scene as a Mitsuba 3 scene file, DIR/scene.xml with its meshes (PLY) and "
            "textures (EXR), for Mitsuba alone (`mitsuba DIR/scene.xml`), instead of rendering",
            shown="render",
        ),
    )


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
    add_command_options(p, reference_options(), parse={"until_noise": noise_level})
    add_scene_edit_options(p)  # --preset, --set KEY=VALUE, --mm-per-unit, as skinlab render's
    p.set_defaults(func=run)


def _check_options(args) -> None:
    """Every option in its declaration's range (past Mitsuba's: its RuntimeError, a traceback)."""
    from skinlab.truth.reference import check_max_depth

    check_command_options(args, reference_options())
    check_max_depth(args.max_depth, "--max-depth")


def run(args) -> int:
    from skinlab.cli import UserError
    from skinlab.image_output import check_output_path, image_format, write_image
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.reference import ReferenceRequest, ReferenceUnavailable, render_reference

    _check_options(args)
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
    """'0.01' or '1%' -> 0.01 (how --until-noise is read; its range is UNTIL_NOISE's)."""
    import argparse

    t = text.strip()
    try:
        return float(t[:-1]) / 100 if t.endswith("%") else float(t)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a fraction such as 0.01 or a percentage such as 1%, got {text!r}"
        ) from None


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
