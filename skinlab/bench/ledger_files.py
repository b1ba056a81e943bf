"""Writing a ledger run's files (each atomically): ledger.csv, ledger.md, ledger.html, ledger.json,
pareto.png, cost.png and (where a scene declares a profile) profiles.png."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from skinlab.atomic_write import write_text_atomic

from .ledger_analysis import (
    ERROR_LABELS,
    TRUTH_KEY,
    cost_series,
    error_key,
    mark_ties,
    pareto_front,
    recommendations,
    slopes,
)
from .ledger_csv import csv_text
from .ledger_markdown import markdown
from .ledger_row import LedgerRow


def write_ledger(rows: list[LedgerRow], meta: dict, out: Path, sweep=None, profiles: dict | None = None) -> dict:
    from skinlab.bench.ledger_html import html_report
    from skinlab.bench.ledger_plots import cost_plot, pareto_plot, profile_plot

    from .sweep import SWEEPS

    sweep = sweep or SWEEPS.get(meta.get("sweep"), SWEEPS["full"])
    out = Path(out)
    key = error_key([r for r in rows if not r.peer])
    rows = mark_ties(rows, key)
    own = [r for r in rows if not r.peer]  # the fronts, ties and defaults are Skinlab's; peers drawn beside
    fronts = {}
    for scene in dict.fromkeys(r.scene for r in own):
        fronts[scene] = pareto_front([r for r in own if r.scene == scene], key)
    series = cost_series(own, sweep)
    sl = slopes(series)
    recs = recommendations(own, key=key)
    write_text_atomic(out / "ledger.csv", csv_text(rows))
    pareto_plot(rows, fronts, out / "pareto.png", key=key, label=ERROR_LABELS[key])
    cost_plot(series, sl, out / "cost.png")
    names = ["ledger.csv", "ledger.md", "ledger.html", "ledger.json", "pareto.png", "cost.png"]
    if profiles:
        profile_plot(profiles, rows, out / "profiles.png")
        names.append("profiles.png")
    md = markdown(rows, meta, sl, recs, fronts)
    write_text_atomic(out / "ledger.md", md)
    write_text_atomic(out / "ledger.html", html_report(rows, meta, sl, recs, fronts, out))

    def clean(v):
        if isinstance(v, (np.floating, float)):
            return None if not math.isfinite(float(v)) else float(v)
        if isinstance(v, (np.integer,)):
            return int(v)
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    rec_json = [
        {
            "threshold": r["threshold"],
            "best": r["best"][1] if r["best"] else None,
            "best_default": r["best_default"][1] if r["best_default"] else None,
            "default": r["default"],
        }
        for r in recs
    ]
    doc = {
        "meta": meta,
        "rows": [r.as_dict() for r in rows],
        "slopes": sl,
        "pareto": {s: [r.setting for r in f] for s, f in fronts.items()},
        "recommendations": rec_json,
        "error_axis": key,
    }
    write_text_atomic(out / "ledger.json", json.dumps(clean(doc), indent=1, allow_nan=False))
    if key == TRUTH_KEY and (out / "error_maps.png").is_file():
        names.append("error_maps.png")
    return {
        "rows": rows,
        "meta": meta,
        "slopes": sl,
        "recommendations": recs,
        "fronts": fronts,
        "error_axis": key,
        "files": [str(out / n) for n in names],
    }
