"""A one-off analysis, not a feature: the point light close above an index-matched slab
(point-light-skin1, docs/ground-truth.md "Close-ups"), the light per distance ring from the light's
foot, in the cached path-traced truth, in an independent Monte Carlo of the same medium and in each
technique's frame (TRUTH_SUPERSAMPLE, as tools/closeup_table.py renders them).

The Monte Carlo is the exact transport of a half-space of the scene's medium (isotropic phase, the
reduced albedo and mean free path the exporter gives Mitsuba, no interface: specular 0), lit by the
point light and seen straight from above: photons from the light onto the surface (uniform in solid
angle out to MC_RADIUS_MM from the foot), a random walk below it, and at every collision the
radiance scattered straight up (albedo / 4 pi x e^(-depth / mfp)), tallied on the truth's pixels. The
slab is 40 mm thick, 160 mm wide (skin1's red diffusion length is 2.3 mm): a half-space.

    python -m tools.near_light_check [--photons N] [--techniques LIST] [--height MM] [--no-truth]

--height moves the light (the frames and the Monte Carlo; the truth only at the scene's own 2 mm)."""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

SCENE = "point-light-skin1"
RINGS_MM = (0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.65, 13.0)  # the view's half-width is 8.64 mm
MC_RADIUS_MM = 30.0  # light entering farther from the foot hardly reaches the view (13 red diffusion lengths)


def half_space_mc(
    height_mm: float,
    albedo,
    mfp_mm,
    intensity: float,
    size: int,
    view_mm: float,
    photons: int,
    seed: int = 1,
    radius_mm: float = MC_RADIUS_MM,
) -> np.ndarray:
    """(size, size, 3) the radiance toward +z of an index-matched isotropic half-space under a point
    light of `intensity` (W/sr; irradiance I cos / d^2 with d in metres) height_mm above it, on a
    square view of view_mm centred below the light (row 0 at +y)."""
    rng = np.random.default_rng(seed)
    px = view_mm / size
    img = np.zeros((size, size, 3))
    cmax = height_mm / math.hypot(height_mm, radius_mm)
    batch = 500_000
    for c in range(3):
        st, a = 1.0 / float(mfp_mm[c]), float(albedo[c])
        done = 0
        while done < photons:
            n = min(batch, photons - done)
            done += n
            ct = rng.uniform(cmax, 1.0, n)
            phi = rng.uniform(0.0, 2 * math.pi, n)
            s = np.sqrt(1.0 - ct * ct)
            d = np.stack([s * np.cos(phi), s * np.sin(phi), ct], 1)  # z: depth below the surface
            p = np.stack([height_mm * s / ct * np.cos(phi), height_mm * s / ct * np.sin(phi), np.zeros(n)], 1)
            w0 = 2 * math.pi * intensity * (1.0 - cmax) / photons  # W per photon
            w = np.full(n, w0)
            while len(w):
                p = p + (-np.log(rng.random(len(w))) / st)[:, None] * d
                inside = p[:, 2] > 0
                p, d, w = p[inside], d[inside], w[inside]
                up = w * a / (4 * math.pi) * np.exp(-st * p[:, 2])  # W/sr straight up
                ix = np.floor((p[:, 0] + view_mm / 2) / px).astype(int)
                iy = np.floor((view_mm / 2 - p[:, 1]) / px).astype(int)
                ok = (ix >= 0) & (ix < size) & (iy >= 0) & (iy < size)
                np.add.at(img[:, :, c], (iy[ok], ix[ok]), up[ok])
                w = w * a
                u = rng.uniform(-1.0, 1.0, len(w))
                ph = rng.uniform(0.0, 2 * math.pi, len(w))
                q = np.sqrt(1.0 - u * u)
                d = np.stack([q * np.cos(ph), q * np.sin(ph), u], 1)
                low = w < 1e-4 * w0  # Russian roulette
                survive = rng.random(len(w)) < 0.1
                w = np.where(low, np.where(survive, w / 0.1, 0.0), w)
                keep = w > 0
                p, d, w = p[keep], d[keep], w[keep]
    return img / (px * 1e-3) ** 2  # W / (sr m^2)


def ring_masks(size: int, view_mm: float) -> list[tuple[str, np.ndarray]]:
    px = view_mm / size
    jj, ii = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
    r = np.hypot((ii + 0.5 - size / 2) * px, (size / 2 - jj - 0.5) * px)
    return [(f"{a:g}-{b:g}", (r >= a) & (r < b)) for a, b in zip(RINGS_MM[:-1], RINGS_MM[1:])]


def ring_line(name: str, img: np.ndarray, ref: np.ndarray, rings) -> str:
    tot = img[..., :3].sum((0, 1)) / ref[..., :3].sum((0, 1)) - 1
    parts = [f"{name:14s} energy " + "/".join(f"{100 * x:+.1f}" for x in tot) + " %  rings (mm):"]
    for label, m in rings:
        e = img[m][:, :3].sum(0) / np.maximum(ref[m][:, :3].sum(0), 1e-30) - 1
        parts.append(f"{label} " + "/".join(f"{100 * x:+.1f}" for x in e))
    return "  ".join(parts)


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m tools.near_light_check", description=__doc__.split("\n\n")[0])
    ap.add_argument("--photons", type=int, default=2_000_000, help="Monte Carlo photons per channel")
    ap.add_argument("--techniques", default="none,tsd,exact,ssss,disk,preintegrated", help="comma-separated")
    ap.add_argument("--height", type=float, default=None, help="the light's height above the slab, mm")
    ap.add_argument("--no-truth", action="store_true", help="against the Monte Carlo, not the cached truth")
    return ap


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    from skinlab.bench.truth_ledger import REFERENCE_SCENES, TRUTH_SUPERSAMPLE
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.scenefile import load_scene
    from tools.closeup_table import CLOSEUPS, load_closeup_truth

    spec = CLOSEUPS[SCENE]
    scene = load_scene(REFERENCE_SCENES / f"{SCENE}.toml")
    light = scene.lights()[0]
    top = 0.0  # the slab's top face (the scene file: a 40 mm slab moved down by 20)
    height = float(light.world_position[2] - top) * scene.mm_per_unit
    if args.height is not None:
        light.translation = np.array([0.0, 0.0, top + args.height / scene.mm_per_unit])
        height = args.height
    size = spec.size[0]
    cam = scene.active_camera()
    cam_z = float(cam.world_matrix[2, 3])  # straight above the light's foot
    view = 2 * (cam_z - top) * math.tan(cam.yfov / 2) * scene.mm_per_unit
    med = material_medium(scene.mesh_nodes()[0].material.values)
    print("load average at start: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    mc = half_space_mc(height, med.alpha, med.mfp_mm, float(np.mean(light.radiance)), size, view, args.photons)
    truth = None
    if not args.no_truth and args.height is None:
        t = load_closeup_truth(scene, spec)
        truth = None if t is None else np.asarray(t.image[..., :3], np.float64)
        if t is None:
            print(f"no cached truth: {spec.command(SCENE)}; against the Monte Carlo")
    rings = ring_masks(size, view)
    ref = mc if truth is None else truth
    print(f"{SCENE}: light {height:g} mm above the slab, view {view:.2f} mm, {size}x{size}; against the "
          f"{'Monte Carlo' if truth is None else 'cached truth'}")  # fmt: skip
    if truth is not None:
        print(ring_line("monte carlo", mc, ref, rings))
    r = Renderer(create_headless_context())
    for tech in [t for t in args.techniques.split(",") if t]:
        rs = RenderSettings.for_technique(tech, size, size, supersample=TRUTH_SUPERSAMPLE)
        img = np.asarray(r.render(scene, rs, readback=("hdr",)).hdr[..., :3], np.float64)
        print(ring_line(tech, img, ref, rings), flush=True)
    r.release()
    print("load average at end: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
