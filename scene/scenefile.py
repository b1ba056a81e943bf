"""Scene files (TOML, read with tomllib).

```toml
[scene]
name = "head"
mm_per_unit = 45.0            # physical scale: scattering distances are in millimetres

[environment]
ambient = [0.03, 0.03, 0.035]
exposure = 1.0

[camera]
position = [0, 1, 30]
target = [0, 1, 0]
yfov_deg = 28

[materials.skin]               # any declared material parameter; paths relative to this file
base_color_map = "../lee-perry-smith/Map-COL.jpg"
roughness = 0.45
# preset = "marble"            # first take a Jensen 2001 medium (albedo, radius, index), then the rest

[[meshes]]
name = "head"
file = "../lee-perry-smith/LeePerrySmith.glb"
material = "skin"
translation = [0, 0, 0]
rotation_deg = [0, 0, 0]        # or rotation = [x, y, z, w]
scale = 1.0
flip_v = false                             # true for assets whose UV origin is the image's top-left
generate_uvs = false                       # true: an xatlas atlas where the file has no UVs
overrides = { roughness = 0.4 }            # per-node material overrides
[meshes.nodes.EyeLeft]                     # nodes inside the file, by name
material = "eye"
overrides = { roughness = 0.05 }

[[lights]]
name = "key"
type = "directional"           # or "point" (use position)
direction = [-0.5, -0.3, -1]   # the way the light travels
color = [1, 0.97, 0.92]
intensity = 3.0
cast_shadow = true
```
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from . import transform as tf
from .graph import CameraNode, LightNode, MeshNode, Node, Scene
from .loaders import LoadedNode, load_mesh_file
from .materials import Material
from .mesh import Mesh

ASSETS = Path(__file__).resolve().parents[1] / "assets"
DEFAULT_SCENE = ASSETS / "scenes" / "head.toml"


class SceneFileError(ValueError):
    pass


def _vec(where: str, value: Any, n: int = 3) -> np.ndarray:
    try:
        a = np.asarray(value, np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise SceneFileError(f"{where}: expected {n} numbers, got {value!r}") from None
    if a.size == 1 and n > 1:
        a = np.repeat(a, n)
    if a.size != n or not np.isfinite(a).all():
        raise SceneFileError(f"{where}: expected {n} finite numbers, got {value!r}")
    return a


def _known(where: str, table: dict, keys: set[str]) -> None:
    extra = set(table) - keys
    if extra:
        raise SceneFileError(
            f"{where}: unknown key(s) {', '.join(sorted(extra))}; expected some of {', '.join(sorted(keys))}"
        )


def _trs(where: str, t: dict) -> dict:
    out = {}
    if "translation" in t:
        out["translation"] = _vec(f"{where}.translation", t["translation"])
    if "rotation" in t and "rotation_deg" in t:
        raise SceneFileError(f"{where}: give rotation or rotation_deg, not both")
    if "rotation" in t:
        q = _vec(f"{where}.rotation", t["rotation"], 4)
        if np.linalg.norm(q) == 0:
            raise SceneFileError(f"{where}.rotation: quaternion must be non-zero")
        out["rotation"] = q / np.linalg.norm(q)
    if "rotation_deg" in t:
        out["rotation"] = tf.euler_deg_to_quat(_vec(f"{where}.rotation_deg", t["rotation_deg"]))
    if "scale" in t:
        s = _vec(f"{where}.scale", t["scale"])
        if (s == 0).any():
            raise SceneFileError(f"{where}.scale: must be non-zero, got {t['scale']!r}")
        out["scale"] = s
    return out


def _resolve_paths(values: dict, base: Path, material: Material) -> dict:
    out = dict(values)
    for p in material.params:
        if p.kind == "texture" and out.get(p.name):
            path = Path(out[p.name])
            out[p.name] = path if path.is_absolute() else (base / path).resolve()
    return out


def load_scene(path: str | Path | None = None) -> Scene:
    """Read a TOML scene file; errors name the file and the offending key."""
    path = Path(path) if path else DEFAULT_SCENE
    if not path.is_file():
        raise FileNotFoundError(f"scene file not found: {path}")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise SceneFileError(f"{path}: not valid TOML: {exc}") from None
    try:
        return _build(path, data)
    except SceneFileError as exc:
        raise SceneFileError(f"{path}: {exc}") from None
    except (ValueError, FileNotFoundError) as exc:
        raise SceneFileError(f"{path}: {exc}") from None


def _build(path: Path, data: dict) -> Scene:
    base = path.parent
    _known("top level", data, {"scene", "environment", "camera", "materials", "meshes", "lights"})
    sc = data.get("scene", {})
    _known("[scene]", sc, {"name", "mm_per_unit"})
    scene = Scene(sc.get("name", path.stem), float(sc.get("mm_per_unit", 1.0)))
    scene.source = path

    env = data.get("environment", {})
    _known("[environment]", env, {"ambient", "exposure"})
    if "ambient" in env:
        scene.environment.ambient = _vec("[environment].ambient", env["ambient"])
    if "exposure" in env:
        scene.environment.exposure = float(env["exposure"])

    materials: dict[str, Material] = {}
    for name, values in data.get("materials", {}).items():
        if not isinstance(values, dict):
            raise SceneFileError(f"[materials.{name}]: expected a table of parameters")
        m = Material(name)
        values = dict(values)
        preset_name = values.pop("preset", None)
        if preset_name is not None:  # a measured medium (assets/presets/jensen2001_table1.csv) first
            from scene.materials import medium_values
            from scene.optics.media import preset

            try:
                m.update(medium_values(preset(str(preset_name))))
            except ValueError as e:
                raise SceneFileError(f"[materials.{name}].preset: {e}") from None
        m.update(_resolve_paths(values, base, m))
        for tex, _ in m.textures().values():
            if not Path(tex).is_file():
                raise SceneFileError(f"[materials.{name}]: texture file not found: {tex}")
        materials[name] = m

    def material_for(where: str, name: str | None, overrides: dict | None) -> Material:
        if name is None:
            mat = Material("default")
        elif name not in materials:
            raise SceneFileError(
                f"{where}.material: no material named {name!r} (defined: {', '.join(materials) or 'none'})"
            )
        else:
            mat = materials[name]
        if overrides:
            mat = mat.with_overrides(_resolve_paths(overrides, base, mat), name=f"{mat.name}+overrides")
        return mat

    for i, entry in enumerate(data.get("meshes", [])):
        where = f"[[meshes]] #{i + 1}"
        _known(
            where,
            entry,
            {
                "name",
                "file",
                "material",
                "overrides",
                "nodes",
                "translation",
                "rotation",
                "rotation_deg",
                "scale",
                "visible",
                "flip_v",
                "generate_uvs",
            },
        )
        if "file" not in entry:
            raise SceneFileError(f"{where}: missing 'file'")
        mpath = Path(entry["file"])
        mpath = mpath if mpath.is_absolute() else base / mpath
        top = Node(entry.get("name", mpath.stem), **_trs(where, entry))
        top.visible = bool(entry.get("visible", True))
        scene.add(top)
        default_mat = material_for(where, entry.get("material"), entry.get("overrides"))
        node_cfg = entry.get("nodes", {})
        loaded = load_mesh_file(mpath)
        names = {n.name for n in loaded}
        for nname in node_cfg:
            if nname not in names:
                raise SceneFileError(
                    f"{where}.nodes.{nname}: {mpath.name} has no node named {nname!r} "
                    f"(it has: {', '.join(sorted(names))})"
                )
        if entry.get("flip_v", False):
            loaded = [LoadedNode(ln.name, ln.parent, ln.matrix, flip_v(ln.mesh)) for ln in loaded]
        if entry.get("generate_uvs", False):  # an xatlas atlas where the file has no UVs
            for ln in loaded:
                if ln.mesh is not None:
                    ln.mesh.ensure_uvs(f"{where}: generate_uvs", generate=True)
        created: dict[str, Node] = {}
        for ln in loaded:
            cfg = node_cfg.get(ln.name, {})
            _known(f"{where}.nodes.{ln.name}", cfg, {"material", "overrides", "visible"})
            if ln.mesh is not None:
                mat = default_mat
                if "material" in cfg or "overrides" in cfg:
                    mat = material_for(
                        f"{where}.nodes.{ln.name}",
                        cfg.get("material", entry.get("material")),
                        {**entry.get("overrides", {}), **cfg.get("overrides", {})},
                    )
                node = MeshNode(ln.name, ln.mesh, mat)
            else:
                node = Node(ln.name)
            node.set_matrix(ln.matrix)
            node.visible = bool(cfg.get("visible", True))
            (created[ln.parent] if ln.parent else top).add(node)
            created[ln.name] = node

    for i, entry in enumerate(data.get("lights", [])):
        where = f"[[lights]] #{i + 1}"
        _known(where, entry, {"name", "type", "direction", "position", "color", "intensity", "cast_shadow"})
        kind = entry.get("type", "directional")
        light = LightNode(
            entry.get("name", f"light{i + 1}"),
            kind,
            _vec(f"{where}.color", entry.get("color", 1.0)),
            float(entry.get("intensity", 1.0)),
            bool(entry.get("cast_shadow", False)),
        )
        if kind == "directional":
            d = _vec(f"{where}.direction", entry.get("direction", [0, 0, -1]))
            if np.linalg.norm(d) == 0:
                raise SceneFileError(f"{where}.direction: must be non-zero")
            light.rotation = tf.look_at_rotation(np.zeros(3), d)
        else:
            if "position" not in entry:
                raise SceneFileError(f"{where}: a point light needs 'position'")
            light.translation = _vec(f"{where}.position", entry["position"])
        scene.add(light)

    cam = data.get("camera")
    if cam is not None:
        _known("[camera]", cam, {"position", "target", "up", "yfov_deg", "znear", "zfar"})
        c = CameraNode(
            "camera",
            np.radians(float(cam.get("yfov_deg", 30.0))),
            float(cam.get("znear", 0.1)),
            float(cam.get("zfar", 1000.0)),
        )
        c.look_at(
            _vec("[camera].position", cam.get("position", [0, 0, 10])),
            _vec("[camera].target", cam.get("target", [0, 0, 0])),
            _vec("[camera].up", cam.get("up", [0, 1, 0])),
        )
        scene.add(c)
    if not scene.mesh_nodes(visible_only=False):
        raise SceneFileError("the scene has no meshes")
    if scene.camera is None:
        scene.add(default_camera(scene))
    return scene


_FLIPPED: dict[int, Mesh] = {}


def flip_v(mesh: Mesh | None) -> Mesh | None:
    """The mesh with v -> 1 - v (for assets whose UV origin is the image's top-left corner)."""
    if mesh is None or mesh.uvs is None:
        return mesh
    if mesh.uid not in _FLIPPED:
        uv = mesh.uvs.copy()
        uv[:, 1] = 1.0 - uv[:, 1]
        _FLIPPED[mesh.uid] = Mesh(mesh.name, mesh.positions, mesh.indices, mesh.normals, uv, None, mesh.source)
    return _FLIPPED[mesh.uid]


def default_camera(scene: Scene, yfov_deg: float = 30.0) -> CameraNode:
    """A camera on +Z framing the scene's bounds."""
    lo, hi = scene.world_bounds()
    centre = (lo + hi) / 2
    radius = max(np.linalg.norm(hi - lo) / 2, 1e-6)
    dist = radius / np.sin(np.radians(yfov_deg) / 2)
    cam = CameraNode("camera", np.radians(yfov_deg), znear=dist * 0.05, zfar=dist * 4)
    cam.look_at(centre + [0, 0, dist], centre)
    return cam
