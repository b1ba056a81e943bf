"""Documentation, not a feature: regenerate the accuracy table of docs/accuracy.md: every profile model
against the Monte Carlo reference (skinlab/scene/optics/montecarlo.py) for reduced albedos 0.1 .. 0.99.

    .venv/bin/python -m tools.accuracy_table [--photons 200000] [--eta 1.3] [--seed 1] [--out FILE]

Set-up: semi-infinite medium, mean free path 1 (results are scale free), isotropic phase (the
reduced coefficients), normally incident light, per photon entering (entry Fresnel excluded, as in
the analytic profiles). For each albedo and model:
  total  = (model total reflectance - MC total) / MC total
  shape  = energy-weighted L1 error of the radial profile over r in [0.05, 10] mfp:
           sum |Rbar_model - R_mc| A_bin / sum R_mc A_bin, with Rbar_model the model averaged over
           each annulus (41-point quadrature) and A_bin the annulus area.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from skinlab.scene.optics.media import Medium
from skinlab.scene.optics.montecarlo import simulate
from skinlab.scene.optics.profiles import evaluate_profile, total_reflectance

ALBEDOS = (0.1, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95, 0.99)
MODELS = ("dipole", "dipole+ss", "pbd", "burley", "blender-burley", "gaussians")
EDGES = np.concatenate([[0.0], np.geomspace(0.05, 10.0, 41)])


def bin_average(name, m, edges):
    out = []
    for r0, r1 in zip(edges[:-1], edges[1:]):
        rr = np.linspace(max(r0, 1e-6), r1, 41)
        f = evaluate_profile(name, rr, m)[:, 0] * 2 * np.pi * rr
        out.append(np.trapezoid(f, rr) / (np.pi * (r1**2 - r0**2)))
    return np.array(out)


def measure(photons, eta, seed, progress=True):
    rows = []
    for k, a in enumerate(ALBEDOS):
        res = simulate(a, eta, 0.0, "normal", photons, seed + k, r_edges=EDGES, progress=progress, workers=2)
        m = Medium((a,) * 3, (1.0,) * 3, eta)
        sel = EDGES[:-1] >= 0.05
        area = np.pi * np.diff(EDGES**2)[sel]
        ref = res.R[sel]
        models: dict[str, tuple[float, float]] = {}
        row = {"albedo": a, "mc_total": res.total, "mc_se": res.total_se, "models": models}
        for name in MODELS:
            t = float(total_reflectance(name, m)[0])
            mod = bin_average(name, m, EDGES)[sel]
            shape = float(np.sum(np.abs(mod - ref) * area) / np.sum(ref * area))
            models[name] = ((t - res.total) / res.total, shape)
        rows.append(row)
    return rows


def markdown(rows, photons, eta, seed):
    head = "| albedo alpha' | MC total +- s.e. | " + " | ".join(MODELS) + " |"
    sep = "|---|---|" + "---|" * len(MODELS)
    lines = [
        f"Total reflectance error (model - MC)/MC, eta = {eta}, {photons:,} photons per albedo, seed {seed}:",
        "",
        head,
        sep,
    ]
    for r in rows:
        lines.append(
            f"| {r['albedo']} | {r['mc_total']:.4f} +- {r['mc_se']:.4f} | "
            + " | ".join(f"{100 * r['models'][n][0]:+.1f} %" for n in MODELS)
            + " |"
        )
    lines += [
        "",
        "Profile shape error (energy-weighted L1 over 0.05-10 mfp):",
        "",
        "| albedo alpha' | " + " | ".join(MODELS) + " |",
        "|---|" + "---|" * len(MODELS),
    ]
    for r in rows:
        lines.append(f"| {r['albedo']} | " + " | ".join(f"{100 * r['models'][n][1]:.1f} %" for n in MODELS) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--photons", type=int, default=200_000)
    p.add_argument("--eta", type=float, default=1.3)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", help="write the markdown table here (default: stdout)")
    p.add_argument("--no-progress", action="store_true")
    a = p.parse_args(argv)
    text = markdown(measure(a.photons, a.eta, a.seed, not a.no_progress), a.photons, a.eta, a.seed)
    if a.out:
        from skinlab.atomic_write import write_text_atomic

        write_text_atomic(a.out, text)
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
