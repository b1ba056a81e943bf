"""The ledger as Markdown (ledger.md): the measurement conditions, the tables against the truth, one table
per scene (its columns from the LedgerRow declaration, skinlab/bench/ledger_row.py), the Pareto fronts,
the cost slopes, the peers, the recommended defaults and the columns with their units."""

from __future__ import annotations

import math

from .blender_peer import blender_markdown
from .image_error import LUM_FRACTION
from .ledger_analysis import ERROR_LABELS, TRUTH_KEY, error_key
from .ledger_csv import fmt_cell
from .ledger_row import Column, LedgerRow, columns
from .truth_ledger import truth_markdown


def pm(r: LedgerRow, key: str, percent: bool = True) -> str:
    """'value +- sigma' (percent or as is), '' where not measured."""
    v, s = r.get(key), r.get(f"{key}_sigma")
    if not isinstance(v, (int, float)) or not math.isfinite(v):
        return ""
    k = 100 if percent else 1
    unit = " %" if percent else ""
    if isinstance(s, (int, float)) and math.isfinite(s):
        return f"{k * v:.2f} +- {k * s:.2f}{unit}" if percent else f"{v:.4f} +- {s:.4f}"
    return f"{k * v:.2f}{unit}" if percent else f"{v:.4f}"


def profile_cell(r: LedgerRow, key: str) -> str:
    """A profile error; n/a where the technique moves no light (a step: exactly 100 %, says nothing)."""
    v = r.get(key)
    if not isinstance(v, (int, float)) or not math.isfinite(v):
        return ""
    if r.technique and r.model == "none" or abs(v - 1.0) < 1e-12:
        return "n/a (no profile)"
    return f"{100 * v:.2f} %"


def _pct(v) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{100 * v:.2f} %"


def table_cell(r: LedgerRow, c: Column) -> str:
    """How ledger.md's per-scene table shows column `c` of row `r` (its declared ``show``)."""
    v = r.param(c.name) if c.kind == "params" else getattr(r, c.name)
    if c.show == "num":
        return "" if isinstance(v, float) and math.isnan(v) else fmt_cell(v, 4)
    if c.show == "pct":
        return _pct(v)
    if c.show in ("pm", "pm_plain"):
        return pm(r, c.name, percent=c.show == "pm")
    if c.show == "profile":
        return profile_cell(r, c.name)
    if c.show == "status":
        return (r.status + (f": {r.error}" if r.error else "")).replace("|", "/")
    if c.show == "params":
        return fmt_cell(v)
    return str(v)


def scene_table(srows: list[LedgerRow]) -> list[str]:
    """One scene's table: a row per setting, the columns that declare a Markdown header, in order."""
    cols = [c for c in columns(*srows) if c.md]
    L = ["| " + " | ".join(c.md for c in cols) + " |", "|---" * len(cols) + "|"]
    L += ["| " + " | ".join(table_cell(r, c) for c in cols) + " |" for r in srows]
    return L


def column_lines(rows: list[LedgerRow]) -> list[str]:
    """Every column of ledger.csv with its unit and what it holds (the LedgerRow declaration)."""
    L = ["## Columns", "", "The columns of ledger.csv (and ledger.json's rows; skinlab/bench/ledger_row.py):", "",
         "| column | unit | holds |", "|---|---|---|"]  # fmt: skip
    L += [f"| `{c.name}` | {c.unit} | {c.doc} |" for c in columns(*rows)]
    return [*L, ""]


def conditions_lines(rows: list[LedgerRow], meta: dict) -> list[str]:
    """The title and how the run was measured: GL, image and shadow sizes, frames, clock, time, load."""
    L = [f"# Accuracy/time ledger ({meta['sweep']} sweep)", ""]
    L.append(f"- GL: {meta['gl']}; {meta['cpus']} CPU(s); {meta['date']}")
    L.append(
        f"- image {meta['size'][0]}x{meta['size'][1]}, shadow maps {meta['shadow_size']}; "
        f"{meta['warmup']} warm-up frames, then the median (p10/p90) of up to {meta['frames']} frames "
        f"of `render(readback=False)` per setting (fewer, at least 3, where they would take over "
        f"{meta['budget_s']:g} s); Monte Carlo {meta['photons']:,} photons per channel"
    )
    clocks = sorted({r.clock for r in rows if r.clock})
    L.append(
        f"- clock: {', '.join(clocks) or 'n/a'} (cpu-synchronised: wall time with glFinish after each "
        "pass, Mesa llvmpipe's GPU timer queries see only command submission; gpu-timer: GL timer queries)"
    )
    L.append(f"- sweep took {meta['sweep_s']:.1f} s, the whole run (with the pyrender peer) {meta['total_s']:.1f} s")
    if meta.get("loadavg_start") is not None:
        L.append(
            f"- load average (1/5/15 min) at the start {meta['loadavg_start']}, at the end "
            f"{meta.get('loadavg_end')}: other processes on the machine share its cores and lengthen frames"
        )
    if meta.get("command"):
        L.append(f"- command: `{meta['command']}`")
    return L


MEASURES = [
    "image error: against the scene's reference image (the `reference` column) on linear HDR over "
    f"lit surface pixels (coverage > 0, luminance > {LUM_FRACTION:.0%} of the 99th percentile); "
    "rel-L1 = sum|img - ref| / sum ref; max/p95: per-pixel sum_c|img - ref| / sum_c ref. "
    "`rel-L1 vs exact same size`: a tsd setting against the exact convolution at its own irradiance "
    "size (the fit/blur error without the texture-resolution error). "
    "profile error: relative L1 of the edge response against the Monte Carlo random walk, "
    "int|E - E_mc| dx / int|step - E_mc| dx (no scattering = 1); `vs model`: the same against the "
    "material's own model profile (the technique's approximation alone).",
    "`truth 4x4` / `truth px`: relative L1 against the path-traced truth on 4x4 blocks / per pixel, "
    "`truth FLIP`: the mean FLIP of the tone-mapped frames, `truth edge px`: relative L1 per pixel within "
    "the edge region, each +- its standard error from the truth's passes (jackknife); the truth's noise "
    "floor (4x4) and the largest per-channel energy difference beside them. `n/a (no profile)`: the "
    "technique moves no light, its profile is a step.",
]


def reference_lines(srows: list[LedgerRow]) -> list[str]:
    """What one scene's image errors are measured against (the exact convolution, a proxy, nothing), and
    which settings are compared with a coarser image than their own."""
    ref = next((r.reference for r in srows if r.reference), "")
    if not ref:
        L = ["**No reference image**: neither the exact convolution nor a tsd proxy rendered; image errors are empty."]
    elif not ref.startswith("exact"):
        L = [
            f"**Proxy reference**: the exact technique did not render (see its row), so `{ref}` "
            "stands in as the image reference; image errors are relative to it, not to the exact "
            "profile."
        ]
    else:
        L = [f"Reference image: `{ref}`."]
    ref_size = next((r.param("tsd_size") for r in srows if r.setting == ref), None)
    finer = [r.setting for r in srows if ref_size and r.param("tsd_size") != "" and r.param("tsd_size") > ref_size]
    if finer:
        L.append(
            f"Settings with a finer irradiance texture than the reference's {ref_size} texels "
            f"({', '.join(finer)}) are compared with a coarser image: their error includes the "
            "reference's own texture-resolution error (compare the exact rows at smaller sizes)."
        )
    return L


def ranking_lines(srows: list[LedgerRow], front: list[LedgerRow], key: str) -> list[str]:
    """Below one scene's table: its Pareto front, its same-image rows, its best and the ties with it."""
    L = []
    if front:
        L += [
            f"Pareto front (time, {ERROR_LABELS[key]}): "
            + " -> ".join(f"`{r.setting}` ({r.frame_ms_median:.1f} ms, {100 * r[key]:.2f} %)" for r in front)
            + " (each point more accurate than the cheaper ones by more than twice the noise of the difference)",
            "",
        ]
    same = [r for r in srows if r.same_image_as]
    if same:
        L += [
            "Same image (bit-identical frames, one point in the Pareto front and the ranks): "
            + "; ".join(f"`{r.setting}` = `{r.same_image_as}`" for r in same),
            "",
        ]
    best = next((r for r in srows if r.ties_best == "best"), None)
    if best is not None and key == TRUTH_KEY:
        ties = [r.setting for r in srows if r.ties_best == "tie"]
        L += [
            f"Best against the truth: `{best.setting}`; "
            + (
                f"the truth's noise cannot tell it from {', '.join(f'`{t}`' for t in ties)}."
                if ties
                else "every other setting is worse by more than the noise."
            ),
            "",
        ]
    return L


def scene_lines(scene: str, rows: list[LedgerRow], fronts: dict) -> list[str]:
    """One scene's section: its reference, its table, its ranks."""
    srows = [r for r in rows if r.scene == scene]
    return [f"## {scene}", "", *reference_lines(srows), "", *scene_table(srows), "",
            *ranking_lines(srows, fronts.get(scene, []), error_key(rows))]  # fmt: skip


def cost_slope_lines(sl: list[dict]) -> list[str]:
    """The cost slopes along every axis a technique declares a cost for."""
    L = [
        "## Cost slopes",
        "",
        "Least-squares slopes of log(time) against log(the cost variable) along each axis a technique declares a "
        "cost for (LedgerStyle.cost_axes; the other settings at the sweep's base, e.g. texture-space diffusion's "
        "texels = size^2 and K), for the whole frame and for the technique's own passes; where the technique "
        "declares blur levels, only the points whose frame blurs at all (a frame that blurs nothing is plain "
        "diffuse: a step, not a power law). Slope 1 = linear.",
        "",
        "| scene | series | frame vs it | technique passes vs it | values | blur levels |",
        "|---|---|---|---|---|---|",
    ]

    def f(t):
        return "n/a" if math.isnan(t[0]) else f"{t[0]:.3f}"

    for s in sl:
        power = "" if s["power"] == 1 else f" = {s['field']}^{s['power']:g}"
        L.append(
            f"| {s['scene']} | {s['technique']} vs {s['what']}{power} | {f(s['frame'])} | {f(s['own'])} | "
            f"{', '.join(f'{v:g}' for v in s['values'])} | {', '.join(map(str, s['levels']))} |"
        )
    if not sl:
        L.append("| (no cost series measured) | | | | | |")
    return [*L, ""]


def pyrender_lines(meta: dict) -> list[str]:
    """The pyrender peer's frame times beside Skinlab's (or why it was not run)."""
    L = ["## Peer: pyrender", ""]
    p = meta.get("peer")
    if p is None:
        L.append("Not run (--no-peer).")
    elif "error" in p:
        L.append(f"The pyrender peer failed: {p['error']}")
    else:
        L += [
            f"`skinlab bench peer --size {p['size'][0]}x{p['size'][1]} --frames {p['frames']}` "
            f"({p['gl']}): the head, shadows off, colour+depth read back on both sides, median of "
            f"{p['frames']} whole frames (no glFinish between passes); pyrender's frame is plain PBR, "
            "Skinlab's plain-PBR frame has sss_model none, its default frame the default "
            "RenderSettings (texture-space diffusion on the skin).",
            "",
            "| renderer | ms/frame | / pyrender |",
            "|---|---|---|",
            f"| skinlab, plain PBR | {p['skinlab_ms']:.2f} | {p['ratio_skinlab_over_pyrender']:.2f} |",
        ]
        if p.get("skinlab_default_ms") is not None:
            L.append(
                f"| skinlab, default settings (tsd) | {p['skinlab_default_ms']:.2f} | "
                f"{p['ratio_default_over_pyrender']:.2f} |"
            )
        L.append(f"| pyrender | {p['pyrender_ms']:.2f} | 1 |")
    return [*L, ""]


def recommendation_lines(rows: list[LedgerRow], recs: list[dict]) -> list[str]:
    """The rule and, per error budget, the cheapest setting overall and of the default technique."""
    key = recs[0]["key"] if recs else "image_rel_l1"
    dflt = recs[0]["default"] if recs else "the default technique"
    rule = (
        "whose error against the path-traced truth (4x4 blocks) is within tau of the scene's best setting in "
        "*every* scene (every technique keeps the error they share, so the budget counts from the best), "
        "unless it is above that by more than twice the standard error of its difference from the best (the "
        "truth's noise): only differences larger than the noise count"
        if key == TRUTH_KEY
        else "whose image rel-L1 against the reference is <= tau in *every* scene; the reference itself "
        "qualifies trivially"
    )
    L = [
        "## Recommended defaults",
        "",
        f"Rule: for each error budget tau, the cheapest setting (mean over the scenes of its median frame time) "
        f"{rule}. `{dflt} only` restricts this to the default technique's settings that blur in every scene (what "
        "its defaults choose among; one that blurs nothing renders the plain frame). A setting must have been "
        "measured in every scene.",
        "",
        "| budget tau | cheapest setting | mean ms | errors per scene "
        f"| cheapest {dflt} setting | mean ms | errors per scene |",
        "|---|---|---|---|---|---|---|",
    ]

    def cell(t):
        if t is None:
            return ["none qualifies", "", ""]
        cost, labl, per = t
        return [f"`{labl}`", f"{cost:.1f}", ", ".join(f"{s} {100 * r[key]:.2f} %" for s, r in per.items())]

    for rec in recs:
        L.append(
            f"| {100 * rec['threshold']:g} % | " + " | ".join(cell(rec["best"]) + cell(rec["best_default"])) + " |"
        )
    if any(r.reference and not r.reference.startswith("exact") for r in rows):
        L += [
            "",
            "These recommendations are relative to a proxy reference (see above), not to the exact "
            "convolution: re-run once the exact technique renders.",
        ]
    return [*L, ""]


def markdown(rows: list[LedgerRow], meta: dict, sl: list[dict], recs: list[dict], fronts: dict) -> str:
    L = [*conditions_lines(rows, meta), "", *MEASURES, "", *truth_markdown(rows, meta)]
    for scene in dict.fromkeys(r.scene for r in rows):
        L += scene_lines(scene, rows, fronts)
    L += cost_slope_lines(sl)
    L += pyrender_lines(meta)
    L += blender_markdown(rows, meta)
    L += recommendation_lines(rows, recs)
    L += column_lines(rows)
    return "\n".join(L)
