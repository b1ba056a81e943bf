"""`skinlab mc (--single-albedo A [--eta ETA] | --preset NAME) --incidence diffuse|normal --photons N [--g G]
[--seed S] --json`: Monte Carlo reference profile of a semi-infinite medium in mean-free-path units.

One name, one meaning, in every command: ``--single-albedo`` is the single-scattering albedo
sigma_s / sigma_t (what a random walk takes), ``skinlab profile --surface-albedo`` the surface albedo
(the colour seen from afar, a scene's subsurface_color). A bare ``--albedo`` is refused with both
names."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os

import numpy as np

from skinlab.commands import refused_option
from skinlab.commands.field_options import add_command_options, check_command_options
from skinlab.declare import Field

UNITS = "r in mean free paths 1/sigma_t; R(r) in 1/mfp^2 (per unit area) per photon entering"


ALBEDO = (
    "say which albedo: --single-albedo A (sigma_s/sigma_t, what the random walk takes) or "
    "--preset NAME; the surface albedo (the colour seen from afar) is skinlab profile --surface-albedo"
)  # one meaning per name: two albedos, two names


def _walk(key: str, **kw):
    """A walk parameter of skinlab/scene/optics/montecarlo.py (its range, the one the walk checks) as an option."""
    from skinlab.scene.optics.montecarlo import WALK_FIELDS

    return dataclasses.replace(WALK_FIELDS[key], **kw)


def mc_options() -> tuple[tuple[Field, ...], tuple[Field, ...]]:
    """(the medium: one of --single-albedo and --preset; the walk's options), each from its declaration."""
    single = _walk("albedo", name="single_albedo", doc=f"{_walk('albedo').doc} (not the surface albedo: "
                   "skinlab profile --surface-albedo)")  # fmt: skip
    preset = Field(
        "preset",
        "string",
        doc="a Jensen 2001 Table 1 medium (e.g. skin1, marble): one walk per channel, R, G and B, each with that "
        "channel's single-scattering albedo, at the preset's index (unless --eta)",
    )
    walk = (
        _walk("eta", default=None, shown="1.3, or the preset's"),
        _walk("incidence", doc="normal: a pencil beam along the normal; diffuse: cosine-distributed, refracted"),
        _walk("photons", doc="photons to trace (e.g. 1e6)"),
        _walk("g"),
        _walk("seed"),
        _walk("max_steps"),
        Field("entry_fresnel", "bool", False, doc="weight by the entry transmittance (default: per photon entering)"),
        _walk("workers", default=0, range=(0, math.inf), doc="processes (0: one per core)"),
        Field("no_progress", "bool", False, doc="no progress bar on stderr"),
        Field("json", "bool", False, doc="print JSON (every bin, with r_edges)"),
    )
    return (single, preset), walk


def register(sub) -> None:
    p = sub.add_parser(
        "mc",
        help="Monte Carlo radial reflectance profile (mean-free-path units)",
        description="Random walk in a semi-infinite homogeneous medium (the ground truth for the "
        f"diffusion profiles). Units: {UNITS}; multiply r by the mean free path in mm to get mm.",
    )
    source, walk = mc_options()
    src = p.add_mutually_exclusive_group(required=True)
    add_command_options(src, source)
    src.add_argument("--albedo", action=refused_option(ALBEDO), help=argparse.SUPPRESS)
    add_command_options(p, walk)
    p.set_defaults(func=run)


def run(args) -> int:
    from skinlab.scene.optics.montecarlo import simulate

    for fields in mc_options():
        check_command_options(args, fields)
    workers = args.workers or (os.cpu_count() or 1)

    def walk(albedo, eta):
        return simulate(
            albedo,
            eta,
            args.g,
            args.incidence,
            args.photons,
            args.seed,
            max_steps=args.max_steps,
            entry_fresnel=args.entry_fresnel,
            progress=not args.no_progress,
            workers=workers,
        )

    if args.preset is not None:
        return _run_preset(args, walk)
    res = walk(args.single_albedo, 1.3 if args.eta is None else args.eta)
    if args.json:
        print(json.dumps(_result(res)))
        return 0
    _print_result(res)
    return 0


def _run_preset(args, walk) -> int:
    """One walk per channel of a preset medium; r also in mm (each channel's mean free path)."""
    from skinlab.scene.optics.media import preset

    m = preset(args.preset)
    eta = m.eta if args.eta is None else args.eta
    channels = []
    for c, name in enumerate("RGB"):
        res = walk(m.alpha[c], eta)
        channels.append({"channel": name, "mfp_mm": m.mfp_mm[c], **_result(res)})
        if not args.json:
            print(f"channel {name} of {m.name}: mean free path {m.mfp_mm[c]:.4g} mm (multiply r by it for mm)")
            _print_result(res)
            print()
    if args.json:
        print(json.dumps({"units": UNITS, "preset": m.name, "eta": eta, "channels": channels}))
    return 0


def _result(res) -> dict:
    out = {
        "units": UNITS,
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
    return out


def _print_result(res) -> None:
    pr = res.params
    print(
        f"Monte Carlo: single-scattering albedo {pr['albedo']:g}, eta {pr['eta']:g}, g {pr['g']:g}, "
        f"{pr['incidence']} incidence, "
        f"{res.photons:.4g} photons, seed {pr['seed']}, max {pr['max_steps']} collisions per walk"
        + (", weighted by entry transmittance" if pr["entry_fresnel"] else "")
    )
    print(f"units: {UNITS}")
    print(
        f"total reflectance {res.total:.6f} +- {res.total_se:.6f}  "
        f"(capped walks' weight {res.capped:.2e}: the exact total lies in [total, total + capped])"
    )
    lit = np.nonzero(res.R > 0)[0]
    last = int(lit[-1]) + 1 if lit.size else 0
    print(f"{'r0 (mfp)':>10} {'r1 (mfp)':>10} {'R(r) (1/mfp^2)':>15} {'std error':>11}")
    for i in range(last):
        print(f"{res.r_edges[i]:10.4g} {res.r_edges[i + 1]:10.4g} {res.R[i]:15.6g} {res.R_se[i]:11.3g}")
    if last < len(res.R):
        print(
            f"(no photon left beyond r = {res.r_edges[last]:.4g} mfp: the {len(res.R) - last} outer bins up to "
            f"{res.r_edges[-1]:.4g} mfp are zero and not listed; --json has them)"
        )
