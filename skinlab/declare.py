"""One declaration of a setting: :class:`Field` (name, kind, default, range, unit, one-line meaning).

Material parameters (skinlab/scene/materials.py ``PRINCIPLED_PARAMS``), render and technique settings
(dataclass fields declared with :func:`option`: skinlab/render/settings.py, skinlab/render/options.py),
scene-file keys (skinlab/scene/scene_keys.py ``SCENE_FILE_KEYS``) and the commands' own options
(skinlab/commands/) are all Fields. What follows from one: its validation and error (one line naming
it and what was expected), its command-line option (skinlab/commands/field_options.py), its viewer
widget (skinlab/viewer/panel.py ``WIDGETS``), its uniform (material kinds) and its row in docs/scenes.md.

Kinds: ``int``, ``float``, ``bool``, ``choice`` (one of ``choices``), ``string``, ``color`` / ``vec3``
(3 numbers, or 1 for all), ``vec2``, ``texture`` (a file path; None: no map), and for scene-file keys
whose reading is their own (tables, quaternions): ``table``, ``tables``, ``vec4``, ``scale``.

This module imports nothing of the project: every layer may use it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

NUMERIC_KINDS = ("float", "color", "vec3", "vec2")  # a material's uniforms
VECTOR_SIZES = {"color": 3, "vec3": 3, "vec2": 2}


@dataclass(frozen=True)
class Field:
    """What one setting means and which values it takes."""

    name: str
    kind: str
    default: Any = None
    range: tuple[float, float] | None = None  # inclusive (an end excluded with lo_open, hi_open)
    doc: str = ""
    unit: str = ""
    choices: tuple[str, ...] = ()  # kind "choice"
    odd: bool = False  # ints only: odd values
    none: str = ""  # when not empty, None is allowed and means this (e.g. "from each blur's width")
    lo_open: bool = False  # the range's low end is not a valid value: (lo, hi]
    hi_open: bool = False  # nor its high end: [lo, hi)
    colorspace: str = "linear"  # textures: "srgb" colour data or "linear" data
    flags: tuple[str, ...] = ()  # command-line spellings besides --<name> (kept for compatibility)
    cli: bool = True  # a command-line option of the commands that take it
    panel: bool = True  # a widget in the viewer's panel
    shown: str = ""  # the default in words, where it is computed ("the file's stem") or none is typed
    type_text: str = ""  # the type in words, where a relation bounds it ("number > znear")

    # -- what values it takes -----------------------------------------------------------------------
    @property
    def limits(self) -> tuple[float, float]:
        """The range of a numeric field (declared for every material value)."""
        if self.range is None:
            raise TypeError(f"{self.name}: a {self.kind} has no range")
        return self.range

    def _range_text(self) -> str:
        """`in [lo, hi]`, or `> lo` / `>= lo` for a range without a top ('' for none)."""
        lo, hi = (self._number_text(x) for x in self.limits)
        if self.limits[1] == math.inf:
            return "" if self.limits[0] == -math.inf else f"{'>' if self.lo_open else '>='} {lo}"
        return f"in {'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"

    def _number_text(self, x: float) -> str:
        """A bound as written: an integer's bounds exactly (4294967295, not 4.29497e+09)."""
        if self.kind == "int" and math.isfinite(x) and x == int(x):
            return str(int(x))
        return f"{x:g}"

    def expected(self, with_none: bool = True) -> str:
        """What a valid value is, in words (errors and --help)."""
        if self.kind == "choice":
            what = "one of " + ", ".join(self.choices)
        elif self.kind in VECTOR_SIZES:
            what = f"{VECTOR_SIZES[self.kind]} numbers"
        else:
            what = {
                "int": "an integer",
                "float": "a number",
                "bool": "true or false",
                "string": "a string",
                "texture": "a file path (string)",
            }.get(self.kind, self.kind)
        if self.odd:
            what = "an odd integer"
        if self.range is not None and self.kind not in ("choice", "bool", "string", "texture"):
            what += f" {self._range_text()}".rstrip()
        if self.none and with_none:
            what += f" or None ({self.none})"
        return what

    def _bad(self, label: str, value: Any) -> ValueError:
        return ValueError(f"{label}: expected {self.expected()}, got {value!r}")

    def _in_range(self, arr: np.ndarray) -> bool:
        if not np.isfinite(arr).all():
            return False
        if self.range is None:
            return True
        lo, hi = self.range
        low_ok = (arr > lo) if self.lo_open else (arr >= lo)
        high_ok = (arr < hi) if self.hi_open else (arr <= hi)
        return bool(low_ok.all() and high_ok.all())

    def _numbers(self, value: Any, label: str) -> np.ndarray:
        """A colour/vec3 or vec2 value as an array (a scalar fills every component)."""
        n = VECTOR_SIZES[self.kind]
        try:
            arr = np.asarray(value, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError, OverflowError):  # OverflowError: an int beyond float range
            raise ValueError(f"{label}: expected {n} numbers, got {value!r}") from None
        if arr.size == 1:
            arr = np.repeat(arr, n)
        if arr.size != n:
            what = "(u, v)" if n == 2 else "(R, G, B)"
            raise ValueError(f"{label}: expected {n} numbers {what}, got {arr.size}")
        return arr

    def check(self, value: Any, label: str | None = None) -> Any:
        """The value in canonical form, or ValueError naming `label` (default: the field's name) and
        what was expected."""
        label = self.name if label is None else label
        if value is None and self.none:
            return None
        kind = self.kind
        if kind == "texture":
            if value is None or value == "":
                return None
            if not isinstance(value, str | Path):
                raise self._bad(label, value)
            return Path(value)
        if kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                raise self._bad(label, value)
            return value
        if kind == "bool":
            if not isinstance(value, bool):
                raise self._bad(label, value)
            return value
        if kind == "string":
            if not isinstance(value, str):
                raise self._bad(label, value)
            return value
        if kind in VECTOR_SIZES:
            arr = self._numbers(value, label)
            if not self._in_range(arr):
                raise self._bad(label, value)
            return tuple(float(x) for x in arr)
        if kind not in ("int", "float"):
            raise TypeError(f"{label}: a {kind} is read where it is declared, not by Field.check")
        if isinstance(value, bool):
            raise self._bad(label, value)
        given = value
        if kind == "int":
            if not isinstance(value, int | np.integer) or (self.odd and value % 2 == 0):
                raise self._bad(label, value)
            value = int(value)
        else:
            try:
                value = float(value)
            except (TypeError, ValueError, OverflowError):
                raise self._bad(label, value) from None
        if not self._in_range(np.array([value], np.float64)):
            raise self._bad(label, given)
        return value

    def clamp(self, value: Any) -> Any:
        """A widget's value made valid: numbers clamped into the range (NaN: the default), integers
        rounded (odd counts to the nearest odd one inside the range); None (automatic) where the field
        allows it; malformed values and unknown choices still raise, naming the field."""
        if value is None and self.none:
            return None
        if self.kind in VECTOR_SIZES:
            arr = self._numbers(value, self.name)
            arr = np.where(np.isnan(arr), self._numbers(self.default, self.name), arr)
            return self.check(tuple(np.clip(arr, *self.limits)), self.name)
        if self.kind not in ("int", "float"):
            return self.check(value)
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            raise self._bad(self.name, value) from None
        if v != v:  # NaN
            v = float(self.default)
        if self.range is not None:
            v = min(max(v, self.range[0]), self.range[1])
        if self.kind == "float":
            return v
        n = int(round(v))
        if self.odd and n % 2 == 0:
            n = n + 1 if self.range is None or n + 1 <= self.range[1] else n - 1
        return n

    # -- how it is shown ----------------------------------------------------------------------------
    def default_text(self) -> str:
        """The default as docs and --help show it: `shown` where it is computed, else the typed value."""
        if self.shown:
            return self.shown
        d = self.default
        if d is None:
            return self.none or "none"
        if isinstance(d, bool):
            return str(d).lower()
        if isinstance(d, tuple | list):
            return "[" + ", ".join(f"{x:g}" for x in d) + "]"
        if isinstance(d, str):
            return f'"{d}"'
        return f"{d:g}"

    def help(self, default: Any = dataclasses.MISSING) -> str:
        """One line for --help and the viewer's tooltips: meaning, values, default with its unit."""
        default = self.default if default is dataclasses.MISSING else default
        unit = f" {self.unit}" if self.unit else ""
        shown = (self.none or "none") if default is None else f"{default}{unit}"
        values = "" if self.kind in ("bool", "choice", "string", "texture") else f"; {self.expected(with_none=False)}"
        return f"{self.doc}{values} (default: {shown})"

    # -- what the renderer derives from a material value ------------------------------------------------
    @property
    def uniform(self) -> str:
        return f"u_{self.name}"

    @property
    def define(self) -> str:
        return f"HAS_{self.name.upper()}"


def option(default: Any, doc: str, kind: str, **kw: Any) -> Any:
    """A dataclass field declared by a :class:`Field` (its metadata; the name is the field's)."""
    return dataclasses.field(default=default, metadata={"declared": Field("", kind, default, doc=doc, **kw)})


_DECLARED: dict[type, dict[str, Field]] = {}  # per dataclass, made once


def declared_fields(cls: type) -> dict[str, Field]:
    """The fields of a dataclass declared with :func:`option`, by name, in order (made once per class;
    the dict is shared: do not change it)."""
    if cls not in _DECLARED:
        _DECLARED[cls] = {
            f.name: dataclasses.replace(f.metadata["declared"], name=f.name)
            for f in dataclasses.fields(cls)
            if "declared" in f.metadata
        }
    return _DECLARED[cls]
