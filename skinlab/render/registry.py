"""The subsurface techniques the renderer knows, by name.

A technique is one package under skinlab/render/techniques/ that exposes ``TECHNIQUE`` (a
:class:`skinlab.render.technique.Technique`). The built-in packages are listed in ``BUILTIN_PACKAGES``
(in the order `skinlab render --technique` and the viewer's T key go through them) and imported on
the first look-up, like the CLI's COMMAND_MODULES; :func:`register` adds one more (a plug-in, or a
test's tiny technique). The core (planning, renderer, forward pass, CLI, viewer, ledger) loops over
this registry and never names a technique.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .technique import Technique

BUILTIN_PACKAGES = (
    "skinlab.render.techniques.tsd",
    "skinlab.render.techniques.exact",
    "skinlab.render.techniques.ssss",
    "skinlab.render.techniques.tint",
    "skinlab.render.techniques.none",
    "skinlab.render.techniques.disk",
    "skinlab.render.techniques.preintegrated",
)
DEFAULT_TECHNIQUE = "tsd"

_registry: dict[str, Technique] = {}
_loaded = False


def _load_builtins() -> None:
    global _loaded
    if _loaded:
        return
    _loaded = True
    try:
        for name in BUILTIN_PACKAGES:
            t = importlib.import_module(name).TECHNIQUE
            if t.name not in _registry:
                register(t)
    except BaseException:
        _loaded = False  # the next look-up tries again (and reports the same error)
        raise


def register(technique: Technique) -> Technique:
    """Add a technique; its name and pass kinds must not clash with those registered."""
    _load_builtins()
    if not technique.name or not technique.name.replace("_", "").isalnum():
        raise ValueError(f"technique name {technique.name!r}: expected letters, digits and _")
    if technique.name in _registry:
        raise ValueError(f"technique {technique.name!r} is already registered")
    if technique.settings_type.technique != technique.name:
        raise ValueError(
            f"technique {technique.name!r}: its settings class {technique.settings_type.__name__} says "
            f"technique = {technique.settings_type.technique!r}"
        )
    for other in _registry.values():
        for kind, cls in technique.passes.items():
            if other.passes.get(kind, cls) is not cls:
                raise ValueError(f"technique {technique.name!r}: pass kind {kind!r} is already {other.name!r}'s")
    _registry[technique.name] = technique
    return technique


def unregister(name: str) -> None:
    _registry.pop(name, None)


def techniques() -> list[Technique]:
    _load_builtins()
    return list(_registry.values())


def technique_names() -> list[str]:
    return [t.name for t in techniques()]


def get_technique(name: str) -> Technique:
    _load_builtins()
    t = _registry.get(name)
    if t is None:
        raise ValueError(f"render setting technique: expected one of {', '.join(_registry)}, got {name!r}")
    return t


def pass_class(kind: str):
    """The pass class registered for a pass kind (by any technique), or None."""
    for t in techniques():
        if kind in t.passes:
            return t.passes[kind]
    return None
