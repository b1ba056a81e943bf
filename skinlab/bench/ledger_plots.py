"""Figures of the accuracy/time ledger (matplotlib, Agg backend, written atomically):
pareto.png (image error against frame time, one panel per scene) and cost.png (frame time against
irradiance texels and against K, log-log, with the fitted slopes)."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from skinlab.atomic_write import write_bytes_atomic
from skinlab.render.registry import techniques

from .blender_peer import PEER_STYLES
from .ledger_analysis import usable
from .ledger_row import LedgerRow


def _floor(pts, key: str = "image_rel_l1") -> float:
    """Where the reference (error 0) is drawn on the log axis: a decade below the smallest other error."""
    nz = [r[key] for r in pts if r[key] > 0]
    return 10.0 ** (math.floor(math.log10(min(nz))) - 1) if nz else 1e-5


def _figure_bytes(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    return buf.getvalue()


def _save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    data = _figure_bytes(fig)
    plt.close(fig)
    return write_bytes_atomic(path, data)


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


FALLBACK_MARKERS = "osD^vP*Xhp<>"
FALLBACK_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink",
                    "tab:olive", "tab:cyan", "black", "tab:gray")  # fmt: skip


def technique_styles() -> dict[str, tuple[str, str]]:
    """(marker, colour) per registered technique: its LedgerStyle's, or, where an earlier technique
    already has that pair, the first free pair (every technique its own look in the plots)."""
    used, out = set(), {}
    for t in techniques():
        pair = (t.ledger.marker, t.ledger.colour)
        if pair in used:
            pair = next(
                (m, c) for c in FALLBACK_COLOURS for m in FALLBACK_MARKERS if (m, c) not in used and c != pair[1]
            )
        used.add(pair)
        out[t.name] = pair
    return out


def pareto_plot(
    rows: list[LedgerRow], fronts: dict, path: Path, key: str = "image_rel_l1", label: str = "image rel-L1"
) -> Path:
    from .ledger_analysis import sigma

    plt = _plt()
    styles = technique_styles()
    scenes = list(dict.fromkeys(r.scene for r in rows)) or ["(none)"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(6.4 * len(scenes), 4.8), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        pts = [r for r in rows if r.scene == scene and usable(r, key) and not r.same_image_as]
        floor = _floor(pts, key)
        # each technique's marker and colour; the Blender peers' (skinlab/bench/blender_peer.py) from PEER_STYLES
        for name in [*(t.name for t in techniques()), *PEER_STYLES]:
            sel = [r for r in pts if r.technique == name]
            if not sel:
                continue
            marker, colour = styles[name] if name in styles else PEER_STYLES[name]
            x = [r.frame_ms_median for r in sel]
            y = [max(r[key], floor) for r in sel]
            err = [2 * sigma(r, key) for r in sel]  # TIE_SIGMAS standard errors: the noise the ranks allow
            if any(e > 0 for e in err):
                ax.errorbar(x, y, yerr=err, fmt="none", ecolor=colour, elinewidth=0.8, alpha=0.6, zorder=2)
            ax.scatter(
                x, y, marker=marker, c=colour, s=70 if marker == "*" else 40, label=name, edgecolors="none",
                zorder=3,
            )  # fmt: skip
            for r, xi, yi in zip(sel, x, y) if name in PEER_STYLES else ():
                ax.annotate(r.setting, (xi, yi), textcoords="offset points", xytext=(5, -9), fontsize=6, color=colour)
        fr = fronts.get(scene, [])
        if fr:
            x = [r.frame_ms_median for r in fr]
            y = [max(r[key], floor) for r in fr]
            ax.step(x, y, where="post", color="grey", lw=1, ls="--", zorder=2, label="Pareto front (beyond noise)")
            ax.scatter(x, y, s=140, facecolors="none", edgecolors="grey", zorder=4)
            for r, xi, yi in zip(fr, x, y):
                text = r.setting + (" (reference: 0)" if r[key] == 0 else "")
                ax.annotate(text, (xi, yi), textcoords="offset points", xytext=(5, 4), fontsize=7)
        notes = []
        bad = [r for r in rows if r.scene == scene and not usable(r, key)]
        if bad:
            notes.append("not plotted: " + ", ".join(f"{r.setting} ({r.status})" for r in bad))
        same = [r for r in rows if r.scene == scene and r.same_image_as and usable(r, key)]
        if same:
            notes.append("same image as another: " + ", ".join(f"{r.setting} = {r.same_image_as}" for r in same))
        if notes:
            ax.text(0.01, 0.01, "\n".join(notes), transform=ax.transAxes, fontsize=6, va="bottom", wrap=True)
        ax.set_xscale("log")
        ax.margins(x=0.25)
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        if pts and any(r[key] > 0 for r in pts):
            ax.set_yscale("log")
        if key == "image_rel_l1":
            ref = next((r.reference for r in rows if r.scene == scene and r.reference), "")
            ax.set_title(f"{scene}: error vs time (reference: {ref or 'none'})", fontsize=9)
            ax.set_ylabel(f"{label} (the reference drawn at {floor:g})")
        else:
            noise = next((r.truth_noise_block for r in pts if np.isfinite(r.truth_noise_block)), None)
            if noise is not None and np.isfinite(noise):
                ax.axhline(noise, color="grey", lw=0.8, ls=":", label="truth noise floor (4x4)")
            ax.set_title(f"{scene}: error against the path-traced truth vs time (bars: 2 sigma)", fontsize=9)
            ax.set_ylabel(label)
        ax.set_xlabel("median frame time (ms)")
        ax.grid(True, which="both", alpha=0.3)
        if pts:
            ax.legend(fontsize=7, loc="upper right")
    return _save(fig, Path(path))


def cost_plot(series: list[dict], slopes: list[dict], path: Path) -> Path:
    """One panel per (technique, axis) with a cost: frame time and the technique's own passes' time
    against the axis's cost variable, log-log, per scene, with the fitted lines."""
    plt = _plt()
    kinds = list(dict.fromkeys((s["technique"], s["field"], s["what"]) for s in series)) or [("", "", "")]
    fig, axes = plt.subplots(1, len(kinds), figsize=(6.4 * len(kinds), 4.8), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    scenes = list(dict.fromkeys(s["scene"] for s in series))
    for ax, (tech, field, what) in zip(axes[0], kinds):
        for s, sl in zip(series, slopes):
            if (s["technique"], s["field"]) != (tech, field) or not s["points"]:
                continue
            col = colours[scenes.index(s["scene"]) % len(colours)]
            xs = [v ** s["power"] for v, _ in s["points"]]
            for ykey, ls, mk, name, fit in (
                ("frame_ms_median", "-", "o", "frame", sl["frame"]),
                ("technique_ms_median", ":", "s", f"{tech} passes", sl["own"]),
            ):
                ys = [r.get(ykey, math.nan) for _, r in s["points"]]
                b, a, _ = fit
                lab = f"{s['scene']} {name}" + ("" if math.isnan(b) else f" (slope {b:.2f})")
                ax.plot(xs, ys, mk, color=col, label=lab, mfc="none" if ykey != "frame_ms_median" else col)
                if not math.isnan(b) and len(xs) >= 2:
                    xf = np.geomspace(min(xs), max(xs), 20)
                    ax.plot(xf, np.exp(a) * xf**b, ls, color=col, lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_xlabel(f"{what} ({field}{'' if not series else ''})" if what else "")
        ax.set_ylabel("median ms")
        ax.set_title(f"{tech}: cost vs {what} (the other settings at the sweep's base)" if tech else "", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    if not any(s["points"] for s in series):
        axes[0][0].text(0.5, 0.5, "no cost series measured", transform=axes[0][0].transAxes, ha="center")
    return _save(fig, Path(path))


def profile_plot(profiles: dict, rows: list[LedgerRow], path: Path) -> Path:
    """Per scene with a declared line or edge: the luminance profile across it of the truth and of each
    technique's setting (its default where swept, else its first), log axis, normalised to the truth's
    peak."""
    from skinlab.truth.compare import REC709

    from .sweep import Setting

    plt = _plt()
    styles = technique_styles()
    scenes = list(profiles)
    fig, axes = plt.subplots(1, len(scenes), figsize=(6.4 * len(scenes), 4.8), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        p = profiles[scene]
        truth = p["truth"]
        lum = lambda pr: pr.rgb @ REC709
        peak = np.nanmax(lum(truth)) or 1.0
        ax.plot(truth.x_mm, lum(truth) / peak, color="black", lw=2.2, label="path-traced truth", zorder=5)
        by_tech: dict[str, str] = {}
        for r in rows:
            if r.scene != scene or r.setting not in p or r.same_image_as:
                continue
            if r.peer:  # each peer row its own line (skinlab/bench/blender_peer.py)
                by_tech[r.setting] = r.setting
                continue
            default = Setting.of(r.technique).label
            if r.technique not in by_tech or r.setting == default:
                by_tech[r.technique] = r.setting
        peer_tech = {r.setting: r.technique for r in rows if r.peer}
        for tech, labl in by_tech.items():
            marker, colour = styles.get(tech) or PEER_STYLES.get(peer_tech.get(tech), ("o", "grey"))
            pr = p[labl]
            every = max(len(pr.x_mm) // 25, 1)
            ax.plot(pr.x_mm, lum(pr) / peak, color=colour, lw=1, marker=marker, ms=3, markevery=every, label=labl)
        ax.set_yscale("log")
        ax.set_ylim(1e-6, 2.0)
        kind = "line spread" if p.get("kind") == "line" else "edge spread"
        ax.set_title(f"{scene}: {kind} profile (luminance / the truth's peak)", fontsize=9)
        ax.set_xlabel("distance across the declared line or edge (mm)")
        ax.set_ylabel("relative luminance (log)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return _save(fig, Path(path))
