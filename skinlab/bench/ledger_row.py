"""One row of the accuracy ledger, :class:`LedgerRow`, with every column declared once: its name (the
field's), type, unit, what it holds and how the tables show it (``column(...)``). ledger.csv's header
and cells (skinlab/bench/ledger_csv.py), ledger.md's per-scene table and column list, ledger.html's
per-scene table and column list, ledger.json's rows, the analysis (skinlab/bench/ledger_analysis.py)
and the plots read the columns from here.

A row is immutable: the run loop builds it and changes it with ``dataclasses.replace`` (``row.but(...)``).
Its settings parameters (``params``) are one column each per parameter a registered technique shows
(``LedgerStyle.columns``; ``setting_columns``), empty where they do not apply.
``row[name]`` reads a column by name (the error axis is a name: ``row[key]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from functools import cache
from typing import Any

# how a table cell shows a column (skinlab/bench/ledger_markdown.py, ledger_html.py)
SHOWS = ("text", "num", "pct", "pm", "pm_plain", "profile", "status", "rank", "params")
KINDS = ("str", "int", "float", "bool", "params", "ms_by_pass", "values_by_error")


def column(default: Any, kind: str, unit: str, doc: str, *, md: str = "", html: str = "", show: str = "text",
           numeric: bool | None = None) -> Any:  # fmt: skip
    """A ledger column: `kind` (one of KINDS: how its cells are written and read back), `unit` ("" for
    none), `doc` (one sentence: what it holds), `md` / `html`: its header in ledger.md's / ledger.html's
    per-scene table ("": not in it), `show`: how those tables show it (SHOWS). `numeric`: its CSV cell is
    always a number (``nan`` where not measured; default: the float columns)."""
    assert kind in KINDS and show in SHOWS, (kind, show)
    meta = {"kind": kind, "unit": unit, "doc": doc, "md": md, "html": html, "show": show,
            "numeric": kind == "float" if numeric is None else numeric}  # fmt: skip
    if isinstance(default, (dict, list)):
        return field(default_factory=type(default), metadata=meta)
    return field(default=default, metadata=meta)


NAN = math.nan


@dataclass(frozen=True)
class LedgerRow:
    """One (scene, setting) of the ledger: what it is, what its frames cost, how far they are from the
    image reference, the Monte Carlo and model profiles and the path-traced truth."""

    scene: str = column("", "str", "", "the scene (its file's stem)")
    setting: str = column("", "str", "", "the setting's label (its technique's LedgerStyle.label)", md="setting",
                          html="setting")  # fmt: skip
    technique: str = column("", "str", "", "the registered technique (or a peer renderer)", md="technique")
    model: str = column("", "str", "", "the profile model of the scattering material as the frame rendered it "
                        "(none: no light moves)", md="model")  # fmt: skip
    params: tuple[tuple[str, Any], ...] = column(
        (), "params", "", "the settings parameter (LedgerStyle.columns); empty where it does not apply; auto: "
        "chosen by the renderer", show="params",
    )  # fmt: skip
    width: int | None = column(None, "int", "px", "width of the timed frames")
    height: int | None = column(None, "int", "px", "height of the timed frames")
    blur_levels: int | None = column(None, "int", "", "passes of the kind the technique's LedgerStyle.levels "
                                     "names (0 where none)", md="blur levels", show="num")  # fmt: skip
    frames: int | None = column(None, "int", "", "timed frames", md="frames", show="num", numeric=True)
    frame_ms_median: float = column(NAN, "float", "ms", "median frame time (the sum of the per-pass times)",
                                    md="frame ms median", html="ms", show="num")  # fmt: skip
    frame_ms_p10: float = column(NAN, "float", "ms", "10th percentile of the frame time", md="p10", show="num")
    frame_ms_p90: float = column(NAN, "float", "ms", "90th percentile of the frame time", md="p90", show="num")
    wall_ms_median: float = column(NAN, "float", "ms", "median wall time of the whole render call")
    technique_ms_median: float = column(NAN, "float", "ms", "median time of the technique's own passes",
                                        md="technique ms", show="num")  # fmt: skip
    clock: str = column("", "str", "", "how passes were timed: gpu-timer or cpu-synchronised (glFinish)")
    image_rel_l1: float = column(NAN, "float", "fraction", "relative L1 against the image reference over lit pixels",
                                 md="image rel-L1", show="pct")  # fmt: skip
    image_max_rel: float = column(NAN, "float", "fraction", "largest per-pixel relative error against the image "
                                  "reference", md="image max", show="pct")  # fmt: skip
    image_p95_rel: float = column(NAN, "float", "fraction", "95th percentile of the per-pixel relative error",
                                  md="image p95", show="pct")  # fmt: skip
    pixels: int | None = column(None, "int", "px", "lit pixels compared with the image reference", numeric=True)
    image_rel_l1_same_size: float = column(NAN, "float", "fraction", "relative L1 against the image reference at the "
                                           "same shared settings (an irradiance size)",
                                           md="rel-L1 vs exact same size", show="pct")  # fmt: skip
    profile_err_mc: float = column(NAN, "float", "fraction", "edge-response error against the Monte Carlo random walk "
                                   "(a step: 1)", md="profile err vs MC", show="profile")  # fmt: skip
    profile_err_model: float = column(NAN, "float", "fraction", "edge-response error against the material's own model "
                                      "profile", md="profile err vs model", show="profile")  # fmt: skip
    reference: str = column("", "str", "", "the setting the image errors are measured against")
    truth_rel_l1_block: float = column(NAN, "float", "fraction", "relative L1 against the path-traced truth on 4x4 "
                                       "blocks (the first error axis)", md="truth 4x4", html="truth 4x4",
                                       show="pm")  # fmt: skip
    truth_rel_l1_block_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_rel_l1: float = column(NAN, "float", "fraction", "relative L1 against the truth per pixel", md="truth px",
                                 html="truth px", show="pm")  # fmt: skip
    truth_rel_l1_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_flip: float = column(NAN, "float", "FLIP, 0-1", "mean FLIP of the tone-mapped frames against the truth's",
                               md="truth FLIP", html="FLIP", show="pm_plain")  # fmt: skip
    truth_flip_sigma: float = column(NAN, "float", "FLIP, 0-1", "its standard error (jackknife)")
    truth_edge_rel_l1: float = column(NAN, "float", "fraction", "relative L1 per pixel within the edge region",
                                      md="truth edge px", html="edge px", show="pm")  # fmt: skip
    truth_edge_rel_l1_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_edge_pixels: int | None = column(None, "int", "px", "pixels in the edge region", numeric=True)
    truth_profile_err: float = column(NAN, "float", "fraction", "relative L1 of the profile across the declared line "
                                      "or edge against the truth's", html="profile", show="pm")  # fmt: skip
    truth_profile_err_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    # the close-up measures a scene's [measure] declares (skinlab/bench/closeup.py), frame minus truth
    truth_tail_2mm: float = column(NAN, "float", "fraction", "share of the light (luminance) in view farther than 2 mm "
                                   "from the declared line, frame minus truth (a line profile)")  # fmt: skip
    truth_tail_2mm_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_5mm: float = column(NAN, "float", "fraction", "the same beyond 5 mm")
    truth_tail_5mm_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_10mm: float = column(NAN, "float", "fraction", "the same beyond 10 mm")
    truth_tail_10mm_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_2mm_r: float = column(NAN, "float", "fraction", "share of the red channel's own light in view "
                                     "farther than 2 mm from the declared line, frame minus truth (a line "
                                     "profile; skin's red diffuses farthest)")  # fmt: skip
    truth_tail_2mm_r_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_2mm_g: float = column(NAN, "float", "fraction", "the same of the green channel beyond 2 mm")
    truth_tail_2mm_g_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_2mm_b: float = column(NAN, "float", "fraction", "the same of the blue channel beyond 2 mm")
    truth_tail_2mm_b_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_5mm_r: float = column(NAN, "float", "fraction", "the same of the red channel beyond 5 mm")
    truth_tail_5mm_r_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_5mm_g: float = column(NAN, "float", "fraction", "the same of the green channel beyond 5 mm")
    truth_tail_5mm_g_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_5mm_b: float = column(NAN, "float", "fraction", "the same of the blue channel beyond 5 mm")
    truth_tail_5mm_b_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_10mm_r: float = column(NAN, "float", "fraction", "the same of the red channel beyond 10 mm")
    truth_tail_10mm_r_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_10mm_g: float = column(NAN, "float", "fraction", "the same of the green channel beyond 10 mm")
    truth_tail_10mm_g_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_tail_10mm_b: float = column(NAN, "float", "fraction", "the same of the blue channel beyond 10 mm")
    truth_tail_10mm_b_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_deep_shadow: float = column(NAN, "float", "fraction", "the deep shadow's mean luminance as a share of "
                                      "the lit surface's (ray-cast regions), frame minus truth "
                                      "(deep_shadow = true)")  # fmt: skip
    truth_deep_shadow_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_mesh_energy: float = column(NAN, "float", "fraction", "the largest relative difference of one "
                                      "visible mesh's per-channel sum against the truth's, "
                                      "its magnitude (mesh_energy = true)")  # fmt: skip
    truth_mesh_energy_sigma: float = column(NAN, "float", "fraction", "its standard error (jackknife)")
    truth_mesh_energy_each: str = column("", "str", "", "each visible mesh's per-channel energy difference (R/G/B)")
    truth_noise: float = column(NAN, "float", "fraction", "the truth's own noise floor per pixel (between the halves "
                                "of its passes)")  # fmt: skip
    truth_noise_block: float = column(NAN, "float", "fraction", "the truth's own noise floor on 4x4 blocks",
                                      md="truth noise 4x4", show="pct")  # fmt: skip
    truth_energy: float = column(NAN, "float", "fraction", "largest per-channel relative difference of the sums over "
                                 "the object", md="truth energy", show="pct")  # fmt: skip
    truth_energy_r: float = column(NAN, "float", "fraction", "relative difference of the red sum over the object")
    truth_energy_g: float = column(NAN, "float", "fraction", "relative difference of the green sum over the object")
    truth_energy_b: float = column(NAN, "float", "fraction", "relative difference of the blue sum over the object")
    truth_spp: int | None = column(None, "int", "", "samples per pixel of the truth", numeric=True)
    truth_passes: int | None = column(None, "int", "", "passes of the truth", numeric=True)
    truth_blocks8_over: int | None = column(None, "int", "", "8x8 blocks more than 15 % off the truth, of those "
                                            "judged", numeric=True)  # fmt: skip
    truth_blocks8_judged: int | None = column(None, "int", "", "8x8 blocks the truth's noise allows to judge",
                                              numeric=True)  # fmt: skip
    truth_blocks8_over_frac: float = column(NAN, "float", "fraction", "truth_blocks8_over / truth_blocks8_judged")
    peer: bool = column(False, "bool", "", "a peer renderer's row (Blender), drawn beside, never ranked")
    samples: int | None = column(None, "int", "", "a peer's samples per pixel", numeric=True)
    first_frame_ms: float = column(NAN, "float", "ms", "a peer's first render of the scene (compiles, BVH)")
    truth_frame_ms: float = column(NAN, "float", "ms", "a peer's render of the frame compared with the truth")
    peer_noise: float = column(NAN, "float", "fraction", "a peer frame's own noise per pixel (two seeds)")
    peer_noise_block: float = column(NAN, "float", "fraction", "a peer frame's own noise on 4x4 blocks")
    ties_best: str = column("", "str", "", "best: the scene's smallest error; tie: the truth's noise cannot "
                            "tell it from the best", html="rank", show="rank")  # fmt: skip
    same_image_as: str = column("", "str", "", "an earlier setting whose compared frame is bit-identical",
                                md="same image as", html="same image as")  # fmt: skip
    status: str = column("ok", "str", "", "ok, error (the message in error) or ignored", md="status",
                         show="status")  # fmt: skip
    error: str = column("", "str", "", "why the setting failed (its first line)")
    passes_ms: dict[str, float] = column({}, "ms_by_pass", "ms", "median time per pass (name=ms; ...)")
    jackknife: dict[str, list[float]] = column({}, "values_by_error", "", "each truth error's values with one "
                                               "group of the truth's passes left out (name=v v ...; ...)")  # fmt: skip

    def __post_init__(self):
        # plain Python numbers (one nan), so that equal measurements are equal rows
        for c in row_columns():
            v = getattr(self, c.name)
            if c.kind == "float":
                v = _float(v)
            elif c.kind == "int" and v is not None:
                v = int(v)
            elif c.kind == "ms_by_pass":
                v = {str(k): _float(x) for k, x in v.items()}
            elif c.kind == "values_by_error":
                v = {str(k): [_float(x) for x in xs] for k, xs in v.items()}
            elif c.kind == "params":
                v = tuple((str(k), x) for k, x in (v.items() if isinstance(v, dict) else v) if x != "")
            object.__setattr__(self, c.name, v)

    def param(self, name: str):
        """A settings parameter column's value, "" where it does not apply."""
        return dict(self.params).get(name, "")

    def __getitem__(self, name: str):
        """A column by name: a field, or a settings parameter column."""
        if name in _FIELD_NAMES and name != "params":
            return getattr(self, name)
        if name in setting_columns() or name in dict(self.params):
            return self.param(name)
        raise KeyError(f"ledger rows have no column {name!r}")

    def get(self, name: str, default=None):
        try:
            return self[name]
        except KeyError:
            return default

    def but(self, **changes) -> LedgerRow:
        """The row with `changes` (column names; ``replace``)."""
        return replace(self, **changes)

    def as_dict(self) -> dict:
        """Column name -> value (every settings parameter column, "" where it does not apply), as
        ledger.json holds it."""
        out: dict = {}
        for c in row_columns():
            if c.kind == "params":
                out.update({p: self.param(p) for p in param_columns(self)})
            else:
                out[c.name] = getattr(self, c.name)
        return out


def finite(v) -> bool:
    """A measured number (not nan, not inf, not empty)."""
    return isinstance(v, (int, float)) and math.isfinite(v)


def _float(v) -> float:
    if v is None or v == "":
        return NAN
    v = float(v)
    return NAN if v != v else v


@dataclass(frozen=True)
class Column:
    """One declared column (the metadata of a LedgerRow field, or one settings parameter column)."""

    name: str
    kind: str
    unit: str
    doc: str
    md: str = ""
    html: str = ""
    show: str = "text"
    numeric: bool = False


_FIELD_NAMES = frozenset(f.name for f in fields(LedgerRow))


@cache
def row_columns() -> tuple[Column, ...]:
    """The LedgerRow fields as columns, in order (``params`` stands for the settings parameter columns)."""
    return tuple(Column(f.name, **f.metadata) for f in fields(LedgerRow))


def setting_columns() -> list[str]:
    """The ledger's parameter columns: every registered technique's LedgerStyle.columns, in registry order."""
    from skinlab.render.registry import techniques

    return list(dict.fromkeys(c for t in techniques() for c in t.ledger.columns))


def param_columns(*rows: LedgerRow) -> list[str]:
    """The settings parameter columns: every registered technique's, then any other the rows carry."""
    return list(dict.fromkeys([*setting_columns(), *(k for r in rows for k, _ in r.params)]))


def columns(*rows: LedgerRow) -> list[Column]:
    """Every column in the CSV's order: the fields, ``params`` expanded into one column per settings
    parameter (setting_columns), each with its technique's field's doc."""
    proto = next(c for c in row_columns() if c.kind == "params")
    docs = _param_docs()
    out = []
    for c in row_columns():
        if c.kind != "params":
            out.append(c)
            continue
        for p in param_columns(*rows):
            out.append(Column(p, "params", "", f"{docs.get(p, 'a settings parameter')}: {proto.doc}", md=p,
                              show="params"))  # fmt: skip
    return out


def _param_docs() -> dict[str, str]:
    """Per settings parameter column: which technique's which settings field it shows."""
    from skinlab.render.registry import techniques

    out: dict[str, list[str]] = {}
    for t in techniques():
        for col, fld in t.ledger.columns.items():
            out.setdefault(col, []).append(f"{t.name} `{fld}`")
    return {c: ", ".join(v) for c, v in out.items()}


NUMERIC_COLUMNS = [c.name for c in row_columns() if c.numeric]
