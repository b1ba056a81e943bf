"""`skinlab profile MODEL [--preset NAME | --surface-albedo R,G,B --mfp R,G,B] [--r LIST] [--json] [--plot PATH]`:
evaluate a diffusion profile (skinlab/scene/optics/profiles.py) for a medium; optionally plot every model
against the Monte Carlo reference. ``--surface-albedo`` is the colour seen from afar (a scene's
subsurface_color); ``skinlab mc --single-albedo`` the single-scattering albedo: a bare ``--albedo`` is
refused with both names."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np

from skinlab.atomic_write import atomic_path
from skinlab.commands import refused_option
from skinlab.commands.field_options import add_command_options, check_command_options
from skinlab.declare import Field
from skinlab.scene.optics.montecarlo import WALK_FIELDS

MAX_LENGTH_MM = 1e6  # a kilometre of mean free path: beyond it the profiles underflow to nothing
DEFAULT_R = "0,0.01,0.02,0.05,0.1,0.2,0.5,1,2,5,10"


def _radii(text: str):
    try:
        r = np.array([float(v) for v in text.split(",") if v.strip()])
    except ValueError:
        raise ValueError(f"r: expected comma-separated radii in mm, got {text!r}") from None
    if r.size == 0 or np.any(~np.isfinite(r)) or np.any(r < 0):
        raise ValueError(f"r: radii must be finite and >= 0 mm, got {text!r}")
    return r


ALBEDO = (
    "say which albedo: --surface-albedo R,G,B (the colour seen from afar, a scene's "
    "subsurface_color); the single-scattering albedo is skinlab mc --single-albedo"
)  # one meaning per name: two albedos, two names


SOURCE_OPTIONS = (
    Field("preset", "string", doc="Jensen 2001 Table 1 material (e.g. skin1, marble)", shown="skin1"),
    Field(
        "surface_albedo",
        "color",
        None,
        (0.0, 1.0),
        doc="surface albedo (total diffuse reflectance, the colour seen from afar: a scene's subsurface_color), "
        "one number or R,G,B; needs --mfp or --radius. Not the single-scattering albedo (skinlab mc --single-albedo)",
    ),
)
PROFILE_OPTIONS = (
    Field(
        "mfp",
        "color",
        None,
        (0.0, MAX_LENGTH_MM),
        unit="mm",
        doc="mean free path l = 1/sigma_t' in mm, one number or R,G,B (with --surface-albedo)",
    ),
    Field(
        "radius",
        "color",
        None,
        (0.0, MAX_LENGTH_MM),
        unit="mm",
        doc="artist radius R = 4 pi l in mm, R,G,B (with --surface-albedo): the scene files' subsurface_radius "
        "and Blender's Subsurface Radius x Scale",
    ),
    Field("eta", "float", None, doc="relative index of refraction", shown="1.3, or the preset's"),
    Field(
        "albedo_method",
        "choice",
        "pbd",
        choices=("pbd", "dipole", "cycles"),
        doc="how --surface-albedo is inverted to the single-scattering albedo",
    ),
    Field("r", "string", DEFAULT_R, doc="radii in mm, comma-separated, each >= 0"),
    Field("json", "bool", False, doc="print JSON"),
    Field("plot", "string", doc="PNG path: every model vs the Monte Carlo reference (log axes)"),
    dataclasses.replace(
        WALK_FIELDS["photons"], name="mc_photons", default=200_000, doc="Monte Carlo photons per channel for --plot"
    ),  # fmt: skip
    dataclasses.replace(WALK_FIELDS["seed"], doc="Monte Carlo random seed for --plot"),
)


def register(sub) -> None:
    from skinlab.scene.optics.profiles import profile_names

    p = sub.add_parser("profile", help="evaluate a diffusion profile R(r) for a medium")
    p.add_argument("model", choices=profile_names() + ["all"], help="profile model ('all': every model)")
    src = p.add_mutually_exclusive_group()
    add_command_options(src, SOURCE_OPTIONS)
    src.add_argument("--albedo", action=refused_option(ALBEDO), help=argparse.SUPPRESS)
    add_command_options(p, PROFILE_OPTIONS)
    p.set_defaults(func=run)


def medium_from_args(args):
    from skinlab.scene.optics.media import Medium, preset

    if args.surface_albedo is not None:
        if (args.mfp is None) == (args.radius is None):
            raise ValueError("mfp: --surface-albedo needs exactly one of --mfp or --radius (mm)")
        eta = 1.3 if args.eta is None else args.eta
        A = list(args.surface_albedo)
        if args.mfp is not None:
            return Medium.from_surface_albedo(A, list(args.mfp), eta, args.albedo_method, "custom")
        return Medium.from_artist_radius(A, list(args.radius), eta, args.albedo_method, "custom")
    if args.mfp is not None or args.radius is not None:
        raise ValueError("albedo: --mfp/--radius need --surface-albedo R,G,B")
    m = preset(args.preset or "skin1")
    if args.eta is not None:
        from skinlab.scene.optics.media import Medium as M

        m = M(m.alpha, m.mfp_mm, args.eta, m.name)
    return m


def run(args) -> int:
    from skinlab.scene.optics.profiles import PROFILE_MODELS, evaluate_profile, profile_names, total_reflectance

    check_command_options(args, SOURCE_OPTIONS + PROFILE_OPTIONS)
    m = medium_from_args(args)
    r = _radii(args.r)
    names = profile_names() if args.model == "all" else [args.model]
    models = {}
    for n in names:
        models[n] = {"R": evaluate_profile(n, r, m).tolist(), "total": total_reflectance(n, m).tolist()}
    medium = {
        "name": m.name,
        "alpha": list(m.alpha),
        "mfp_mm": list(m.mfp_mm),
        "eta": m.eta,
        "sigma_s_per_mm": m.sigma_s.tolist(),
        "sigma_a_per_mm": m.sigma_a.tolist(),
        "surface_albedo": m.surface_albedo().tolist(),
    }
    if args.plot:
        from skinlab.image_output import check_output_path

        if not args.plot.lower().endswith(".png"):
            raise ValueError(f"--plot: expected a .png path, got {args.plot!r}")
        check_output_path(args.plot, "--plot")
        plot_models(m, args.plot, args.mc_photons, args.seed)
    notes = {n: PROFILE_MODELS[n].note for n in names if PROFILE_MODELS[n].note}
    if args.json:
        out = {"medium": medium, "r_mm": r.tolist(), "units": "R in 1/mm^2 per unit entering flux"}
        if len(names) == 1:
            out.update(model=names[0], **models[names[0]])
        else:
            out["models"] = models
        if args.plot:
            out["plot"] = args.plot
        nulls: list[str] = []
        out = strict_json(out, "", nulls)
        if nulls:  # JSON has no Infinity or NaN: such numbers are null, and this says where and why
            notes["null"] = (
                f"{', '.join(nulls)}: not finite (a mean free path of 0 mm gives infinite coefficients), "
                "written as null"
            )
        if notes:
            out["notes"] = notes
        print(json.dumps(out, allow_nan=False))
    else:
        print(
            f"medium {m.name or '(custom)'}: alpha' = {np.round(m.alpha, 5).tolist()}, "
            f"mfp = {np.round(m.mfp_mm, 5).tolist()} mm, eta = {m.eta}"
        )
        for n in names:
            print(f"\n{n}: total reflectance R,G,B = {np.round(models[n]['total'], 5).tolist()}")
            if n in notes:
                print(f"  note: {notes[n]}")
            print(f"{'r (mm)':>10} {'R':>12} {'G':>12} {'B':>12}   (1/mm^2)")
            for ri, row in zip(r, models[n]["R"]):
                print(f"{ri:10.4g} " + " ".join(f"{v:12.5g}" for v in row))
        if args.plot:
            print(f"\nwrote {args.plot}")
    return 0


def strict_json(value, where: str, nulls: list[str]):
    """``value`` with every non-finite float replaced by None; the dotted paths replaced go to ``nulls``
    (a list with any bad element is named once)."""
    if isinstance(value, dict):
        return {k: strict_json(v, f"{where}.{k}" if where else k, nulls) for k, v in value.items()}
    if isinstance(value, list | tuple):
        inner: list[str] = []
        out = [strict_json(v, where, inner) for v in value]
        if inner:
            nulls.append(where)
        return out
    if isinstance(value, float) and not np.isfinite(value):
        nulls.append(where)
        return None
    return value


def plot_models(m, path, photons, seed=0):
    """All models against the Monte Carlo reference, one panel per channel, log-log axes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skinlab.scene.optics.montecarlo import simulate
    from skinlab.scene.optics.profiles import evaluate_profile, profile_names

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=False)
    for c, (ax, chan) in enumerate(zip(axes, "RGB")):
        l = m.mfp_mm[c]
        if l <= 0 or m.alpha[c] <= 0:
            ax.set_title(f"{chan}: no scattering")
            continue
        res = simulate(m.alpha[c], m.eta, 0.0, "normal", photons, seed + c, progress=True, workers=2)
        edges, R, se = res.scaled(l)
        rm = res.r_mid * l
        ok = R > 0
        ax.errorbar(rm[ok], R[ok], yerr=se[ok], fmt="k.", ms=3, lw=0.6, label=f"Monte Carlo ({photons:.0e})")
        r = np.geomspace(edges[1], edges[-1], 300)
        for n in profile_names():
            if n == "none":
                continue
            ax.plot(r, evaluate_profile(n, r, m)[:, c], lw=1.2, label=n)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(max(R[ok].min() * 0.3, 1e-12), R[ok].max() * 5)
        ax.set_xlabel("r (mm)")
        ax.set_ylabel("R(r) (1/mm^2)")
        ax.set_title(f"{m.name or 'custom'} {chan}: alpha'={m.alpha[c]:.4g}, l={l:.3g} mm, eta={m.eta}")
        ax.grid(True, which="both", alpha=0.25)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=Path(path).suffix.lstrip(".") or "png")
    plt.close(fig)
