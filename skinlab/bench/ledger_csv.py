"""The ledger's rows as CSV: the columns (one per setting parameter, timing and error) and cell formats."""

from __future__ import annotations

import csv
import io
import math

from .blender_peer import PEER_COLUMNS
from .truth_ledger import TRUTH_COLUMNS


def csv_columns() -> list[str]:
    """The CSV's columns: the setting's, one per parameter column a registered technique declares
    (LedgerStyle.columns), the timings and the errors."""
    from .sweep import setting_columns

    return [
        "scene",
        "setting",
        "technique",
        "model",
        *setting_columns(),
        "width",
        "height",
        "blur_levels",
        "frames",
        "frame_ms_median",
        "frame_ms_p10",
        "frame_ms_p90",
        "wall_ms_median",
        "technique_ms_median",
        "clock",
        "image_rel_l1",
        "image_max_rel",
        "image_p95_rel",
        "pixels",
        "image_rel_l1_same_size",
        "profile_err_mc",
        "profile_err_model",
        "reference",
        *TRUTH_COLUMNS,
        *PEER_COLUMNS,
        "same_image_as",
        "ties_best",
        "status",
        "error",
        "passes_ms",
    ]


NUMERIC_COLUMNS = [
    "frames",
    "frame_ms_median",
    "frame_ms_p10",
    "frame_ms_p90",
    "wall_ms_median",
    "technique_ms_median",
    "image_rel_l1",
    "image_max_rel",
    "image_p95_rel",
    "pixels",
    "image_rel_l1_same_size",
    "profile_err_mc",
    "profile_err_model",
    *TRUTH_COLUMNS,
    *PEER_COLUMNS,
]


def fmt_cell(v, digits=4) -> str:
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.{digits}g}"
    return str(v)


def csv_text(rows: list[dict]) -> str:
    buf = io.StringIO()
    columns = csv_columns()
    w = csv.DictWriter(buf, columns, lineterminator="\n")
    w.writeheader()
    for r in rows:
        cells = {}
        for c in columns:
            if c == "passes_ms":
                cells[c] = ";".join(f"{k}={v:.3f}" for k, v in (r.get("passes") or {}).items())
            elif c in NUMERIC_COLUMNS:
                v = r.get(c, math.nan)
                cells[c] = (
                    "nan"
                    if v in (None, "") or (isinstance(v, float) and math.isnan(v))
                    else (str(v) if isinstance(v, int) else f"{float(v):.6g}")
                )
            else:
                cells[c] = fmt_cell(r.get(c, ""), 6)
        w.writerow(cells)
    return buf.getvalue()
