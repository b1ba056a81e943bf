"""A scene written back as a scene file (TOML, docs/scenes.md): what the viewer saves after edits
(``ViewerCore.save_scene``, Ctrl+S) and what ``skinlab.api`` users can call (:func:`save_scene`).

Written: ``[scene]`` (name, mm_per_unit), ``[environment]`` (ambient, exposure; the map, its rotation,
intensity and background), ``[camera]`` (where it is
now), every material the meshes use as a ``[materials.NAME]`` table of its values that differ from the
defaults (maps as absolute paths), one ``[[meshes]]`` entry per mesh file with its transform and each
mesh node's material and visibility under ``[meshes.nodes.NAME]``, and the lights. Loading the file gives
the same materials, camera and lights (tests/scene/test_scene_save.py).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from .graph import LightNode, MeshNode, Node, Scene
from .materials import Material

_BARE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


def _key(name: str) -> str:
    return name if name and set(name) <= _BARE else json.dumps(name)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | np.integer):
        return str(int(v))
    if isinstance(v, float | np.floating):
        f = float(v)
        if not math.isfinite(f):
            raise ValueError(f"cannot write {f} to a scene file")
        return repr(f)
    if isinstance(v, str | Path):
        return json.dumps(str(v))
    if isinstance(v, list | tuple | np.ndarray):
        return "[" + ", ".join(_value(x) for x in list(v)) + "]"
    raise ValueError(f"cannot write {type(v).__name__} {v!r} to a scene file")


def _table(header: str, values: dict) -> list[str]:
    lines = [header]
    lines += [f"{_key(k)} = {_value(v)}" for k, v in values.items() if v is not None]
    return lines + [""]


def _material_values(m: Material) -> dict:
    """The values that differ from the declared defaults."""
    default = Material("default")
    out = {}
    for p in m.params:
        v = m.values[p.name]
        if v != default.values[p.name]:
            out[p.name] = str(Path(v).resolve()) if p.kind == "texture" and v is not None else v
    return out


def _trs(node: Node) -> dict:
    t, r, s = node.translation, node.rotation, node.scale
    out: dict = {}
    if np.any(t != 0):
        out["translation"] = t.tolist()
    if not np.allclose(r, [0, 0, 0, 1]):
        out["rotation"] = r.tolist()
    if not np.allclose(s, 1):
        out["scale"] = s.tolist()
    return out


def scene_toml(scene: Scene) -> str:
    """The scene as scene-file text."""
    lines = [f"# written by Skinlab from {scene.source or 'a scene built in Python'}", ""]
    lines += _table("[scene]", {"name": scene.name, "mm_per_unit": scene.mm_per_unit})
    env = scene.environment
    env_values = {"ambient": np.asarray(env.ambient).tolist(), "exposure": env.exposure}
    if env.map is not None:  # a bundled map by name, another by its absolute path
        from .envmap import bundled_maps

        bundled = {str(p): n for n, p in bundled_maps().items()}
        env_values |= {
            "map": bundled.get(str(env.map), str(Path(env.map).resolve())),
            "rotation_deg": float(env.rotation_deg),
            "intensity": float(env.intensity),
            "show_background": bool(env.show_background),
        }
    lines += _table("[environment]", env_values)
    cam = scene.camera
    if cam is not None:
        w = cam.world_matrix
        pos = w[:3, 3]
        lo, hi = scene.world_bounds()
        dist = max(float(np.linalg.norm((lo + hi) / 2 - pos)), 1e-6)
        forward = -w[:3, 2] / np.linalg.norm(w[:3, 2])
        up = w[:3, 1] / np.linalg.norm(w[:3, 1])
        cam_values = {
            "position": pos.tolist(),
            "target": (pos + forward * dist).tolist(),
            "up": up.tolist(),
            "yfov_deg": math.degrees(cam.yfov),
            "znear": cam.znear,
            "zfar": cam.zfar,
        }
        lines += _table("[camera]", cam_values)
    # every material in use, one table each, under a name unique in the file
    names: dict[int, str] = {}
    for node in scene.mesh_nodes(visible_only=False):
        m = node.material
        if id(m) in names:
            continue
        name, k = m.name or "material", 1
        while name in names.values():
            k += 1
            name = f"{m.name}_{k}"
        names[id(m)] = name
        lines += _table(f"[materials.{_key(name)}]", _material_values(m))
    for top in scene.root.children:
        info = getattr(top, "file_info", None)
        if info is None:
            continue
        entry = {"name": top.name, "file": str(Path(info["file"]).resolve()), **_trs(top)}
        if not top.visible:
            entry["visible"] = False
        for flag in ("flip_v", "generate_uvs"):
            if info.get(flag):
                entry[flag] = True
        if info.get("subdivide"):
            entry["subdivide"] = int(info["subdivide"])
        lines += _table("[[meshes]]", entry)
        for sub in top.walk():
            if sub is top:
                continue
            cfg: dict = {}
            if isinstance(sub, MeshNode):
                cfg["material"] = names[id(sub.material)]
            if not sub.visible:
                cfg["visible"] = False
            if cfg:
                lines += _table(f"[meshes.nodes.{_key(sub.name)}]", cfg)
    for light in scene.nodes():
        if not isinstance(light, LightNode):
            continue
        entry = {"name": light.name, "type": light.kind}
        if light.kind != "directional":
            entry["position"] = light.world_position.tolist()
        if light.kind in ("directional", "spot", "rect"):
            entry["direction"] = light.direction.tolist()
        shape = {"spot": ("inner_deg", "outer_deg"), "rect": ("width", "height"), "sphere": ("radius",)}
        entry |= {k: float(getattr(light, k)) for k in shape.get(light.kind, ())}
        entry |= {"color": np.asarray(light.color).tolist(), "intensity": light.intensity}
        entry["cast_shadow"] = light.cast_shadow
        if not light.visible:  # switched off (the viewer's scene tree): kept, and off again when loaded
            entry["visible"] = False
        lines += _table("[[lights]]", entry)
    return "\n".join(lines)


def save_scene(scene: Scene, path: str | Path) -> Path:
    """Write the scene file (to a temporary name, then renamed into place)."""
    from skinlab.atomic_write import write_text_atomic

    path = Path(path)
    if path.suffix.lower() != ".toml":
        raise ValueError(f"{path}: a scene file is TOML: expected a .toml path")
    return write_text_atomic(path, scene_toml(scene))
