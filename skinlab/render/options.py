"""A technique's settings: a small frozen dataclass whose fields are declared with :func:`option`
(default, range, unit, one-line meaning). Validation, the `skinlab render` options and the viewer's
panel widgets all come from that declaration."""

from __future__ import annotations

import dataclasses
import importlib
from dataclasses import dataclass, field
from typing import Any, ClassVar

from .techniques import BUILTIN_PACKAGES


@dataclass(frozen=True)
class Option:
    """What a settings field means and which values it takes."""

    doc: str
    kind: str  # int | float | bool | choice
    range: tuple[float, float] | None = None  # inclusive
    odd: bool = False  # ints only: odd values
    none: str = ""  # when not empty, None is allowed and means this (e.g. "from each blur's width")
    unit: str = ""
    flags: tuple[str, ...] = ()  # extra command-line spellings kept for compatibility
    choices: tuple[
        str, ...
    ] = ()  # kind "choice": the values it takes (the first is not the default unless so declared)

    def expected(self, with_none: bool = True) -> str:
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        what = {"int": "an integer", "float": "a number", "bool": "true or false"}[self.kind]
        if self.odd:
            what = "an odd integer"
        if self.range is not None:
            what += f" in [{self.range[0]:g}, {self.range[1]:g}]"
        if self.none and with_none:
            what += f" or None ({self.none})"
        return what

    def check(self, value: Any, label: str) -> Any:
        """The value in canonical form, or ValueError naming `label` and what was expected."""
        if value is None and self.none:
            return None
        bad = ValueError(f"{label}: expected {self.expected()}, got {value!r}")
        if self.kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                raise bad
            return value
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise bad
            return value
        if isinstance(value, bool):
            raise bad
        if self.kind == "int":
            if not isinstance(value, int) or (self.odd and value % 2 == 0):
                raise bad
        else:
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise bad from None
            if value != value:  # NaN
                raise bad
        if self.range is not None and not self.range[0] <= value <= self.range[1]:
            raise bad
        return value

    def help(self, default: Any) -> str:
        """One line for --help and the viewer's tooltips: meaning, values, default."""
        unit = f" {self.unit}" if self.unit else ""
        shown = self.none if default is None else f"{default}{unit}"
        values = "" if self.kind in ("bool", "choice") else f"; {self.expected(with_none=False)}"
        return f"{self.doc}{values} (default: {shown})"


def option(default: Any, doc: str, kind: str, **kw) -> Any:
    """A settings field with its :class:`Option` (dataclasses.field metadata)."""
    return field(default=default, metadata={"option": Option(doc, kind, **kw)})


@dataclass(frozen=True)
class TechniqueSettings:
    """Base of every technique's settings. Subclasses set ``technique`` (the registered name) and
    declare their fields with :func:`option`; values are checked on construction."""

    technique: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for name, opt in self.options().items():
            object.__setattr__(self, name, opt.check(getattr(self, name), f"{self.technique} setting {name}"))

    @classmethod
    def options(cls) -> dict[str, Option]:
        return {f.name: f.metadata["option"] for f in dataclasses.fields(cls) if "option" in f.metadata}

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        return {f.name: f.default for f in dataclasses.fields(cls) if "option" in f.metadata}

    def replace(self, **changes) -> TechniqueSettings:
        """A copy with some values changed (checked again)."""
        return dataclasses.replace(self, **changes)

    def values(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.options()}


# the settings classes of the techniques registered beyond the built-in ones (skinlab/render/registry.py
# `register` adds them): a name resolves without importing the registry, which sits above the settings
_REGISTERED: dict[str, type[TechniqueSettings]] = {}


def add_settings_type(cls: type[TechniqueSettings]) -> None:
    _REGISTERED[cls.technique] = cls


def drop_settings_type(name: str) -> None:
    _REGISTERED.pop(name, None)


def technique_names() -> list[str]:
    """The technique names a setting may take: the built-in ones, then those registered."""
    return [*BUILTIN_PACKAGES, *(n for n in _REGISTERED if n not in BUILTIN_PACKAGES)]


def technique_settings(name: str) -> type[TechniqueSettings]:
    """The settings class of technique `name`; a built-in one imports its own package only."""
    cls = _REGISTERED.get(name)
    if cls is None and name in BUILTIN_PACKAGES:
        cls = importlib.import_module(BUILTIN_PACKAGES[name]).TECHNIQUE.settings_type
    if cls is None:
        raise ValueError(f"render setting technique: expected one of {', '.join(technique_names())}, got {name!r}")
    return cls
