"""`skinlab compare A B [--out map.png] [--json]`: how far image A is from image B (the reference):
relative L1 per pixel and per channel, energy per channel, FLIP on the tone-mapped frames and error
maps (skinlab/truth/metrics.py has the definitions)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from skinlab.commands.field_options import add_command_options, check_command_options
from skinlab.declare import Field

COMPARE_OPTIONS = (
    Field(
        "out",
        "string",
        doc="write the signed relative-difference map here (PNG: red brighter than B, blue darker, full colour at "
        "+-50 %) and the FLIP map beside it (NAME-flip.png)",
        shown="none",
    ),
    Field(
        "exposure",
        "float",
        1.0,
        (0.0, math.inf),
        lo_open=True,
        doc="linear multiplier on both images' radiance before tone mapping, for FLIP",
    ),
    Field("json", "bool", False, doc="print the result as JSON"),
)


def register(sub) -> None:
    p = sub.add_parser(
        "compare",
        help="compare two images of one size: relative L1, energy, FLIP and error maps (B is the reference)",
        description="Compares image A with the reference B (a frame against `skinlab reference`'s EXR, or two "
        "techniques' frames). EXR: linear radiance; PNG/JPEG: sRGB, decoded to linear for relative L1 and "
        "energy and compared as it is by FLIP. Pixels compared: where B's alpha is > 0.5 (every pixel when B "
        "has no alpha). relative L1 = sum |A - B| / sum B over those pixels and R, G, B; energy = sum A / sum B "
        "- 1 per channel; FLIP: NVIDIA's LDR-FLIP of the tone-mapped images (exposure, ACES, sRGB) at 67 "
        "pixels per degree, its mean over the pixels compared. See docs/ground-truth.md.",
    )
    p.add_argument("a", help="the image to judge (.exr linear, or .png/.jpg sRGB)")
    p.add_argument("b", help="the reference image, of the same size")
    add_command_options(p, COMPARE_OPTIONS)
    p.set_defaults(func=run)


def load_for_compare(path: str, label: str):
    """(pixels float (H, W, C>=3), linear: bool) or ValueError naming the file."""
    import numpy as np

    from skinlab.image_output import read_image
    from skinlab.scene.optics.color import srgb_decode

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{label} {path}: no such file" if not p.exists() else f"{label} {path}: not a file")
    try:
        img = read_image(p)
    except Exception as exc:
        raise ValueError(f"{label} {path}: cannot read it as an image ({str(exc).splitlines()[0][:120]})") from None
    if img.ndim != 3 or img.shape[2] < 3:
        raise ValueError(f"{label} {path}: expected an RGB or RGBA image, got {img.shape[-1]} channel(s)")
    linear = img.dtype != np.uint8
    x = img.astype(np.float64)
    if not linear:
        x = x / 255.0
    bad = int((~np.isfinite(x)).any(axis=2).sum())
    if bad:
        raise ValueError(f"{label} {path}: {bad} pixel(s) are NaN or Inf; expected finite values")
    if not linear:
        x[..., :3] = srgb_decode(x[..., :3])
    return x, linear


def compare_images(a, b, exposure: float = 1.0, ldr: bool = False) -> dict:
    """The measures of A against B (float (H, W, C) arrays of one size, linear)."""
    import numpy as np

    from skinlab.truth import metrics

    if a.shape[:2] != b.shape[:2]:
        raise ValueError(f"A is {a.shape[1]}x{a.shape[0]}, B is {b.shape[1]}x{b.shape[0]}: expected one size")
    mask = b[..., 3] > 0.5 if b.shape[2] >= 4 else np.ones(b.shape[:2], bool)
    a4, b4 = _rgba(a), _rgba(b)
    if ldr:  # FLIP on the encoded values as they are (already tone mapped)
        from skinlab.scene.optics.color import srgb_encode

        fmap = _flip_ldr(srgb_encode(a4[..., :3]), srgb_encode(b4[..., :3]))
    else:
        fmap = metrics.flip_map(a4, b4, exposure)
    return {
        "size": [int(b.shape[1]), int(b.shape[0])],
        "pixels": int(mask.sum()),
        "rel_l1": metrics.rel_l1(a4, b4, mask),
        "rel_l1_rgb": metrics.rel_l1_rgb(a4, b4, mask),
        "energy": metrics.energy(a4, b4, mask),
        "flip_mean": float(fmap[mask].mean()) if mask.any() else float("nan"),
        "relative_map": metrics.relative_map(a4, b4, mask),
        "flip_map": fmap,
    }


def _rgba(x):
    import numpy as np

    if x.shape[2] >= 4:
        return x[..., :4]
    return np.concatenate([x[..., :3], np.ones(x.shape[:2] + (1,))], axis=2)


def _flip_ldr(a, b):
    import flip_evaluator
    import numpy as np

    from skinlab.truth.metrics import FLIP_PPD

    f = lambda x: np.ascontiguousarray(np.clip(x, 0, 1), np.float32)
    err, _, _ = flip_evaluator.evaluate(
        f(b), f(a), "LDR", inputsRGB=True, applyMagma=False, computeMeanError=False, parameters={"ppd": FLIP_PPD}
    )
    return np.asarray(err, np.float32).reshape(a.shape[:2])


def finite_json(v):
    """NaN and Inf as null (standard JSON), recursively."""
    import math

    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if isinstance(v, dict):
        return {k: finite_json(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [finite_json(x) for x in v]
    return v


def run(args) -> int:
    from skinlab.image_output import check_output_path, write_image
    from skinlab.truth.compare import error_map_rgb, magma_rgb

    check_command_options(args, COMPARE_OPTIONS)  # --exposure > 0
    out = check_output_path(args.out, "--out") if args.out else None
    a, lin_a = load_for_compare(args.a, "A")
    b, lin_b = load_for_compare(args.b, "B")
    if a.shape[:2] != b.shape[:2]:
        raise ValueError(
            f"{args.a} is {a.shape[1]}x{a.shape[0]}, {args.b} is {b.shape[1]}x{b.shape[0]}: expected images of one size"
        )
    res = compare_images(a, b, args.exposure, ldr=not (lin_a and lin_b))
    written = []
    if out is not None:
        written.append(str(write_image(out, error_map_rgb(res["relative_map"])).resolve()))
        flip_out = out.with_name(out.stem + "-flip.png")
        written.append(str(write_image(flip_out, magma_rgb(res["flip_map"])).resolve()))
    doc = {
        "a": str(args.a),
        "b": str(args.b),
        "linear": lin_a and lin_b,
        **{k: v for k, v in res.items() if not k.endswith("_map")},
        "outputs": written,
    }
    if args.json:
        print(json.dumps(finite_json(doc), indent=1, allow_nan=False))
        return 0
    pct = lambda v: "n/a" if not math.isfinite(v) else f"{100 * v:.2f} %"
    w, h = res["size"]
    kind = "linear radiance" if doc["linear"] else "sRGB images decoded to linear"
    print(f"{args.a} against {args.b}: {w}x{h}, {res['pixels']} pixels compared ({kind})")
    per = ", ".join(f"{c} {pct(x)}" for c, x in zip("RGB", res["rel_l1_rgb"]))
    print(f"  relative L1 {pct(res['rel_l1'])} (per channel: {per})")
    print("  energy " + ", ".join(f"{c} {100 * e:+.2f} %" for c, e in zip("RGB", res["energy"])))
    print(f"  FLIP mean {res['flip_mean']:.4f} (0: identical, 1: the largest perceived difference)")
    for p in written:
        print(f"wrote {p}")
    return 0
