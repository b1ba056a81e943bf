"""ledger.html: the ledger as one self-contained page (every figure inlined as a PNG data URI): per scene
what it tests and its truth, the Pareto front, a table of at most ten columns, the error and FLIP maps
of one setting per technique, the close-up measures it declares, the profiles across a declared line or
edge; the recommendations and the cost slopes. ledger.md keeps the full tables."""

from __future__ import annotations

import base64
import html
import math
from pathlib import Path

from .ledger_analysis import ERROR_LABELS, TRUTH_KEY, error_key
from .ledger_row import Column, LedgerRow, columns, finite
from .truth_ledger import closeup_notes, closeup_tables

CSS = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
table { border-collapse: collapse; margin: 0.6em 0 1.4em; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 2px 7px; text-align: right; }
th { background: #f2f2f2; } td:first-child, th:first-child { text-align: left; }
tr.best td { background: #e6f4e6; } tr.tie td { background: #f4f9e6; } tr.same td { color: #999; }
img.fig { max-width: 100%; } .maps { display: flex; flex-wrap: wrap; gap: 10px; }
.maps figure { margin: 0; text-align: center; font-size: 11px; }
.maps img { width: 160px; image-rendering: pixelated; } .note { color: #555; }
"""


def _uri(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def _img(path: Path, cls: str = "fig", alt: str = "") -> str:
    if not Path(path).is_file():
        return ""
    return f'<img class="{cls}" src="{_uri(path)}" alt="{html.escape(alt)}">'


def _pm(r: LedgerRow, key: str, pct: bool = True) -> str:
    v, s = r.get(key), r.get(f"{key}_sigma")
    if not finite(v):
        return ""
    if pct:
        return f"{100 * v:.2f}" + (f" &plusmn; {100 * s:.2f}" if finite(s) else "") + " %"
    return f"{v:.4f}" + (f" &plusmn; {s:.4f}" if finite(s) else "")


def _table(head: list[str], rows: list[list[str]], classes: list[str] | None = None) -> str:
    out = ["<table><tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr>"]
    for i, r in enumerate(rows):
        cls = f' class="{classes[i]}"' if classes and classes[i] else ""
        out.append(f"<tr{cls}>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>")
    return "\n".join(out) + "</table>"


RANKS = {"best": "best", "tie": "tie (within noise)"}


def table_cell(r: LedgerRow, c: Column) -> str:
    """How ledger.html's per-scene table shows column `c` of row `r` (its declared ``show``; the setting
    with its status where it is not ok)."""
    esc = html.escape
    v = r.param(c.name) if c.kind == "params" else getattr(r, c.name)
    if c.name == "setting":
        return esc(r.setting) + ("" if r.status == "ok" else f" ({esc(r.status)})")
    if c.show == "num":
        return f"{v:.1f}" if finite(v) else ""
    if c.show in ("pm", "pm_plain", "pct", "profile"):
        return _pm(r, c.name, pct=c.show != "pm_plain")
    if c.show == "rank":
        return RANKS.get(v, "")
    return esc(str(v))


def scene_table(srows: list[LedgerRow]) -> str:
    """One scene's table: the columns that declare an HTML header (at most ten), a row per setting."""
    cols = [c for c in columns(*srows) if c.html]
    body = [[table_cell(r, c) for c in cols] for r in srows]
    return _table([c.html for c in cols], body, ["same" if r.same_image_as else r.ties_best for r in srows])


def column_table(rows: list[LedgerRow]) -> str:
    """Every column of ledger.csv with its unit and what it holds (the LedgerRow declaration)."""
    esc = html.escape
    return _table(["column", "unit", "holds"], [[f"<code>{esc(c.name)}</code>", esc(c.unit), esc(c.doc)]
                                                for c in columns(*rows)])  # fmt: skip


def conditions(meta: dict, key: str) -> list[str]:
    """The title, how the run was measured, which scenes lack their truth."""
    esc = html.escape
    P = [f"<h1>Accuracy/time ledger ({esc(meta['sweep'])} sweep)</h1>"]
    P.append(
        f"<p class='note'>GL: {esc(str(meta['gl']))}; {meta['cpus']} CPU(s); {esc(meta['date'])}; image "
        f"{meta['size'][0]}x{meta['size'][1]}; load average {meta.get('loadavg_start')} &rarr; "
        f"{meta.get('loadavg_end')}; command <code>{esc(meta.get('command') or '')}</code>. Error axis: "
        f"{esc(ERROR_LABELS[key])}. The full tables are in ledger.md.</p>"
    )
    for scene, why in ((meta.get("truth") or {}).get("missing") or {}).items():
        P.append(f"<p><b>{esc(scene)}</b>: {esc(why)}</p>")
    if key != TRUTH_KEY:
        P.append(
            "<p><b>Not measured against the path-traced truth</b> (no cached reference for every scene): the errors "
            "are against the exact convolution.</p>"
        )
    return P


def closeup_section(scene: str, srows: list[LedgerRow], meta: dict) -> list[str]:
    """The close-up measures one scene declares (the tables ledger.md has, truth_ledger.closeup_tables, for
    this scene alone: a column per measure, at most four), and those it could not measure; nothing for a
    scene that declares none."""
    esc = html.escape
    per_scene = (meta.get("truth") or {}).get("scenes") or {}
    P = []
    for (what, how), head, body in closeup_tables(srows, [scene], per_scene, pm="\u00b1"):
        P.append(f"<p><b>{esc(what)}</b>{esc(how)}:</p>")
        P.append(_table([esc(h) for h in head], [[esc(c) for c in b] for b in body]))
    P += [f"<p class='note'>Close-ups not measured: {esc('; '.join(n))}</p>"
          for s, n in closeup_notes(per_scene).items() if s == scene]  # fmt: skip
    return P


def scene_section(scene: str, rows: list[LedgerRow], meta: dict, fronts: dict, key: str, out: Path) -> list[str]:
    """One scene: what it tests and its truth, its Pareto figure, its table, its error and FLIP maps."""
    from .ledger_plots import pareto_plot
    from .sweep import sheet_settings_of_rows

    esc = html.escape
    srows = [r for r in rows if r.scene == scene]
    P = [f"<h2>{esc(scene)}</h2>"]
    d = ((meta.get("truth") or {}).get("scenes") or {}).get(scene)
    if d:
        nb, npx, sec = 100 * (d.get("noise_block") or 0), 100 * (d.get("noise") or 0), d.get("seconds") or 0
        P.append(
            f"<p>{esc(d.get('tests') or '')} Truth: {d.get('spp')} spp in {d.get('passes')} passes "
            f"({sec:.0f} s of path tracing), noise floor {nb:.2f} % on 4x4 blocks, {npx:.2f} % per pixel; edge "
            f"region: {d.get('edge_pixels')} px within {d.get('edge_mm', 0):.1f} mm of the "
            f"{esc(d.get('edge_from') or '')} edges.</p>"
        )
    fig = out / "html" / f"pareto-{scene}.png"
    pareto_plot(srows, {scene: fronts.get(scene, [])}, fig, key=key, label=ERROR_LABELS[key])
    P.append(_img(fig, alt=f"Pareto front of {scene}"))
    P.append(scene_table(srows))
    P += closeup_section(scene, srows, meta)
    figs = []
    for labl in sheet_settings_of_rows(rows).get(scene, []):
        safe = labl.replace(" ", "-")
        em, fm = out / "error_maps" / f"{scene}-{safe}.png", out / "flip_maps" / f"{scene}-{safe}.png"
        if em.is_file():
            figs.append(f"<figure>{_img(em, 'map', labl)}{_img(fm, 'map', labl)}<figcaption>{esc(labl)}"
                        "</figcaption></figure>")  # fmt: skip
    if figs:
        P.append(
            "<p class='note'>Per pixel, at the truth's size: (frame - truth) / truth of luminance (red brighter, "
            "blue darker, full colour at &plusmn;50 %), and the FLIP map (magma, 0 to 1).</p>"
        )
        P.append("<div class='maps'>" + "".join(figs) + "</div>")
    return P


def recommendations_and_slopes(recs: list[dict], sl: list[dict], out: Path) -> list[str]:
    esc = html.escape
    P = ["<h2>Recommended defaults</h2>"]
    dflt = recs[0]["default"] if recs else ""

    def cell(t):
        return ["none qualifies", ""] if t is None else [f"<code>{esc(t[1])}</code>", f"{t[0]:.1f}"]

    rec_rows = [[f"{100 * rec['threshold']:g} %", *cell(rec["best"]), *cell(rec["best_default"])] for rec in recs]
    P.append(_table(["budget", "cheapest setting", "mean ms", f"cheapest {esc(dflt)}", "mean ms"], rec_rows))
    P.append("<h2>Cost slopes</h2>")

    def f(t):
        return "n/a" if math.isnan(t[0]) else f"{t[0]:.3f}"

    slope_rows = [[esc(s["scene"]), f"{esc(s['technique'])} vs {esc(s['what'])}", f(s["frame"]), f(s["own"]),
                   ", ".join(f"{v:g}" for v in s["values"])] for s in sl]  # fmt: skip
    P.append(_table(["scene", "series", "frame", "technique passes", "values"], slope_rows))
    P.append(_img(out / "cost.png", alt="cost"))
    return P


def html_report(rows: list[LedgerRow], meta: dict, sl: list[dict], recs: list[dict], fronts: dict, out: Path) -> str:
    out = Path(out)
    key = error_key(rows)
    esc = html.escape
    P = [f"<!doctype html><html><head><meta charset='utf-8'><title>Accuracy/time ledger ({esc(meta['sweep'])})</title>"
         f"<style>{CSS}</style></head><body>"]  # fmt: skip
    P += conditions(meta, key)
    for scene in dict.fromkeys(r.scene for r in rows):
        P += scene_section(scene, rows, meta, fronts, key, out)
    if (out / "profiles.png").is_file():
        P.append("<h2>Profiles across the declared lines and edges</h2>")
        P.append(_img(out / "profiles.png", alt="profiles"))
    P += recommendations_and_slopes(recs, sl, out)
    P += ["<h2>Columns</h2>", "<p class='note'>The columns of ledger.csv (skinlab/bench/ledger_row.py).</p>",
          column_table(rows)]  # fmt: skip
    P.append("</body></html>")
    return "\n".join(P)
