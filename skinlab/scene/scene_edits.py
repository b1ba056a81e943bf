"""Edits to a scene before it is built, from the command line (``skinlab render MESH --preset marble
--set roughness=0.3 --set environment.exposure=2 --mm-per-unit 45``) or the API
(``skinlab.load(path, preset=..., mm_per_unit=..., set={...})``).

Every edit is applied to the scene file's TOML data (a mesh file opened directly becomes the data a
scene file with only its ``[[meshes]] file`` would have), so the scene file's own validation checks it
and its errors name the key. ``--set KEY=VALUE``:

- ``KEY`` a material parameter (``roughness``, ``subsurface_color``, an alias such as
  ``subsurface_weight``, or ``preset``): on every mesh, on top of its material (the ``overrides`` of each
  ``[[meshes]]`` entry and node);
- ``materials.NAME.PARAM``: one ``[materials.NAME]`` table;
- ``scene.KEY``, ``environment.KEY``, ``camera.KEY``: those tables' keys;
- ``lights.NAME.KEY``, ``meshes.NAME.KEY``: the light or ``[[meshes]]`` entry of that name.

``VALUE`` is read as a TOML value (``0.3``, ``[0.2, 0.8, 0.2]``, ``true``, ``"dipole"``); a bare word is
a string and a comma list an array (``0.2,0.8,0.2``). ``--preset`` is ``--set preset=NAME``, applied
before the other material values.
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass, field
from typing import Any

from .materials import PARAM_ALIASES, PRINCIPLED_PARAMS

MATERIAL_KEYS = frozenset({p.name for p in PRINCIPLED_PARAMS} | set(PARAM_ALIASES) | {"preset", "openpbr"})
TABLES = ("scene", "environment", "camera")
NAMED = ("lights", "meshes", "materials")


class SceneEditError(ValueError):
    pass


@dataclass
class SceneEdits:
    preset: str | None = None
    mm_per_unit: float | None = None
    sets: list[tuple[str, Any]] = field(default_factory=list)  # (key, value), in order

    def __bool__(self) -> bool:
        return self.preset is not None or self.mm_per_unit is not None or bool(self.sets)


def make_edits(preset_name=None, mm_per_unit=None, sets=(), option: str = "") -> SceneEdits | None:
    """Checked SceneEdits (None if empty): a preset that exists, mm_per_unit > 0, each set a
    ``KEY=VALUE`` string or a (key, value) pair. Errors name the option (``option="--"``: the command
    line's spelling)."""
    if mm_per_unit is not None:  # checked as the [scene] key it sets
        from .scene_keys import scene_key

        label = f"{option}mm-per-unit" if option else "mm_per_unit"
        try:
            mm_per_unit = float(scene_key("[scene]", "mm_per_unit").check(mm_per_unit, label))
        except ValueError as exc:
            raise SceneEditError(str(exc)) from None
    if preset_name is not None:
        from .optics.media import preset

        try:
            preset(str(preset_name))
        except ValueError as exc:
            raise SceneEditError(f"{option}preset: {str(exc).removeprefix('preset: ')}") from None
    parsed = [parse_set(s) if isinstance(s, str) else _checked_pair(*s) for s in sets]
    edits = SceneEdits(preset_name, mm_per_unit, parsed)
    return edits or None


def _checked_pair(key: str, value: Any) -> tuple[str, Any]:
    k, _ = parse_set(f"{key}=0")  # the key's form, checked as the command line's
    return k, value


def parse_value(text: str) -> Any:
    """A TOML value, else a comma list as an array of TOML values, else the text as a string."""
    for candidate in (text, f"[{text}]" if "," in text else None):
        if candidate is None:
            continue
        try:
            return tomllib.loads(f"v = {candidate}")["v"]
        except tomllib.TOMLDecodeError:
            pass
    return text.strip()


def parse_set(item: str) -> tuple[str, Any]:
    """``KEY=VALUE`` -> (key, value); a malformed item is a one-line error naming it."""
    key, sep, value = item.partition("=")
    key = key.strip()
    if not sep or not key or not value.strip():
        raise SceneEditError(f"--set {item!r}: expected KEY=VALUE, e.g. --set roughness=0.3")
    parts = key.split(".")
    if len(parts) == 1:
        if key not in MATERIAL_KEYS:
            raise SceneEditError(
                f"--set {key}: not a material parameter; a scene key is section.key ({', '.join(TABLES)}) or "
                f"{'/'.join(NAMED)}.NAME.key (docs/scenes.md lists them)"
            )
    elif parts[0] in TABLES and len(parts) == 2:
        pass
    elif parts[0] in NAMED and len(parts) == 3:
        pass
    else:
        raise SceneEditError(
            f"--set {key}: expected a material parameter, section.key ({', '.join(TABLES)}) or "
            f"{'/'.join(NAMED)}.NAME.key"
        )
    return key, parse_value(value)


def apply_edits(data: dict, edits: SceneEdits | None) -> dict:
    """The TOML data with the edits applied (a copy; the original is not changed)."""
    if not edits:
        return data
    data = copy.deepcopy(data)
    material: dict[str, Any] = {}
    if edits.preset is not None:
        material["preset"] = edits.preset
    if edits.mm_per_unit is not None:
        _section(data, "scene")["mm_per_unit"] = edits.mm_per_unit
    for key, value in edits.sets:
        parts = key.split(".")
        if len(parts) == 1:
            material[key] = value
        elif len(parts) == 2:
            _section(data, parts[0])[parts[1]] = value
        elif parts[0] == "materials":
            mats = _section(data, "materials")
            if parts[1] not in mats:
                raise SceneEditError(
                    f"--set {key}: the scene has no material {parts[1]!r} (it has: {', '.join(mats) or 'none'})"
                )
            mats[parts[1]][parts[2]] = value
        else:
            entries = data.get(parts[0], [])
            hits = [e for e in entries if isinstance(e, dict) and e.get("name", _stem(e)) == parts[1]]
            if not hits:
                names = [str(e.get("name", _stem(e))) for e in entries if isinstance(e, dict)]
                raise SceneEditError(
                    f"--set {key}: the scene has no {parts[0][:-1]} named {parts[1]!r} "
                    f"(it has: {', '.join(names) or 'none'})"
                )
            for e in hits:
                e[parts[2]] = value
    if material:
        for entry in data.get("meshes", []):
            if isinstance(entry, dict):
                _merge_overrides(entry, material)
                for cfg in entry.get("nodes", {}).values():
                    if isinstance(cfg, dict) and "overrides" in cfg:
                        _merge_overrides(cfg, material)
    return data


def _merge_overrides(table: dict, material: dict) -> None:
    old = table.get("overrides", {})
    if not isinstance(old, dict):
        return  # the scene file's own error names it
    merged = {k: v for k, v in old.items() if k not in material}
    if "preset" in material:
        merged.pop("preset", None)
    table["overrides"] = {**merged, **material}


def _section(data: dict, name: str) -> dict:
    t = data.setdefault(name, {})
    if not isinstance(t, dict):
        raise SceneEditError(f"--set {name}: the scene's [{name}] is not a table")
    return t


def _stem(entry: dict) -> str:
    from pathlib import Path

    f = entry.get("file")
    return Path(f).stem if isinstance(f, str) else ""
