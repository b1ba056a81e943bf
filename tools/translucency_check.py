"""Light through thin parts against the truth, per pixel: which of two local slab models of the
thickness follows the path-traced truth (a one-off analysis for docs/ground-truth.md, "The back-lit
ear"; not a feature).

For every pixel of the scene's view the visible point, its normal and the light's direction are found
by casting rays through the mesh (Embree, through trimesh), and the light through it is predicted by
the exact slab transmittance (skinlab/scene/optics/slab.py slab_through) under two readings of the
thickness:

- ``chord``: the renderer's before issue 21's ``sheet``: the matter the light crosses on its way to
  the point (every entry and exit along the ray to the light), times the cosine of the point's normal
  with the light, lit at that cosine;
- ``normal``: the distance through the mesh along the inward normal to the far face, lit at the far
  face's own cosine where that face sees the light;
- ``entry``: the chord times the cosine of the face where the light entered the point's part (the
  back face's, not the front's; the same on a flat slab), lit at that cosine;
- ``max``: the chord times the larger of the two cosines, lit at it;
- ``sheet``: the renderer's since issue 21 (lib/sss_translucency.glsl sss_through_cosine): ``max``
  where the entry face faces away from the point's own (their normals opposed: a sheet), the chord
  times the point's cosine where both face one side (the light skims through a bulge);
- ``normal-flux``: the normal thickness at the far face's cosine, its irradiance not projected on the
  far face (lit at 1): not a model that keeps energy but a measure of how much of the truth's level the
  light travelling along a curved sheet adds (issue 21).

With ``--composite TECH`` the technique's frame with translucency off is rendered as well (at the
truth's size, supersampled like closeup_table's), each model's radiance added to it, and the sum
measured against the truth as the close-up tables measure a frame (relative L1 on 4x4 blocks and per
pixel, energy per channel): a model's frame before its shader exists (the composite of ``chord`` is
near the frame, not equal to it: no diffusion of the light through, ray-cast chords).

Each prediction is radiance (the light's colour and intensity, the base colour, 1/pi and the exit
factor of light that came through, as the renderer shades it), then scaled per channel to the truth
(the median ratio) so that its relative L1 judges the pattern alone; the frame's own against the truth
is printed beside. The scales say how far each model's level and colour are from the truth's (1 1 1:
the same).

    .venv/bin/python -m tools.translucency_check SCENE TRUTH.exr FRAME.exr [--out DIR] [--composite TECH]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def _camera_rays(scene, w: int, h: int):
    inv = np.linalg.inv(scene.camera.projection_matrix(w / h) @ scene.camera.view_matrix())
    ys, xs = np.mgrid[0:h, 0:w]
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, 1 - (ys + 0.5) / h * 2], -1).reshape(-1, 2)
    ends = []
    for z in (-1.0, 1.0):
        q = (inv @ np.c_[ndc, np.full(len(ndc), z), np.ones(len(ndc))].T).T
        ends.append(q[:, :3] / q[:, 3:])
    d = ends[1] - ends[0]
    return ends[0], d / np.linalg.norm(d, axis=1, keepdims=True)


def predictions(scene, w: int, h: int) -> dict[str, np.ndarray]:
    """(h * w, 3) predicted light through per unit irradiance for each model, and the visible mask."""
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    from skinlab.scene.interreflection import world_geometry
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.optics.slab import slab_exit, slab_exit_tables, slab_table, slab_through

    node = scene.mesh_nodes()[0]
    p, n = world_geometry(node)
    f = node.mesh.indices.astype(np.int64)
    tm = trimesh.Trimesh(p, f, process=False)
    ray = RayMeshIntersector(tm)

    def normal_at(tri, loc):
        bary = trimesh.triangles.points_to_barycentric(p[f[tri]], loc)
        q = (n[f[tri]] * bary[:, :, None]).sum(1)
        return q / np.linalg.norm(q, axis=1, keepdims=True)

    origins, dirs = _camera_rays(scene, w, h)
    tri, idx, loc = ray.intersects_id(origins, dirs, multiple_hits=False, return_locations=True)
    seen = np.zeros(h * w, bool)
    seen[idx] = True
    pos, nrm = loc, normal_at(tri, loc)
    view = np.clip(-(nrm * dirs[idx]).sum(1), 0.0, 1.0)  # the cosine toward the camera
    lights = [l for l in scene.lights() if l.kind == "directional"]
    if not lights:
        raise ValueError("translucency_check: the scene needs a directional light")
    to_light = -np.asarray(lights[0].direction, np.float64)
    to_light /= np.linalg.norm(to_light)
    mm = scene.mm_per_unit
    values = node.material.values
    med = material_medium(values)
    table = slab_table(med.alpha_arr, values["subsurface_color"])
    exits = slab_exit_tables(med.alpha_arr, table, 1.0)
    # radiance per unit of the prediction's light through: the light's colour and intensity, the base
    # colour (the table is per unit of it), 1 / pi, and the exit factor of light that came through
    scale = np.asarray(lights[0].color, np.float64) * float(lights[0].intensity) * np.asarray(values["base_color"])
    scale = scale / np.pi
    k = len(pos)

    def radiance(cos_in, d_mm, through):
        ex = np.array([slab_exit(m, c, d, table, exits, med.mfp_arr, 1.0) for m, c, d in zip(view, cos_in, d_mm)])
        return through * ex * scale

    # chord: the matter along the ray to the light (inside from the point to the first hit, then alternating)
    o = pos + to_light * 1e-4
    tri2, r2, l2 = ray.intersects_id(o, np.tile(to_light, (k, 1)), multiple_hits=True, return_locations=True)
    dist = np.linalg.norm(l2 - o[r2], axis=1)
    order = np.lexsort((dist, r2))
    r2, dist, tri2, l2 = r2[order], dist[order], tri2[order], l2[order]
    rank = np.arange(len(r2)) - np.searchsorted(r2, r2)  # the hit's place along its ray
    # the cosine to the light of the face where the light entered the point's part (the first hit)
    first = rank == 0
    n_entry = np.zeros((k, 3))
    n_entry[r2[first]] = normal_at(tri2[first], l2[first])
    cos_entry = np.clip(n_entry @ to_light, 0.0, 1.0)
    sheet = (nrm * n_entry).sum(1) < 0.0
    prev = np.where(rank > 0, np.concatenate([[0.0], dist[:-1]]), 0.0)
    chord = np.bincount(r2, np.where(rank % 2 == 0, dist - prev, 0.0), minlength=k)
    back = np.clip(-(nrm @ to_light), 0.0, 1.0)  # the light reaches the point from behind its surface
    d_chord = chord * back * mm
    through_chord = back[:, None] * slab_through(back, d_chord, table, med.mfp_arr, med.alpha_arr, 1.0)
    through_chord = radiance(back, d_chord, through_chord)

    def chord_at(c):  # the chord times the cosine c, lit at it (where the light is behind the point)
        c = np.where(back > 0, c, 0.0)
        d = chord * c * mm
        t = c[:, None] * slab_through(np.maximum(c, 1e-3), d, table, med.mfp_arr, med.alpha_arr, 1.0)
        return radiance(np.maximum(c, 1e-3), d, t)

    # normal: the far face along the inward normal, lit at its own cosine where it sees the light
    o2 = pos - nrm * 1e-4
    tri3, r3, l3 = ray.intersects_id(o2, -nrm, multiple_hits=False, return_locations=True)
    d_n = np.full(k, np.nan)
    d_n[r3] = np.linalg.norm(l3 - o2[r3], axis=1)
    cos_far = np.zeros(k)
    cos_far[r3] = np.clip(normal_at(tri3, l3) @ to_light, 0.0, 1.0)
    far = o2 - nrm * np.nan_to_num(d_n)[:, None]
    lit = ~np.isnan(d_n) & (cos_far > 0) & ~ray.intersects_any(far + to_light * 1e-3, np.tile(to_light, (k, 1)))
    t_n = slab_through(cos_far, np.nan_to_num(d_n) * mm, table, med.mfp_arr, med.alpha_arr, 1.0)
    through_normal = radiance(cos_far, np.nan_to_num(d_n) * mm, np.where(lit[:, None], cos_far[:, None] * t_n, 0.0))
    flux = radiance(cos_far, np.nan_to_num(d_n) * mm, np.where(lit[:, None], t_n, 0.0))

    out: dict[str, np.ndarray] = {"seen": seen}
    models = (
        ("chord", through_chord),
        ("normal", through_normal),
        ("entry", chord_at(cos_entry)),
        ("max", chord_at(np.maximum(back, cos_entry))),
        ("sheet", chord_at(np.where(sheet, np.maximum(back, cos_entry), back))),
        ("normal-flux", flux),
    )
    for name, v in models:
        full = np.zeros((h * w, 3))
        full[seen] = v
        out[name] = full
    return out


MODELS = ("chord", "normal", "entry", "max", "sheet", "normal-flux")


def _scale(pred: np.ndarray, truth: np.ndarray) -> float:
    m = (pred > 1e-6) & (truth > 1e-6)
    return float(np.median(truth[m] / pred[m])) if m.any() else 0.0


def _rel_l1(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).sum() / max(b.sum(), 1e-30))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.translucency_check", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="scene file (a back-lit one: light through thin parts)")
    ap.add_argument("truth", help="the path-traced truth (EXR, as `skinlab reference` writes it)")
    ap.add_argument("frame", help="Skinlab's frame of the same view and size (EXR)")
    ap.add_argument("--out", help="folder for truth | chord | normal images (tone mapped PNG)")
    ap.add_argument(
        "--composite",
        metavar="TECH",
        help="also render TECH without translucency and measure it plus each model's light through",
    )
    args = ap.parse_args(argv)
    from skinlab.image_output import read_image, write_image
    from skinlab.scene.scenefile import load_scene

    truth_rgba, frame = read_image(args.truth), read_image(args.frame)[..., :3]
    truth = truth_rgba[..., :3]
    if truth.shape != frame.shape:
        raise SystemExit(
            f"translucency_check: the truth is {truth.shape[1]}x{truth.shape[0]}, the frame "
            f"{frame.shape[1]}x{frame.shape[0]}: render them at one size"
        )
    h, w = truth.shape[:2]
    scene = load_scene(args.scene)
    pred = predictions(scene, w, h)
    seen = pred["seen"]
    t, fr = truth.reshape(-1, 3)[seen], frame.reshape(-1, 3)[seen]
    print(f"{args.scene}: {seen.sum()} pixels; relative L1 per channel R G B against the truth")
    print("  frame          " + "  ".join(f"{_rel_l1(fr[:, c], t[:, c]):6.3f}" for c in range(3)))
    images = [truth]
    for name in MODELS:
        v = pred[name][seen]
        k = np.array([_scale(v[:, c], t[:, c]) for c in range(3)])
        errs = "  ".join(f"{_rel_l1(k[c] * v[:, c], t[:, c]):6.3f}" for c in range(3))
        print(f"  {name:11s} model  {errs}   (times {k[0]:.3f} {k[1]:.3f} {k[2]:.3f} to the truth's level)")
        full = np.zeros((h * w, 3))
        full[seen] = v * k
        images.append(full.reshape(h, w, 3))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        for name, img in zip(("truth", *MODELS), images):
            ldr = (np.clip(1.0 - np.exp(-6.0 * img), 0.0, 1.0) ** (1 / 2.2) * 255).astype(np.uint8)
            print(f"wrote {write_image(out / f'{name}.png', ldr)}")
    if args.composite:
        composite(scene, args.composite, truth_rgba, pred)
    return 0


def composite(scene, technique: str, truth: np.ndarray, pred: dict[str, np.ndarray]) -> None:
    """Print the technique's frame, its frame without translucency, and that plus each model's light
    through, each against the truth (image_error: 4x4 blocks, per pixel, energy per channel)."""
    from skinlab.bench.truth_ledger import TRUTH_SUPERSAMPLE
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.truth.compare import image_error

    h, w = truth.shape[:2]
    r = Renderer(create_headless_context())
    frames = {}
    for on in (True, False):
        rs = RenderSettings.for_technique(technique, w, h, supersample=TRUTH_SUPERSAMPLE, translucency=on)
        frames[on] = np.asarray(r.render(scene, rs, readback=("hdr",)).hdr, np.float64)[..., :3]

    def line(name: str, img: np.ndarray) -> None:
        e = image_error(img, truth)
        energy = "/".join(f"{100 * x:+.1f}" for x in e["energy"])
        print(f"  {name:34s} 4x4 {100 * e['rel_l1_block']:6.2f} %  px {100 * e['rel_l1']:6.2f} %  energy {energy} %")

    print(f"{technique} against the truth, and its frame without translucency plus each model's light through:")
    line(f"{technique} (its translucency)", frames[True])
    line(f"{technique} without translucency", frames[False])
    for name in MODELS:
        line(f"  + {name}", frames[False] + pred[name].reshape(h, w, 3))


if __name__ == "__main__":
    sys.exit(main())
