"""The subsurface techniques the renderer knows, by name.

A technique is one package under skinlab/render/techniques/ that exposes ``TECHNIQUE`` (a
:class:`skinlab.render.technique.Technique`). The built-in packages are listed in
``skinlab.render.techniques.BUILTIN_PACKAGES`` (in the order `skinlab render --technique` and the viewer's
T key go through them); a look-up by name imports that package alone, a listing imports them all, like
the CLI's COMMAND_MODULES. :func:`register` adds one more (a plug-in, or a test's tiny technique). The
core (planning, renderer, forward pass, CLI, viewer, ledger) loops over this registry and never names a
technique.
"""

from __future__ import annotations

import importlib

from .options import add_settings_type, drop_settings_type
from .technique import RenderPass, Technique
from .techniques import BUILTIN_PACKAGES, DEFAULT_TECHNIQUE

__all__ = ["BUILTIN_PACKAGES", "DEFAULT_TECHNIQUE", "register", "unregister", "techniques", "get_technique"]

_builtin: dict[str, Technique] = {}  # the built-in packages imported so far
_added: dict[str, Technique] = {}  # registered beyond them


def _load_builtin(name: str) -> Technique:
    t = _builtin.get(name)
    if t is None:
        t = importlib.import_module(BUILTIN_PACKAGES[name]).TECHNIQUE
        if t.name != name:
            raise ValueError(f"package {BUILTIN_PACKAGES[name]}: its TECHNIQUE is named {t.name!r}, not {name!r}")
        _builtin[name] = t
    return t


def register(technique: Technique) -> Technique:
    """Add a technique; its name and pass kinds must not clash with those registered."""
    if not technique.name or not technique.name.replace("_", "").isalnum():
        raise ValueError(f"technique name {technique.name!r}: expected letters, digits and _")
    if technique.name in BUILTIN_PACKAGES or technique.name in _added:
        raise ValueError(f"technique {technique.name!r} is already registered")
    if technique.settings_type.technique != technique.name:
        raise ValueError(
            f"technique {technique.name!r}: its settings class {technique.settings_type.__name__} says "
            f"technique = {technique.settings_type.technique!r}"
        )
    for other in techniques():
        for kind, cls in technique.passes.items():
            if other.passes.get(kind, cls) is not cls:
                raise ValueError(f"technique {technique.name!r}: pass kind {kind!r} is already {other.name!r}'s")
    _added[technique.name] = technique
    add_settings_type(technique.settings_type)
    return technique


def unregister(name: str) -> None:
    if _added.pop(name, None) is not None:
        drop_settings_type(name)


def techniques() -> list[Technique]:
    """Every technique: the built-in ones in their order, then those registered."""
    return [*(_load_builtin(n) for n in BUILTIN_PACKAGES), *_added.values()]


def technique_names() -> list[str]:
    return [*BUILTIN_PACKAGES, *_added]


def get_technique(name: str) -> Technique:
    if name in _added:
        return _added[name]
    if name in BUILTIN_PACKAGES:
        return _load_builtin(name)
    raise ValueError(f"render setting technique: expected one of {', '.join(technique_names())}, got {name!r}")


def pass_class(kind: str) -> type[RenderPass] | None:
    """The pass class registered for a pass kind (by any technique), or None."""
    for t in [*_builtin.values(), *_added.values()]:  # those imported first
        if kind in t.passes:
            return t.passes[kind]
    for t in techniques():
        if kind in t.passes:
            return t.passes[kind]
    return None
