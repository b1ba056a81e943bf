"""A one-off analysis, not a feature: every technique (default settings) on the close-up reference
scenes against their cached path-traced truth (issue 21; docs/ground-truth.md, "Close-ups"): relative
L1 on 4x4 blocks and per pixel, per-channel energy, NVIDIA's FLIP (the mean of the LDR-FLIP map of the
tone-mapped frame against the tone-mapped truth over the object, skinlab/truth/metrics.py; with its
ratio to plain diffuse's, issue 21's "a fifth of plain diffuse's"), and per scene what it was made to
measure, each with the truth's own noise (the same measure between the halves of its passes):

* slit scenes: the line profile (the image averaged along the slit, per channel): its relative L1
  against the truth's, and the fraction of the energy in view beyond 2, 5 and 10 mm from the slit;
* the nose's shadow: the mean radiance of the deep shadow (camera-visible points the light does not
  reach, more than 2 mm from any lit one: a ray cast with Embree, independent of the shadow maps)
  relative to the lit cheek's, and the relative L1 within 3 mm of the shadow's edges (edge region);
  with --edge-bins also each channel's energy and the relative L1 in bands by the signed distance from
  the shadow's edge (EDGE_BINS_MM, + on the lit side);
* the two back-lit slabs: the front slab's and the back slab's energy apart (the light through
  both slabs and through one).

Nothing is path-traced here: the references must be cached (the commands are in CLOSEUPS and
docs/ground-truth.md). Frames are supersampled like the truth's pixels (TRUTH_SUPERSAMPLE). The
measures are skinlab/bench/closeup.py's, the accuracy ledger's (docs/ledger.md "Close-ups in the ledger").

    python -m tools.closeup_table [SCENES] [TECHNIQUES] [--profiles OUT.npz] [--bounces N] [--bounce-rays N]
        [--sss-model MODEL] [--no-translucency] [--through-kernel] [--size WxH --spp N] [--edge-bins]

SCENES and TECHNIQUES are comma-separated ("" or left out: all). --bounces and --sss-model as in
tools/truth_table.py; --no-translucency renders with every technique's translucency off; --size and
--spp compare against other (cached) truths of every scene than CLOSEUPS' (a slit's millimetres per
column scaled to the width)."""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from skinlab.bench.closeup import (
    TAIL_MM,
    line_profile,
    profile_error,
    ray_geometry,
    region_error,
    region_level,
    shadow_regions,
    tail_fractions,
)
from skinlab.bench.truth_ledger import REFERENCE_SCENES, TRUTH_SUPERSAMPLE
from skinlab.truth.compare import image_error
from skinlab.truth.metrics import flip_mean

TECHNIQUES = ["none", "tint", "tsd", "exact", "ssss", "disk", "preintegrated"]
EDGE_BINS_MM = (-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 3.0, 6.0)  # --edge-bins' bands (and beyond 6 mm)


def signed_edge_mm(scene, size) -> np.ndarray:
    """Per pixel of a shadow scene at `size`: the distance (mm) from the shadow's edge, + where the
    light reaches the point, - where it does not; NaN where no mesh is seen."""
    from scipy.ndimage import distance_transform_edt

    from skinlab.bench.closeup import mm_per_pixel

    node, lit = ray_geometry(scene, *size)
    mm = np.nanmedian(mm_per_pixel(scene, *size))
    seen = node >= 0
    sd = np.where(lit, distance_transform_edt(lit | ~seen) * mm, -distance_transform_edt(~lit) * mm)
    return np.where(seen, sd, np.nan)


def edge_bins(img, truth, sd) -> list[str]:
    """One line per band of signed_edge_mm: its pixels, each channel's energy against the truth's and
    the relative L1 there."""
    lines = []
    edges = list(EDGE_BINS_MM) + [np.inf]
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (sd >= lo) & (sd < hi)
        if not m.any():
            continue
        f, t = img[m][:, :3].astype(np.float64), truth[m][:, :3].astype(np.float64)
        energy = "/".join(f"{100 * (a / b - 1):+.1f}" for a, b in zip(f.sum(0), t.sum(0)))
        l1 = np.abs(f - t).sum() / t.sum()
        lines.append(f"    {lo:+5.1f} to {hi:+5.1f} mm ({m.sum():4d} px): energy {energy} %, L1 {100 * l1:5.2f} %")
    return lines


@dataclass(frozen=True)
class Closeup:
    size: tuple[int, int]
    spp: int
    rr_depth: int = 64
    kind: str = ""  # "slit" | "shadow" | "slabs" | ""
    mm_per_px: float = 0.0  # slit scenes: along the profile axis (the image's columns)

    def at(self, size: tuple[int, int] | None, spp: int | None) -> Closeup:
        """The same close-up against a truth of another size or spp (a slit's mm per column scaled)."""
        spec = self if spp is None else replace(self, spp=spp)
        if size is None:
            return spec
        return replace(spec, size=size, mm_per_px=self.mm_per_px * self.size[0] / size[0])

    def command(self, scene: str) -> str:
        rr = f" --rr-depth {self.rr_depth}" if self.rr_depth != 64 else ""
        return (
            f"skinlab reference skinlab/assets/scenes/reference/{scene}.toml --size {self.size[0]}x{self.size[1]} "
            f"--spp {self.spp}{rr} --out out/truth/{scene}.exr"
        )


# the truths measured in docs/ground-truth.md ("Close-ups"): the smallest size and spp that decide the
# comparison on a shared 2-core machine (a few minutes each; the truth's noise is printed beside every
# figure). The slits keep their 256 columns (the profile's resolution) and average 16 rows.
CLOSEUPS = {
    "slit-skin1": Closeup((256, 16), 256, kind="slit", mm_per_px=0.135),
    "slit-marble": Closeup((256, 16), 64, rr_depth=1024, kind="slit", mm_per_px=0.35),
    "nose-shadow-skin1": Closeup((96, 96), 256, kind="shadow"),
    "ear-backlit-skin1": Closeup((96, 96), 64),
    "point-light-skin1": Closeup((64, 64), 128),
    "slabs-gap-backlit-skin1": Closeup((64, 64), 512, kind="slabs"),
    "ball-backlit-skin1": Closeup((96, 96), 8192),
}


def load_closeup_truth(scene, spec: Closeup):
    """The cached reference of `spec` (whole, or assembled from its cached passes), or None."""
    from skinlab.truth.reference import ReferenceRequest, ReferenceUnavailable, render_reference

    req = ReferenceRequest(spec.size[0], spec.size[1], spp=spec.spp, rr_depth=spec.rr_depth)
    try:
        return render_reference(scene, req, progress=False, render=False)
    except ReferenceUnavailable:
        return None


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    return w, h


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m tools.closeup_table", description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="?", default="", help=f"comma-separated (default: {','.join(CLOSEUPS)})")
    ap.add_argument("techniques", nargs="?", default="", help=f"comma-separated (default: {','.join(TECHNIQUES)})")
    ap.add_argument("--profiles", default=None, help="write the slits' line profiles to this .npz")
    ap.add_argument("--bounces", type=int, default=None, help="orders of interreflection (0: off)")
    ap.add_argument("--sss-model", default=None, help="override every material's sss_model")
    ap.add_argument("--bounce-rays", type=int, default=None, help="interreflection rays per vertex")
    ap.add_argument("--no-translucency", action="store_true", help="every technique's translucency off")
    ap.add_argument(
        "--through-kernel",
        action="store_true",
        help="light through thin parts from the transfer through the medium (RenderSettings.through_kernel)",
    )
    ap.add_argument("--size", type=_size, default=None, help="WxH of the truths instead of CLOSEUPS'")
    ap.add_argument("--shadow-size", type=int, default=None, help="shadow map texels per side instead of 2048")
    ap.add_argument("--spp", type=int, default=None, help="samples per pixel of the truths instead of CLOSEUPS'")
    ap.add_argument(
        "--edge-bins", action="store_true", help="shadow scenes: energy and L1 by the distance from the shadow's edge"
    )
    return ap


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    out = args.profiles
    scenes = args.scenes.split(",") if args.scenes else list(CLOSEUPS)
    unknown = [s for s in scenes if s not in CLOSEUPS]
    if unknown:
        raise SystemExit(f"closeup_table: no close-up {', '.join(unknown)}; expected some of {', '.join(CLOSEUPS)}")
    techs = args.techniques.split(",") if args.techniques else TECHNIQUES
    extra: dict[str, Any] = {} if args.bounces is None else {"bounces": args.bounces}
    if args.shadow_size:
        extra["shadow_size"] = args.shadow_size
    if args.bounce_rays is not None:
        extra["bounce_rays"] = args.bounce_rays
    if args.through_kernel:
        extra["through_kernel"] = True
    model = args.sss_model
    r = Renderer(create_headless_context())
    saved: dict[str, Any] = {}  # name -> array (np.savez's keyword arguments)
    print("load average at start: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    for s in scenes:
        spec = CLOSEUPS[s].at(args.size, args.spp)
        scene = load_scene(REFERENCE_SCENES / f"{s}.toml")
        truth = load_closeup_truth(scene, spec)
        if truth is None:
            print(f"{s}: no cached reference; render it with\n    {spec.command(s)}")
            continue
        t_img, ha, hb = truth.image, truth.half_a, truth.half_b
        noise = truth.noise
        exposure = scene.environment.exposure
        head = (
            # the truth's own spp and passes: a cache holding more passes than asked for gives them all
            f"{s:24s} truth {spec.size[0]}x{spec.size[1]} {truth.meta.get('spp', spec.spp)} spp "
            f"({truth.meta.get('passes', '?')} passes): noise 4x4 "
            f"{100 * noise['rel_l1_block']:.2f} %, px {100 * noise['rel_l1']:.2f} %, "
            f"FLIP {flip_mean(ha, hb, exposure=exposure):.4f}"
        )
        plain_flip = math.nan  # plain diffuse's FLIP mean, for the others' ratio to it
        masks: tuple = ()  # the kind's regions (shadow: deep, lit, edge; slabs: front, back)
        if spec.kind == "slit":
            pa, pb, pt = line_profile(ha), line_profile(hb), line_profile(t_img)
            head += f", profile {100 * profile_error(pa, pb):.2f} %"
            ta, tb = tail_fractions(pa, spec.mm_per_px), tail_fractions(pb, spec.mm_per_px)
            tt = tail_fractions(pt, spec.mm_per_px)
            head += "; truth's light beyond " + ", ".join(
                f"{d:g} mm "
                + "/".join(f"{100 * v:.2f}" for v in tt[k])
                + " (+-"
                + "/".join(f"{50 * abs(x):.2f}" for x in ta[k] - tb[k])
                + ") %"
                for k, d in enumerate(TAIL_MM)
            )
            saved[f"{s}/truth"] = pt
            saved[f"{s}/truth_a"], saved[f"{s}/truth_b"] = pa, pb
        elif spec.kind == "shadow":
            masks = shadow_regions(scene, spec.size)
            deep, lit, edge = masks
            sd = signed_edge_mm(scene, spec.size) if args.edge_bins else None
            lv = region_level(t_img, deep, lit)
            lva, lvb = region_level(ha, deep, lit), region_level(hb, deep, lit)
            head += (
                f"; deep shadow {deep.sum()} px at {100 * lv:.3f} % of the lit level (+-{50 * abs(lva - lvb):.3f}), "
                f"edge region {edge.sum()} px, noise {100 * region_error(ha, hb, edge):.2f} %"
            )
        elif spec.kind == "slabs":
            node, _ = ray_geometry(scene, *spec.size)
            masks = (node == 0, node == 1)
        print(head, flush=True)
        for t in techs:
            own = {}
            if args.no_translucency and t not in ("none", "tint"):
                own["translucency"] = False
            rs = RenderSettings.for_technique(
                t, spec.size[0], spec.size[1], supersample=TRUTH_SUPERSAMPLE, sss_model=model, **extra, **own
            )
            img = r.render(scene, rs, readback=("hdr",)).hdr
            e = image_error(img, t_img)
            energy = "/".join(f"{100 * x:+.1f}" for x in e["energy"])
            fl = flip_mean(img, t_img, exposure=exposure)
            if t == "none":
                plain_flip = fl
            line = f"  {t:14s} 4x4 {100 * e['rel_l1_block']:6.2f} %  px {100 * e['rel_l1']:6.2f} %  energy {energy} %"
            line += f"  FLIP {fl:.4f}" + (
                f" ({fl / plain_flip:.2f} of none's)" if t != "none" and plain_flip > 0 else ""
            )
            if spec.kind == "slit":
                pf = line_profile(img)
                tf = tail_fractions(pf, spec.mm_per_px)
                line += f"  profile {100 * profile_error(pf, pt):6.2f} %  beyond " + ", ".join(
                    f"{d:g} mm " + "/".join(f"{100 * v:.2f}" for v in tf[k]) for k, d in enumerate(TAIL_MM)
                )
                saved[f"{s}/{t}"] = pf
            elif spec.kind == "shadow":
                deep, lit, edge = masks
                line += (
                    f"  deep shadow {100 * region_level(img, deep, lit):.3f} %"
                    f"  edge region {100 * region_error(img, t_img, edge):6.2f} %"
                )
            elif spec.kind == "slabs":
                front, back = masks
                ef = image_error(img, t_img, mask=front)["energy"]
                eb = image_error(img, t_img, mask=back)["energy"]
                line += (
                    "  front slab "
                    + "/".join(f"{100 * x:+.1f}" for x in ef)
                    + " %  back slab "
                    + "/".join(f"{100 * x:+.1f}" for x in eb)
                    + " %"
                )
            print(line, flush=True)
            if spec.kind == "shadow" and args.edge_bins:
                print("\n".join(edge_bins(img, t_img, sd)), flush=True)
    print("load average at end: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    r.release()
    if out:
        np.savez(out, **saved)
    return 0


if __name__ == "__main__":
    sys.exit(main())
