"""A one-off analysis, not a feature: one technique on the close-up reference scenes against their cached
truths (tools/closeup_table.py's CLOSEUPS and measures: 4x4-block and per-pixel relative L1, energy per
channel, FLIP; the shadow scenes' deep shadow and edge region), in variants that differ by render
settings or by measurement defines of the shaders (``MEASURE_...``: passes/forward.frag and the texture-space
irradiance pass; none is what the renderer runs), side by side (issue 21, docs/ground-truth.md).

    python -m tools.closeup_variants SCENES TECHNIQUE NAME=KEY:VALUE,... [NAME=...] [--truth SIZE:SPP]

A KEY in capitals is a define (VALUE a number, or none: 1), any other a RenderSettings field or the
technique's option (VALUE parsed as a number, true/false, or text); NAME= alone is the defaults. With
--truth, the other reference scenes too (the head, the bunnies), against their cached SIZExSIZE truth of
SPP samples (tools/truth_table.py's --truth):

    python -m tools.closeup_variants ball-backlit-skin1,nose-shadow-skin1 tsd base= flat=single_through:false \\
        kernel=through_kernel:true chord=MEASURE_BULGE_CHORD:0
"""

from __future__ import annotations

import os
import sys
from typing import Any

DEFINED_IN = ("passes/forward.frag", "techniques/tsd/irradiance.frag")


def _value(text: str) -> Any:
    from skinlab.bench.ledger_csv import _param_value  # a number where it reads as one (the ledger's CSV cells)

    low = text.lower()
    return low == "true" if low in ("true", "false") else _param_value(text)


def parse_variant(text: str) -> tuple[str, dict, dict]:
    """'NAME=KEY:VALUE,...' -> (name, settings, defines)."""
    name, sep, body = text.partition("=")
    if not sep or not name:
        raise SystemExit(f"closeup_variants: expected NAME=KEY:VALUE,..., got {text!r}")
    settings: dict = {}
    defines: dict = {}
    for item in filter(None, body.split(",")):
        key, _, val = item.partition(":")
        if key.isupper():
            defines[key] = _value(val) if val else 1
        else:
            settings[key] = _value(val)
    return name, settings, defines


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog="python -m tools.closeup_variants", description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", help="comma-separated reference scenes")
    ap.add_argument("technique")
    ap.add_argument("variants", nargs="+", help="NAME=KEY:VALUE,...")
    ap.add_argument("--truth", default=None, help="SIZE:SPP of the truths of scenes that are not close-ups")
    opts = ap.parse_args(argv)
    from skinlab.bench.closeup import region_error, region_level, shadow_regions
    from skinlab.bench.truth_ledger import REFERENCE_SCENES, TRUTH_SUPERSAMPLE, TruthSpec, load_truth
    from skinlab.gl.context import create_headless_context
    from skinlab.gl.shader_source import ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.compare import image_error
    from skinlab.truth.metrics import flip_mean

    from .closeup_table import CLOSEUPS, load_closeup_truth

    scenes, tech = opts.scenes.split(","), opts.technique
    other = None
    if opts.truth:
        size, _, spp = opts.truth.partition(":")
        other = TruthSpec((int(size), int(size)), int(spp))
    unknown = [
        s for s in scenes if s not in CLOSEUPS and (other is None or not (REFERENCE_SCENES / f"{s}.toml").exists())
    ]
    if unknown:
        raise SystemExit(
            f"closeup_variants: no close-up {', '.join(unknown)}; expected some of {', '.join(CLOSEUPS)} "
            "(or any reference scene with --truth)"
        )
    variants = [parse_variant(v) for v in opts.variants]
    ctx = create_headless_context()
    print("load average at start: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    for sname in scenes:
        scene = load_scene(REFERENCE_SCENES / f"{sname}.toml")
        if sname in CLOSEUPS:
            spec = CLOSEUPS[sname]
            size, kind = spec.size, spec.kind
            truth = load_closeup_truth(scene, spec)
            hint = spec.command(sname)
        else:
            assert other is not None
            size, kind = other.size, "plain"
            truth = load_truth(scene, other, progress=False)
            hint = f"skinlab reference {REFERENCE_SCENES / sname}.toml --size {size[0]}x{size[1]} --spp {other.spp}"
        if truth is None:
            print(f"{sname}: no cached reference; render it with\n    {hint}")
            continue
        t = truth.image
        masks = shadow_regions(scene, size) if kind == "shadow" else None
        head = f"{sname}: truth noise 4x4 {100 * truth.noise['rel_l1_block']:.2f} %"
        if masks is not None:
            head += f", deep shadow {100 * region_level(t, masks[0], masks[1]):.3f} % of the lit level"
        print(head, flush=True)
        for name, settings, defines in variants:
            library = ShaderLibrary(defines={f: defines for f in DEFINED_IN}) if defines else ShaderLibrary()
            r = Renderer(ctx, library)
            try:
                rs = RenderSettings.for_technique(tech, size[0], size[1], supersample=TRUTH_SUPERSAMPLE, **settings)
                img = r.render(scene, rs, readback=("hdr",)).hdr
            finally:
                r.release()
            e = image_error(img, t)
            line = (
                f"  {name:14s} 4x4 {100 * e['rel_l1_block']:6.2f} %  px {100 * e['rel_l1']:6.2f} %  energy "
                + "/".join(f"{100 * x:+.1f}" for x in e["energy"])
                + f" %  FLIP {flip_mean(img, t, exposure=scene.environment.exposure):.4f}"
            )
            if masks is not None:
                line += (
                    f"  deep shadow {100 * region_level(img, masks[0], masks[1]):.3f} %"
                    f"  edge region {100 * region_error(img, t, masks[2]):6.2f} %"
                )
            print(line, flush=True)
    print("load average at end: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
