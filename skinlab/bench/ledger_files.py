"""Writing a ledger run's files (each atomically): ledger.csv, ledger.md, ledger.json, pareto.png and
cost.png."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from skinlab.atomic_write import write_text_atomic

from .ledger_analysis import ERROR_LABELS, TRUTH_KEY, cost_series, error_key, pareto_front, recommendations, slopes
from .ledger_csv import csv_text
from .ledger_markdown import markdown


def write_ledger(rows: list[dict], meta: dict, out: Path) -> dict:
    from skinlab.bench.ledger_plots import cost_plot, pareto_plot

    out = Path(out)
    key = error_key(rows)
    fronts = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        fronts[scene] = pareto_front([r for r in rows if r["scene"] == scene], key)
    k_sizes = [r["tsd_size"] for r in rows if r["technique"] == "tsd"]
    # the K sweep's size: the size with the most distinct K
    k_size = None
    if k_sizes:
        counts = {}
        for r in rows:
            if r["technique"] == "tsd" and r["taps"] == "auto":
                counts.setdefault(r["tsd_size"], set()).add(r["K"])
        k_size = max(counts, key=lambda s: (len(counts[s]), s)) if counts else None
    series = cost_series(rows, {"k_size": k_size})
    sl = slopes(series)
    recs = recommendations(rows, key=key)
    write_text_atomic(out / "ledger.csv", csv_text(rows))
    pareto_plot(rows, fronts, out / "pareto.png", key=key, label=ERROR_LABELS[key])
    cost_plot(series, sl, out / "cost.png")
    md = markdown(rows, meta, sl, recs, fronts)
    write_text_atomic(out / "ledger.md", md)

    def clean(v):
        if isinstance(v, (np.floating, float)):
            return None if math.isnan(float(v)) else float(v)
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
            "best_tsd": r["best_tsd"][1] if r["best_tsd"] else None,
        }
        for r in recs
    ]
    doc = {
        "meta": meta,
        "rows": rows,
        "slopes": {s: {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()} for s, d in sl.items()},
        "pareto": {s: [r["setting"] for r in f] for s, f in fronts.items()},
        "recommendations": rec_json,
        "error_axis": key,
    }
    write_text_atomic(out / "ledger.json", json.dumps(clean(doc), indent=1))
    names = ["ledger.csv", "ledger.md", "ledger.json", "pareto.png", "cost.png"]
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
