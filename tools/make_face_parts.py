"""Maintenance, not a feature: make the bundled face's extra parts (skinlab/assets/face-parts/):
eyeballs from UV spheres in the Lee Perry-Smith head's eye sockets, a cornea cap over each, a lash
card above each upper lid (one mesh for both), as one GLB of plain meshes
(skinlab/scenes/head-eyes.toml gives each its material), and the iris and lash textures, procedural
(seeded) PNGs.

    python -m tools.make_face_parts [--out DIR]   # default skinlab/assets/face-parts/

Geometry is in the head's own units (the scan's, 45 mm per unit: head.toml). The eye centres were
read off the scan by casting rays along -z over the face (the lids' bulge, symmetric about the nose at
x = -0.1): (-0.68, 1.78) and (0.48, 1.78), the lids' crowns at z = 1.96; an eyeball of radius 0.24 units
(11 mm) sits with its front 0.012 units ahead of the crown, so the scan's closed lids intersect it (the
path tracer sees two media overlap there: the head's and the eye's).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "skinlab" / "assets" / "face-parts"
EYES = ((-0.68, 1.78), (0.48, 1.78))
LID_Z, EYE_R = 1.96, 0.24
EYE_Z = LID_Z + 0.012 - EYE_R
CORNEA_R, CORNEA_THETA = 0.14, math.radians(62.0)


def uv_sphere(r: float, n_lat: int = 16, n_lon: int = 28):
    """Positions, normals and indices of a UV sphere about the origin, poles on +-y."""
    pos, nrm = [], []
    for i in range(n_lat + 1):
        th = math.pi * i / n_lat
        for j in range(n_lon + 1):
            ph = 2 * math.pi * j / n_lon
            n = (math.sin(th) * math.sin(ph), math.cos(th), math.sin(th) * math.cos(ph))
            nrm.append(n)
            pos.append(tuple(r * c for c in n))
    idx = []
    w = n_lon + 1
    for i in range(n_lat):
        for j in range(n_lon):
            a, b = i * w + j, (i + 1) * w + j
            if i > 0:
                idx.append((a, b, a + 1))
            if i < n_lat - 1:
                idx.append((a + 1, b, b + 1))
    return np.array(pos, np.float32), np.array(nrm, np.float32), np.array(idx, np.uint32)


def cap(r: float, theta_max: float, n_rings: int = 8, n_seg: int = 28):
    """A spherical cap about +z (polar angle <= theta_max), centre of the sphere at the origin."""
    pos, nrm = [(0.0, 0.0, r)], [(0.0, 0.0, 1.0)]
    for i in range(1, n_rings + 1):
        th = theta_max * i / n_rings
        for j in range(n_seg):
            ph = 2 * math.pi * j / n_seg
            n = (math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th))
            nrm.append(n)
            pos.append((r * n[0], r * n[1], r * n[2]))
    idx = [(0, 1 + j, 1 + (j + 1) % n_seg) for j in range(n_seg)]
    for i in range(n_rings - 1):
        a0, b0 = 1 + i * n_seg, 1 + (i + 1) * n_seg
        for j in range(n_seg):
            k = (j + 1) % n_seg
            idx += [(a0 + j, b0 + j, b0 + k), (a0 + j, b0 + k, a0 + k)]
    return np.array(pos, np.float32), np.array(nrm, np.float32), np.array(idx, np.uint32)


def lash_cards():
    """One strip per eye along the upper lid, leaning forward; u along the lid, v from root to tip."""
    pos: list[tuple[float, float, float]] = []
    nrm: list[tuple[float, float, float]] = []
    uv: list[tuple[float, float]] = []
    idx: list[tuple[int, int, int]] = []
    n = 10
    for cx, cy in EYES:
        base = len(pos)
        for i in range(n + 1):
            t = i / n
            x = cx - 0.26 + 0.52 * t
            dz = math.sqrt(max(EYE_R**2 - (x - cx) ** 2, 0.0))
            z = EYE_Z + 0.9 * dz + 0.03
            y = cy + 0.12 + 0.05 * math.sin(math.pi * t)
            for v, (ly, lz) in enumerate(((0.0, 0.0), (0.06, 0.12))):
                pos.append((x, y + ly, z + lz))
                nrm.append((0.0, -0.57, 0.82))
                uv.append((t, float(v)))
        for i in range(n):
            a = base + 2 * i
            idx += [(a, a + 2, a + 3), (a, a + 3, a + 1)]
    return np.array(pos, np.float32), np.array(nrm, np.float32), np.array(uv, np.float32), np.array(idx, np.uint32)


def iris_png(size: int = 128, seed: int = 23) -> np.ndarray:
    """RGB: the white of the eye, a green-grey iris with radial fibres and a dark limbus, a black pupil
    (planar UVs: the front of the eyeball at the centre; iris radius 0.24 of the texture)."""
    rng = np.random.default_rng(seed)
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size - 0.5
    r, a = np.hypot(x, y), np.arctan2(y, x)
    sclera = np.array([0.93, 0.90, 0.86])
    fibres = sum(rng.uniform(0.3, 1.0) * np.cos(k * a + rng.uniform(0, 6.3)) for k in rng.integers(20, 90, 12))
    fibres = 0.5 + 0.5 * fibres / 12
    iris_col = np.array([0.28, 0.36, 0.30])[None, None] * (0.7 + 0.6 * fibres[..., None])
    iris_col *= (0.75 + 0.5 * (r / 0.24))[..., None]
    img = np.broadcast_to(sclera, (size, size, 3)).copy()
    img[r < 0.26] = np.array([0.12, 0.13, 0.12])  # limbus
    img[r < 0.24] = iris_col[r < 0.24]
    img[r < 0.09] = np.array([0.015, 0.015, 0.02])  # pupil
    veins = (rng.random((size, size)) < 0.002) & (r > 0.32)
    img[veins] = np.array([0.7, 0.35, 0.3])
    return np.clip(img * 255 + 0.5, 0, 255).astype(np.uint8)


def lashes_png(w: int = 128, h: int = 32, seed: int = 7) -> np.ndarray:
    """RGBA: dark curved strands from the root (v = 0, the bottom row) to the tip, alpha 1 on them."""
    rng = np.random.default_rng(seed)
    img = np.zeros((h, w, 4), np.uint8)
    img[..., :3] = (30, 22, 18)
    for _ in range(70):
        u0, length, bend = rng.uniform(0, w), rng.uniform(0.6, 1.0) * h, rng.uniform(-6, 6)
        for t in np.linspace(0, 1, 3 * h):
            row = int(h - 1 - t * length)
            col = int(u0 + bend * t * t)
            if 0 <= row < h and 0 <= col < w:
                img[row, col, 3] = 255
    return img


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.make_face_parts", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=OUT, help=f"folder to write into (default {OUT})")
    out = ap.parse_args(argv).out
    from PIL import Image

    from skinlab.scene.gltf_export import export_gltf
    from skinlab.scene.graph import MeshNode, Scene
    from skinlab.scene.materials import Material
    from skinlab.scene.mesh import Mesh

    out.mkdir(parents=True, exist_ok=True)
    Image.fromarray(iris_png()).save(out / "iris.png", optimize=True)
    Image.fromarray(lashes_png(), "RGBA").save(out / "lashes.png", optimize=True)
    scene = Scene("face-parts", 45.0)
    p, n, idx = uv_sphere(EYE_R)
    uv = np.column_stack([0.5 + p[:, 0] / (2 * EYE_R), 0.5 + p[:, 1] / (2 * EYE_R)]).astype(np.float32)
    pc, nc, ic = cap(CORNEA_R, CORNEA_THETA)
    lift = EYE_R + 0.02 - CORNEA_R  # the cap's front 0.02 ahead of the eyeball's
    for side, (cx, cy) in zip(("Left", "Right"), EYES):
        c = np.array([cx, cy, EYE_Z], np.float32)
        scene.add(MeshNode(f"Eye{side}", Mesh(f"Eye{side}", p + c, idx, n, uv), Material("eye")))
        cc = c + np.array([0.0, 0.0, lift], np.float32)
        scene.add(MeshNode(f"Cornea{side}", Mesh(f"Cornea{side}", pc + cc, ic, nc), Material("cornea")))
    lp, ln, luv, li = lash_cards()
    scene.add(MeshNode("Lashes", Mesh("Lashes", lp, li, ln, luv), Material("lashes")))
    path, _ = export_gltf(scene, out / "face-parts.glb")
    print(f"wrote {path}, {out / 'iris.png'}, {out / 'lashes.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
