"""The ledger's rows as CSV (ledger.csv) and back: one column per LedgerRow column
(skinlab/bench/ledger_row.py), each cell written so that reading it gives the value back."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

from .ledger_row import NUMERIC_COLUMNS, Column, LedgerRow, columns, row_columns

__all__ = ["NUMERIC_COLUMNS", "csv_columns", "csv_text", "fmt_cell", "parse_csv", "read_csv"]

REQUIRED = ("scene", "setting", "technique", "status")  # a file without these is not a ledger


def csv_columns(*rows: LedgerRow) -> list[str]:
    """The CSV's header: every LedgerRow column, the settings parameters one column each (LedgerStyle.columns
    of every registered technique, then any other the rows carry)."""
    return [c.name for c in columns(*rows)]


def fmt_cell(v, digits=4) -> str:
    """A value for a table: "" where there is none, nan, floats to `digits` significant digits."""
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.{digits}g}"
    return str(v)


def _number(v: float) -> str:
    return "nan" if math.isnan(v) else repr(float(v))


def _cell(c: Column, v) -> str:
    if c.kind == "float":
        return _number(v)
    if c.kind == "int":
        return ("nan" if c.numeric else "") if v is None else str(v)
    if c.kind == "bool":
        return "yes" if v else ""
    if c.kind == "ms_by_pass":
        return ";".join(f"{k}={_number(x)}" for k, x in v.items())
    if c.kind == "values_by_error":
        return ";".join(f"{k}=" + " ".join(_number(x) for x in xs) for k, xs in v.items())
    if c.kind == "params":
        return "" if v in ("", None) else str(v)
    return str(v)


def csv_text(rows: list[LedgerRow]) -> str:
    buf = io.StringIO()
    cols = columns(*rows)
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([c.name for c in cols])
    for r in rows:
        w.writerow([_cell(c, r.param(c.name) if c.kind == "params" else getattr(r, c.name)) for c in cols])
    return buf.getvalue()


def _param_value(text: str):
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def _parse(c: Column, text: str):
    if c.kind == "float":
        return float(text) if text else math.nan
    if c.kind == "int":
        if text in ("", "nan"):
            return None
        try:
            return int(text)
        except ValueError:
            return int(float(text))  # an older ledger wrote some counts as floats
    if c.kind == "bool":
        if text not in ("", "yes"):
            raise ValueError(f"expected yes or empty, got {text!r}")
        return text == "yes"
    if c.kind == "ms_by_pass":
        return {k: float(v) for k, v in (p.split("=", 1) for p in text.split(";") if p)}
    if c.kind == "values_by_error":
        return {k: [float(x) for x in v.split()] for k, v in (p.split("=", 1) for p in text.split(";") if p)}
    return text


def parse_csv(text: str, source: str = "ledger.csv") -> list[LedgerRow]:
    """The rows of a ledger.csv's text. Columns the file lacks (an older ledger's) take their defaults; a
    column that is not a LedgerRow field is a settings parameter. ValueError, one line naming `source`,
    the row and the column, for a cell that does not parse or a file that is not a ledger."""
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    missing = [c for c in REQUIRED if c not in (header or [])]
    if missing:
        raise ValueError(
            f"{source}: not a ledger (no {', '.join(missing)} column); expected `skinlab bench accuracy`'s ledger.csv"
        )
    assert header is not None
    declared = {c.name: c for c in row_columns() if c.kind != "params"}
    rows = []
    for i, cells in enumerate(reader, start=2):
        if len(cells) != len(header):
            raise ValueError(f"{source}: line {i} has {len(cells)} cells, the header {len(header)}")
        values: dict = {"params": []}
        for name, text in zip(header, cells):
            c = declared.get(name)
            try:
                if c is None:
                    if text:
                        values["params"].append((name, _param_value(text)))
                else:
                    values[name] = _parse(c, text)
            except ValueError as exc:
                raise ValueError(f"{source}: line {i}, column {name}: {exc}") from None
        rows.append(LedgerRow(**values))
    return rows


def read_csv(path: str | Path) -> list[LedgerRow]:
    """The rows of a ledger.csv (see parse_csv)."""
    return parse_csv(Path(path).read_text(encoding="utf-8"), str(path))
