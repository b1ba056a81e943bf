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

from .ledger_analysis import usable


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


def pareto_plot(
    rows: list[dict], fronts: dict, path: Path, key: str = "image_rel_l1", label: str = "image rel-L1"
) -> Path:
    plt = _plt()
    scenes = list(dict.fromkeys(r["scene"] for r in rows)) or ["(none)"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(6.4 * len(scenes), 4.8), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        pts = [r for r in rows if r["scene"] == scene and usable(r, key)]
        floor = _floor(pts, key)
        for t in techniques():  # each technique's marker and colour from its LedgerStyle
            sel = [r for r in pts if r["technique"] == t.name]
            if not sel:
                continue
            ax.scatter(
                [r["frame_ms_median"] for r in sel],
                [max(r[key], floor) for r in sel],
                marker=t.ledger.marker,
                c=t.ledger.colour,
                s=70 if t.ledger.marker == "*" else 40,
                label=t.name,
                edgecolors="none",
                zorder=3,
            )
        fr = fronts.get(scene, [])
        if fr:
            x = [r["frame_ms_median"] for r in fr]
            y = [max(r[key], floor) for r in fr]
            ax.step(x, y, where="post", color="grey", lw=1, ls="--", zorder=2, label="Pareto front")
            ax.scatter(x, y, s=140, facecolors="none", edgecolors="grey", zorder=4)
            for r, xi, yi in zip(fr, x, y):
                text = r["setting"] + (" (reference: 0)" if r[key] == 0 else "")
                ax.annotate(text, (xi, yi), textcoords="offset points", xytext=(5, 4), fontsize=7)
        bad = [r for r in rows if r["scene"] == scene and not usable(r, key)]
        if bad:
            ax.text(
                0.01,
                0.01,
                "not plotted: " + ", ".join(f"{r['setting']} ({r['status']})" for r in bad),
                transform=ax.transAxes,
                fontsize=6,
                va="bottom",
                wrap=True,
            )
        ax.set_xscale("log")
        ax.margins(x=0.25)
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        if pts and any(r[key] > 0 for r in pts):
            ax.set_yscale("log")
        if key == "image_rel_l1":
            ref = next((r["reference"] for r in rows if r["scene"] == scene and r.get("reference")), "")
            ax.set_title(f"{scene}: error vs time (reference: {ref or 'none'})", fontsize=9)
            ax.set_ylabel(f"{label} (the reference drawn at {floor:g})")
        else:
            noise = next((r.get("truth_noise_block") for r in pts if r.get("truth_noise_block") is not None), None)
            if noise is not None and np.isfinite(noise):
                ax.axhline(noise, color="grey", lw=0.8, ls=":", label="truth noise floor (4x4)")
            ax.set_title(f"{scene}: error against the path-traced truth vs time", fontsize=9)
            ax.set_ylabel(label)
        ax.set_xlabel("median frame time (ms)")
        ax.grid(True, which="both", alpha=0.3)
        if pts:
            ax.legend(fontsize=7, loc="upper right")
    return _save(fig, Path(path))


def cost_plot(series: dict, slopes: dict, path: Path) -> Path:
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12.8, 4.8))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (scene, s) in enumerate(series.items()):
        col = colours[i % len(colours)]
        sl = slopes.get(scene, {})
        for ax, key, xs, xkey in (
            (a1, "texels", [r["tsd_size"] ** 2 for r in s["size"]], "size"),
            (a2, "K", [r["K"] for r in s["K"]], "K"),
        ):
            rs = s[xkey]
            for ykey, ls, mk, what in (
                ("frame_ms_median", "-", "o", "frame"),
                ("tsd_ms_median", ":", "s", "tsd passes"),
            ):
                ys = [r[ykey] for r in rs]
                b, a, n = sl.get(f"{'frame' if ykey == 'frame_ms_median' else 'tsd'}_vs_{key}", (math.nan,) * 3)
                lab = f"{scene} {what}" + ("" if math.isnan(b) else f" (slope {b:.2f})")
                ax.plot(xs, ys, mk, color=col, label=lab, mfc="none" if ykey == "tsd_ms_median" else col)
                if not math.isnan(b) and len(xs) >= 2:
                    xf = np.geomspace(min(xs), max(xs), 20)
                    ax.plot(xf, np.exp(a) * xf**b, ls, color=col, lw=1)
    for ax, xl, title in (
        (a1, "irradiance texels (tsd_size^2)", "cost vs irradiance texels (K = max, auto taps)"),
        (a2, "K (Gaussians fitted)", "cost vs K (auto taps)"),
    ):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_xlabel(xl)
        ax.set_ylabel("median ms")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    ks = sorted({r["K"] for s in series.values() for r in s["K"]})
    if ks:
        a2.set_xticks(ks)
        a2.set_xticklabels([str(k) for k in ks])
    if not series:
        a1.text(0.5, 0.5, "no tsd series measured", transform=a1.transAxes, ha="center")
    return _save(fig, Path(path))
