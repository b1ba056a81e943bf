"""A technique's settings: a small frozen dataclass whose fields are declared with
:func:`skinlab.declare.option` (a :class:`skinlab.declare.Field`: default, range, unit, one-line meaning).
Validation, the `skinlab render` options and the viewer's panel widgets all come from that declaration."""

from __future__ import annotations

import dataclasses
import importlib
from dataclasses import dataclass
from typing import Any, ClassVar

from skinlab.declare import Field, declared_fields

from .techniques import BUILTIN_PACKAGES


@dataclass(frozen=True)
class TechniqueSettings:
    """Base of every technique's settings. Subclasses set ``technique`` (the registered name) and
    declare their fields with :func:`skinlab.declare.option`; values are checked on construction."""

    technique: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for name, opt in self.options().items():
            object.__setattr__(self, name, opt.check(getattr(self, name), f"{self.technique} setting {name}"))

    @classmethod
    def options(cls) -> dict[str, Field]:
        return declared_fields(cls)

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        return {name: f.default for name, f in declared_fields(cls).items()}

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
