"""`skinlab mc --albedo A --eta ETA --incidence diffuse|normal --photons N [--g G] [--seed S] --json`:
Monte Carlo reference profile of a semi-infinite medium in mean-free-path units."""

from __future__ import annotations

import json
import os


def register(sub) -> None:
    p = sub.add_parser("mc", help="Monte Carlo radial reflectance profile (mean-free-path units)")
    p.add_argument("--albedo", type=float, required=True, help="single-scattering albedo in [0, 1]")
    p.add_argument("--eta", type=float, default=1.3, help="relative index of refraction (default 1.3)")
    p.add_argument("--incidence", choices=("normal", "diffuse"), default="normal")
    p.add_argument("--photons", type=float, default=1e5, help="number of photons (e.g. 1e6)")
    p.add_argument("--g", type=float, default=0.0, help="Henyey-Greenstein mean cosine (default 0)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--max-steps", type=int, default=100_000, help="collision cap per walk")
    p.add_argument(
        "--entry-fresnel",
        action="store_true",
        help="weight by the entry transmittance (default: per photon that enters)",
    )
    p.add_argument("--workers", type=int, default=0, help="processes (default: all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    from scene.optics.montecarlo import simulate

    if args.photons != int(args.photons):
        raise ValueError(f"photons: need an integer, got {args.photons!r}")
    workers = args.workers or (os.cpu_count() or 1)
    res = simulate(
        args.albedo,
        args.eta,
        args.g,
        args.incidence,
        int(args.photons),
        args.seed,
        max_steps=args.max_steps,
        entry_fresnel=args.entry_fresnel,
        progress=not args.no_progress,
        workers=workers,
    )
    out = {
        "units": "mean free paths (sigma_t = 1); R per unit area",
        "params": res.params,
        "photons": res.photons,
        "r_edges": res.r_edges.tolist(),
        "r": res.r_mid.tolist(),
        "R": res.R.tolist(),
        "R_se": res.R_se.tolist(),
        "total": res.total,
        "total_se": res.total_se,
        "capped": res.capped,
    }
    if args.json:
        print(json.dumps(out))
    else:
        print(f"total reflectance {res.total:.6f} +- {res.total_se:.6f}  (capped walks: {res.capped:.2e})")
        print(f"{'r':>12} {'R(r)':>14} {'se':>12}")
        for r, R, se in zip(res.r_mid, res.R, res.R_se):
            print(f"{r:12.5g} {R:14.6g} {se:12.3g}")
    return 0
