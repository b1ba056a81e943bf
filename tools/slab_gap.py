"""Where the two back-lit slabs' shared error comes from (a one-off analysis for docs/ground-truth.md,
"What the two slabs share"; not a feature).

slabs-gap-backlit-skin1 has two 3 mm skin1 slabs 10 mm apart, lit from behind; the frame counts the
front slab's light as through one slab of the summed thickness (lib/sss_translucency.glsl
sss_thickness_mm), exact for infinite index-matched parallel slabs. This prints:

1. ``--model``: the slab model (skinlab/scene/optics/slab.py slab_through and slab_exit) against a
   photon Monte Carlo of one infinite slab (3 and 6 mm, isotropic, index-matched: the truth's
   medium), the transmitted flux and the radiance toward the camera's cosine;
2. ``--gap``: the doubling method's transmission of the two slabs with a fraction F of each round trip
   between them kept (1 - F leaves the gap past the front slab's edges: F the view factor of the front
   slab from the back one), over the summed slab's (F = 1), per channel;
3. ``--edges TECH``: the frame (TECH, supersampled like closeup_table's) over the cached truth on the
   front slab's face, binned by the distance from that slab's edge.

    python -m tools.slab_gap [--model] [--gap] [--edges TECH]   (none given: all three, tsd)
"""

from __future__ import annotations

import argparse

import numpy as np

SCENE = "slabs-gap-backlit-skin1"
MU0 = 0.866  # the light's cosine on the slabs (30 degrees off their axis)
MU_VIEW = 0.954  # the camera's cosine to the slabs' normal at their centre
HALF_WIDTH_MM = 30.0  # the front slab's half width


def _medium():
    from skinlab.bench.truth_ledger import REFERENCE_SCENES
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.scenefile import load_scene

    scene = load_scene(REFERENCE_SCENES / f"{SCENE}.toml")
    vals = scene.mesh_nodes()[0].material.values
    return scene, material_medium(vals), np.asarray(vals["subsurface_color"], np.float64)


def monte_carlo(a: float, l: float, d: float, mu0: float, n: int, seed: int, band=(0.93, 0.975)):
    """Diffusely transmitted flux (per unit beam flux normal to the beam x mu0) through an infinite
    index-matched slab d mm thick (mean free path l, single-scattering albedo a, isotropic), and its
    radiance in the exit-cosine band: (flux, radiance)."""
    rng = np.random.default_rng(seed)
    z, w, mu = np.zeros(n), np.ones(n), np.full(n, mu0)
    scattered, alive = np.zeros(n, bool), np.ones(n, bool)
    flux = band_w = 0.0
    while alive.any():
        i = np.nonzero(alive)[0]
        zn = z[i] - np.log(rng.random(len(i))) * l * mu[i]
        far, near = zn >= d, zn <= 0
        ex = i[far & scattered[i]]
        flux += w[ex].sum()
        band_w += w[ex][(mu[ex] >= band[0]) & (mu[ex] < band[1])].sum()
        alive[i[far | near]] = False
        st = i[~(far | near)]
        z[st], w[st], scattered[st] = zn[~(far | near)], w[st] * a, True
        mu[st] = 2.0 * rng.random(len(st)) - 1.0
        low = st[w[st] < 1e-3]  # Russian roulette
        keep = rng.random(len(low)) < 0.1
        w[low[keep]] *= 10.0
        alive[low[~keep]] = False
    return mu0 * flux / n, mu0 * band_w / n / (np.pi * (band[1] ** 2 - band[0] ** 2))


def two_slab_ratio(a: float, tau: float, mu0: float, keep: float) -> float:
    """Two equal slabs of optical thickness tau, a beam at mu0 on the first: the transmitted flux with
    a fraction `keep` of every round trip between them over the flux with all of it (the summed slab)."""
    from skinlab.scene.optics.slab import QUAD_NODES

    x, w = np.polynomial.legendre.leggauss(QUAD_NODES)
    mu = np.concatenate([0.5 * (x + 1.0), [mu0]])
    wt = np.concatenate([0.5 * w, [0.0]])
    n = 30 + int(np.ceil(np.log2(tau)))
    dd = tau / 2.0**n
    r = a * dd * wt[:, None] / (2.0 * mu[None, :])
    t = np.diag(np.exp(-dd / mu)) + r
    eye = np.eye(len(mu))
    for _ in range(n):
        m = np.linalg.solve(eye - r @ r, t)
        r, t = r + t @ np.linalg.solve(eye - r @ r, r @ t), t @ m
    beam = np.zeros(len(mu))
    beam[-1] = 1.0
    first = t @ beam

    def through(f: float) -> float:
        return float((t @ np.linalg.solve(eye - f * r @ r, first))[:QUAD_NODES].sum())

    return through(keep) / through(1.0)


def parallel_squares_view_factor(side: float, gap: float) -> float:
    """View factor between two equal, parallel, directly opposed squares (side, gap apart): the
    closed form for opposed rectangles (Howell's catalogue, C-11)."""
    x = y = side / gap
    a, b = 1.0 + x * x, 1.0 + y * y
    v = 0.5 * np.log(a * b / (1.0 + x * x + y * y))
    v += x * np.sqrt(b) * np.arctan(x / np.sqrt(b)) + y * np.sqrt(a) * np.arctan(y / np.sqrt(a))
    v -= x * np.arctan(x) + y * np.arctan(y)
    return float(2.0 * v / (np.pi * x * y))


def report_model() -> None:
    from skinlab.scene.optics.boundary import boundary_tables
    from skinlab.scene.optics.translucency import through, translucent_exit

    _, med, colour = _medium()
    tables = boundary_tables(med.alpha_arr, colour, 1.0)  # index-matched (specular 0)

    print(
        "the slab model against a photon Monte Carlo (4 x 1M photons per channel; +- its standard error), "
        f"beam at cosine {MU0}:"
    )
    for d in (3.0, 6.0):
        t = through(np.array([MU0]), np.array([d]), tables, med, colour)[0] * colour * MU0
        ex = translucent_exit(np.array([MU_VIEW]), np.array([MU0]), np.array([d]), tables, med, colour)[0]
        for c in range(3):
            a, l = med.alpha_arr[c], med.mfp_arr[c]
            runs = np.array([monte_carlo(a, l, d, MU0, 1_000_000, seed=8 * c + k) for k in range(4)])
            (flux, rad), se = runs.mean(0), runs.std(0, ddof=1) / 2.0
            model_rad = t[c] / np.pi * ex[c]
            print(
                f"  {d:g} mm, channel {c}: flux {t[c]:.5g} against {flux:.5g} ({100 * (t[c] / flux - 1):+.1f} "
                f"+- {100 * se[0] / flux:.1f} %), radiance at cosine {MU_VIEW} {model_rad:.4g} against {rad:.4g} "
                f"({100 * (model_rad / rad - 1):+.1f} +- {100 * se[1] / rad:.1f} %)"
            )


def report_gap() -> None:
    _, med, _ = _medium()
    f_avg = parallel_squares_view_factor(2 * HALF_WIDTH_MM, 10.0)
    f_mid = (2 * HALF_WIDTH_MM) ** 2 / ((2 * HALF_WIDTH_MM) ** 2 + np.pi * 10.0**2)  # a disk of the same area
    print(
        f"two 3 mm slabs, F kept of each round trip (view factor of the 60 mm front slab from the back one, "
        f"10 mm apart: {f_avg:.2f} on average, about {f_mid:.2f} from the centre): transmission over the summed slab's"
    )
    for keep in (1.0, 0.9, f_avg, 0.6):
        vals = [two_slab_ratio(med.alpha_arr[c], 3.0 / med.mfp_arr[c], MU0, keep) for c in range(3)]
        print(
            f"  F = {keep:.2f}: "
            + " / ".join(f"{v:.3f}" for v in vals)
            + "  (the summed slab's reading "
            + " / ".join(f"{100 * (1 / v - 1):+.1f}" for v in vals)
            + " %)"
        )


def report_edges(tech: str) -> None:
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    from skinlab.bench.closeup import _scene_mesh, camera_rays
    from skinlab.bench.truth_ledger import TRUTH_SUPERSAMPLE
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from tools.closeup_table import CLOSEUPS, load_closeup_truth

    scene, _, _ = _medium()
    spec = CLOSEUPS[SCENE]
    truth = load_closeup_truth(scene, spec)
    if truth is None:
        raise SystemExit(f"slab_gap: no cached truth of {SCENE}; render it with\n    {spec.command(SCENE)}")
    w, h = spec.size
    mesh, owners = _scene_mesh(scene)
    o, d = camera_rays(scene, w, h)
    tri, idx, loc = RayMeshIntersector(mesh).intersects_id(o, d, multiple_hits=False, return_locations=True)
    node = np.full(len(o), -1)
    node[idx] = owners[tri]
    pos = np.full((len(o), 3), np.nan)
    pos[idx] = loc
    nz = np.zeros(len(o))
    nz[idx] = np.abs(mesh.face_normals[tri][:, 2])
    face = ((node == 0) & (nz > 0.9)).reshape(h, w)
    edge = (HALF_WIDTH_MM - np.maximum(np.abs(pos[:, 0]), np.abs(pos[:, 1]))).reshape(h, w)
    r = Renderer(create_headless_context())
    rs = RenderSettings.for_technique(tech, w, h, supersample=TRUTH_SUPERSAMPLE)
    img = r.render(scene, rs, readback=("hdr",)).hdr
    r.release()
    print(f"{tech} over the truth on the front slab's face, by the distance from its edge (R / G / B):")
    for lo, hi in ((0, 2), (2, 5), (5, 10), (10, 20), (20, 31)):
        m = face & (edge >= lo) & (edge < hi)
        if m.any():
            f, t = img[m][:, :3].sum(0), truth.image[m][:, :3].sum(0)
            print(
                f"  {lo:2d}-{hi:2d} mm ({m.sum():4d} px): "
                + " / ".join(f"{100 * (a / b - 1):+.1f}" for a, b in zip(f, t))
                + " %, the truth's mean "
                + " / ".join(f"{x:.4g}" for x in t / m.sum())
            )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.slab_gap", description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", action="store_true", help="the slab model against a photon Monte Carlo")
    ap.add_argument("--gap", action="store_true", help="the two slabs with a fraction of each round trip kept")
    ap.add_argument("--edges", metavar="TECH", default=None, help="the frame over the truth by distance from the edge")
    args = ap.parse_args(argv)
    every = not (args.model or args.gap or args.edges)
    if args.model or every:
        report_model()
    if args.gap or every:
        report_gap()
    if args.edges or every:
        report_edges(args.edges or "tsd")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
