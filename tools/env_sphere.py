"""A one-off analysis, not a feature (issue 22): a convex skin1 sphere (radius 40 mm, index-matched)
under smooth environment light, to judge the per-point transport of a map's diffuse part without
occlusion or interreflection. Writes the scene files, compares the frame with the cached truth by
view cosine and per channel, and runs a Monte Carlo walk in a sphere to measure how much more a
convex body reflects than the flat half-space the frame's model assumes.

    python -m tools.env_sphere scenes DIR           # DIR/sphere-r40.obj, white.exr, studio-rest.exr, two .toml
    skinlab reference DIR/sphere-white.toml --size 64x64 --spp 1024     # and DIR/sphere-studio-rest.toml
    python -m tools.env_sphere compare DIR/sphere-white.toml [--technique tsd]
    python -m tools.env_sphere mc [--radii 30.9,42,59.6] [--photons 400000]

`compare` renders the frame with the map's bright sources left in its smooth part (the map is
prepared without extracting sources, as the truth has no lights but the map), then prints per band
of the view cosine frame / truth - 1 per channel; on the white map also the truth and the frame
against Chandrasekhar's half-space albedo 1 - H(mu) sqrt(1 - a) (skinlab/scene/optics/boundary.py);
and the figures with the frame scaled by the Monte Carlo's curvature factor 1 + 1.33 l / R.
`mc`: photons entering a sphere of radius R mean free paths (isotropic scattering, index-matched)
with a cosine-weighted direction, as a uniform sky sends them; reflectance over the half-space's.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

RADIUS_MM = 40.0
CURVATURE_GAIN = 1.33  # the Monte Carlo's (mc): reflectance / flat - 1 = 1.33 l / R for skin1's albedos

SCENE = """# Diagnostic (issue 22, tools/env_sphere.py): a skin1 sphere, index-matched, under {what}.
[scene]
name = "{name}"
mm_per_unit = 1.0

[environment]
map = "{map}"
rotation_deg = {rotation}

[camera]
position = [0.0, 0.0, 400.0]
target = [0.0, 0.0, 0.0]
yfov_deg = 12.0
znear = 100.0
zfar = 800.0

[materials.skin]
preset = "skin1"
specular = 0.0
roughness = 0.45
sss_model = "burley"

[[meshes]]
name = "sphere"
file = "sphere-r40.obj"
material = "skin"
"""


def sphere_obj(path: Path, nu: int = 96, nv: int = 48, r: float = RADIUS_MM) -> None:
    """A UV sphere with normals and texture coordinates (texture-space diffusion needs them)."""
    lines = []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            x, y, z = math.sin(th) * math.sin(ph), math.cos(th), math.sin(th) * math.cos(ph)
            lines += [
                f"v {r * x:.6f} {r * y:.6f} {r * z:.6f}",
                f"vt {i / nu:.6f} {1 - j / nv:.6f}",
                f"vn {x:.6f} {y:.6f} {z:.6f}",
            ]
    lines.sort(key=lambda s: s[:2] != "v ")  # positions, then the rest in order (stable)
    for j in range(nv):
        for i in range(nu):
            a, b, c, d = (jj * (nu + 1) + ii + 1 for ii, jj in ((i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)))
            for t in ([(a, b, d)] if j > 0 else []) + ([(b, c, d)] if j < nv - 1 else []):
                lines.append("f " + " ".join(f"{k}/{k}/{k}" for k in t))
    path.write_text("\n".join(lines) + "\n")


def write_scenes(out: Path) -> None:
    from skinlab.scene import envmap

    out.mkdir(parents=True, exist_ok=True)
    sphere_obj(out / "sphere-r40.obj")
    envmap.write_map(out / "white.exr", np.ones((32, 64, 3), np.float32))
    pixels, _ = envmap.load_pixels(envmap.resolve_map("studio"))
    envmap.write_map(out / "studio-rest.exr", envmap.extract_sources(pixels)[1])
    for name, m, rot, what in (
        ("sphere-white", "white.exr", 0.0, "a uniform white map (a furnace)"),
        ("sphere-studio-rest", "studio-rest.exr", 30.0, "the studio map without its two extracted lamps"),
    ):
        (out / f"{name}.toml").write_text(SCENE.format(name=name, map=m, rotation=rot, what=what))
        print(f"wrote {out / name}.toml")


def _view_cosines(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel: on the sphere, and n.v (the camera of SCENE)."""
    f = math.tan(math.radians(6.0))
    y, x = np.mgrid[0:h, 0:w]
    d = np.stack([((x + 0.5) / w * 2 - 1) * f, -((y + 0.5) / h * 2 - 1) * f, -np.ones((h, w))], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.array([0.0, 0.0, 400.0])
    b = d @ o
    disc = b * b - (o @ o - RADIUS_MM**2)
    hit = disc > 0
    p = o + (-b - np.sqrt(np.maximum(disc, 0)))[..., None] * d
    return hit, np.clip(-(p / RADIUS_MM * d).sum(-1), 0, 1)


def compare(scene_path: str, technique: str) -> None:
    from skinlab.bench.sweep import QUICK
    from skinlab.bench.truth_ledger import load_truth, truth_errors
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene import envmap
    from skinlab.scene.optics.boundary import albedo_isotropic
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.scenefile import load_scene
    from tools.truth_table import truth_spec

    keep = envmap.extract_sources
    envmap.extract_sources = lambda img, max_sources=0: keep(img, 0)  # the whole map is the smooth part
    envmap.PREPARE_VERSION += 1000  # and its own disk cache
    scene = load_scene(scene_path)
    truth = load_truth(scene, truth_spec("64:1024"), progress=False)
    if truth is None:
        sys.exit(f"no cached 64x64 1024-spp reference of {scene_path}: render it first (module docstring)")
    r = Renderer(create_headless_context())
    try:
        rs = RenderSettings.for_technique(technique, 64, 64, shadow_size=QUICK.shadow_size, supersample=4)
        img = r.render(scene, rs, readback=("hdr",)).hdr
    finally:
        r.release()
    medium = material_medium(scene.mesh_nodes()[0].material.values)
    fr, tr = img[..., :3].astype(np.float64), truth.image[..., :3].astype(np.float64)
    hit, mu = _view_cosines(*tr.shape[:2])
    white = "white" in Path(scene_path).stem
    flat = np.stack([albedo_isotropic(a, mu) for a in medium.alpha_arr], -1)
    for lo, hi in ((0.15, 0.4), (0.4, 0.6), (0.6, 0.8), (0.8, 1.01)):
        s = hit & (mu >= lo) & (mu < hi)
        line = f"mu {lo:.2f}-{hi:.2f}: frame/truth - 1 {np.round(100 * (fr[s].sum(0) / tr[s].sum(0) - 1), 1)} %"
        if white:
            t_flat = np.round(100 * (tr[s].sum(0) / flat[s].sum(0) - 1), 1)
            f_flat = np.round(100 * (fr[s].sum(0) / flat[s].sum(0) - 1), 1)
            line += f"   truth/flat - 1 {t_flat} %   frame/flat - 1 {f_flat} %"
        print(line)
    gain = 1.0 + CURVATURE_GAIN * medium.mfp_arr / RADIUS_MM
    for label, im in (
        ("frame", img),
        (f"frame x (1 + {CURVATURE_GAIN} l/R)", np.concatenate([fr * gain, img[..., 3:]], -1)),
    ):
        e = truth_errors(im, truth)
        energy = " ".join(f"{100 * e[f'truth_energy_{c}']:+.1f}" for c in "rgb")
        block, noise = 100 * e["truth_rel_l1_block"], 100 * e["truth_noise_block"]
        print(f"{label}: 4x4 {block:.1f} %, energy {energy} % (truth noise {noise:.1f} %)")


def walk(a: float, radius: float, photons: int, seed: int = 1) -> float:
    """Reflectance of a sphere of `radius` mean free paths under a uniform sky (isotropic phase, index 1)."""
    rng = np.random.default_rng(seed)
    u1, u2 = rng.random(photons), rng.random(photons)
    st, ph = np.sqrt(1 - u1), 2 * np.pi * u2
    d = np.stack([st * np.cos(ph), st * np.sin(ph), -np.sqrt(u1)], 1)  # cosine-weighted, inward at the top
    p = np.tile([0.0, 0.0, radius], (photons, 1))
    w, alive, out = np.ones(photons), np.ones(photons, bool), 0.0
    while alive.any():
        idx = np.nonzero(alive)[0]
        pp, dd = p[idx], d[idx]
        s = -np.log(rng.random(len(idx)))
        b = (pp * dd).sum(1)
        t_exit = -b + np.sqrt(np.maximum(b * b - ((pp * pp).sum(1) - radius * radius), 0))
        gone = s >= t_exit
        out += w[idx[gone]].sum()
        alive[idx[gone]] = False
        stay = idx[~gone]
        p[stay] = pp[~gone] + s[~gone, None] * dd[~gone]
        w[stay] *= a
        m, phi = rng.random(len(stay)) * 2 - 1, 2 * np.pi * rng.random(len(stay))
        sq = np.sqrt(1 - m * m)
        d[stay] = np.stack([sq * np.cos(phi), sq * np.sin(phi), m], 1)
        low = stay[w[stay] < 1e-3]  # Russian roulette
        survive = rng.random(len(low)) < 0.1
        w[low[survive]] *= 10.0
        alive[low[~survive]] = False
    return out / photons


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("scenes").add_argument("out", type=Path)
    c = sub.add_parser("compare")
    c.add_argument("scene")
    c.add_argument("--technique", default="tsd")
    m = sub.add_parser("mc")
    m.add_argument("--radii", default="30.9,42,59.6")  # 40 mm in skin1's mean free paths, R G B
    m.add_argument("--photons", type=int, default=400_000)
    args = ap.parse_args(argv)
    if args.cmd == "scenes":
        write_scenes(args.out)
    elif args.cmd == "compare":
        compare(args.scene, args.technique)
    else:
        from skinlab.scene.optics.boundary import albedo_isotropic, hemispherical

        radii = [float(x) for x in args.radii.split(",")]
        for a in (0.8941265, 0.68742125, 0.4944199):  # skin1's reduced albedos
            flat = hemispherical(lambda mu, a=a: albedo_isotropic(a, mu))
            gains = " ".join(f"R = {r:g} l: {walk(a, r, args.photons) / flat - 1:+.4f}" for r in radii)
            print(f"albedo {a:.3f}: flat {flat:.4f}; sphere / flat - 1: {gains}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
