"""A workflow for maintainers, not a feature of the package: path-traced references rendered on another
machine (a lent GPU, Mitsuba's ``cuda_ad_rgb``), for the cases a 2-core CPU cannot make quiet enough
(the head at its real index, docs/ground-truth.md: "Known hard case"). Three steps:

    python -m tools.gpu_reference export SCENE.toml --size 96x96 --out DIR      # here: the description
    python -m tools.gpu_reference render DIR/NAME.npz --spp N --out RESULT.npz  # there: numpy + Mitsuba only
    python -m tools.gpu_reference store SCENE.toml RESULT.npz                   # here: into the cache

``render`` imports only skinlab/truth/description.py (no scene graph, no GL), so the GPU machine needs
nothing but numpy and Mitsuba. ``store`` files the result under the cache key of the request it was
rendered with (size, spp, passes, seed, variant), so `load_truth` / tools/truth_table.py find it
(``--truth 96:SPP:cuda_ad_rgb:SEED``)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _size(text: str) -> tuple[int, int]:
    w, h = (int(x) for x in text.lower().split("x"))
    return w, h


def export(args) -> int:
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.description import save
    from skinlab.truth.export import describe

    scene = load_scene(args.scene)
    w, h = _size(args.size)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{Path(args.scene).stem}-{w}x{h}.npz"
    save(describe(scene, w, h), path)
    print(path)
    return 0


def render(args) -> int:
    import mitsuba as mi

    from skinlab.truth.description import load, path_trace

    mi.set_variant(args.variant)
    desc = load(Path(args.description))
    done = [0]

    def progress(n):
        done[0] += n
        print(f"{done[0]} / {args.spp} spp", flush=True)

    mean, a, b, seconds = path_trace(desc, args.spp, args.passes, args.seed, progress, chunk=args.chunk)
    meta = {
        "spp": args.spp,
        "passes": args.passes,
        "seed": args.seed,
        "variant": args.variant,
        "mitsuba": mi.__version__,
        "seconds": round(seconds, 3),
        "size": [desc.width, desc.height],
    }
    with open(args.out, "wb") as fh:
        np.savez_compressed(fh, image=mean, half_a=a, half_b=b, meta=np.frombuffer(json.dumps(meta).encode(), np.uint8))
    print(json.dumps(meta))
    return 0


def store(args) -> int:
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.compare import image_error, object_mask
    from skinlab.truth.export import describe
    from skinlab.truth.reference import Reference, ReferenceRequest, reference_key, store_reference

    with np.load(args.result) as z:
        image, a, b = z["image"], z["half_a"], z["half_b"]
        meta = json.loads(bytes(z["meta"]).decode())
    scene = load_scene(args.scene)
    w, h = meta["size"]
    req = ReferenceRequest(w, h, spp=meta["spp"], passes=meta["passes"], seed=meta["seed"], variant=meta["variant"])
    key = reference_key(describe(scene, w, h), req, meta["mitsuba"])
    noise = image_error(a, b, object_mask(image))
    store_reference(Reference(image, a, b, key, {**meta, "scene": scene.name, "noise_floor": noise}, cached=False))
    floor = f"{100 * noise['rel_l1_block']:.2f} % on 4x4 blocks, {100 * noise['rel_l1']:.2f} % per pixel"
    print(f"{key}: noise floor {floor}")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m tools.gpu_reference", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    e = sub.add_parser("export", help="write a scene's reference description (npz)")
    e.add_argument("scene")
    e.add_argument("--size", default="96x96")
    e.add_argument("--out", default="out/gpu-reference")
    r = sub.add_parser("render", help="path-trace a description (numpy and Mitsuba only)")
    r.add_argument("description")
    r.add_argument("--spp", type=int, required=True)
    r.add_argument("--passes", type=int, default=4)
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--variant", default="cuda_ad_rgb")
    r.add_argument("--chunk", type=int, default=1024, help="samples per pixel per render call")
    r.add_argument("--out", required=True)
    s = sub.add_parser("store", help="file a rendered result in the reference cache")
    s.add_argument("scene")
    s.add_argument("result")
    args = p.parse_args(argv)
    return {"export": export, "render": render, "store": store}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())
