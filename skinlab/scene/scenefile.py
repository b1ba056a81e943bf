"""Scene files (TOML, read with tomllib). Every key with its type, default and meaning is declared in
skinlab/scene/scene_keys.py (SCENE_FILE_KEYS) and read from its declaration here; docs/scenes.md is
generated from those and the material declarations.

```toml
[scene]
name = "head"
mm_per_unit = 45.0            # physical scale: scattering distances are in millimetres

[environment]
ambient = [0.03, 0.03, 0.035]
exposure = 1.0
# map = "studio"               # an HDR environment map: a bundled one by name, or an .exr/.hdr file
# rotation_deg = 90            # turns the map about +Y; intensity = 1.0; show_background = true

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
type = "directional"           # or "point", "spot", "rect", "sphere" (docs/scenes.md)
direction = [-0.5, -0.3, -1]   # the way the light travels
color = [1, 0.97, 0.92]
intensity = 3.0
cast_shadow = true
```
"""

from __future__ import annotations

import math
import sys
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from skinlab.resources import assets_root, bundled_scenes, scene_by_name

from . import transform as tf
from .graph import CameraNode, LightNode, MeshNode, Node, Scene
from .loaders import SUPPORTED, TRANSFORM_RANGE, load_mesh_file, transform_problem
from .materials import Material
from .mesh import Mesh, with_atlas
from .paths import absolute
from .scene_edits import apply_edits
from .scene_keys import SCENE_FILE_KEYS, scene_key

ASSETS = assets_root()
DEFAULT_SCENE = ASSETS / "scenes" / "head.toml"


class SceneFileError(ValueError):
    pass


def _keys(section: str) -> set[str]:
    return {k.name for k in SCENE_FILE_KEYS[section]}


# -- typed reads: every wrong type or value names its key ------------------------------------------

_TOML_TYPE = {
    bool: "a boolean",
    int: "an integer",
    float: "a number",
    str: "a string",
    list: "an array",
    dict: "a table",
}


def _kind(value: Any) -> str:
    return next((name for t, name in _TOML_TYPE.items() if isinstance(value, t)), type(value).__name__)


def _show(value: Any) -> str:
    if _too_big(value):
        return f"of {len(str(abs(value)))} digits (beyond the range of a float)"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _table(where: str, value: Any) -> dict:
    if not isinstance(value, dict):
        raise SceneFileError(f"{where}: expected a table, got {_kind(value)} {_show(value)}")
    return value


def _tables(where: str, value: Any) -> list[dict]:
    """An array of tables (``[[meshes]]``)."""
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise SceneFileError(
            f"{where}: expected an array of tables ([[{where.strip('[]')}]] entries), got {_kind(value)} {_show(value)}"
        )
    return value


def _str(where: str, value: Any) -> str:
    if not isinstance(value, str):
        raise SceneFileError(f"{where}: expected a string, got {_kind(value)} {_show(value)}")
    return value


def _bool(where: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise SceneFileError(f"{where}: expected true or false, got {_kind(value)} {_show(value)}")
    return value


_FLOAT_MAX = int(sys.float_info.max)


def _too_big(value: Any) -> bool:
    """An integer no float can hold (``1`` followed by 400 zeros): TOML integers are unbounded."""
    return isinstance(value, int) and not isinstance(value, bool) and abs(value) > _FLOAT_MAX


def _is_number(value: Any) -> bool:
    """A TOML integer or float (not a boolean) that converts to a float: every numeric key and vector
    component is read through here, so an integer beyond float range is a wrong value naming its key."""
    return isinstance(value, int | float) and not isinstance(value, bool) and not _too_big(value)


def _num(where: str, value: Any, lo: float | None = None, hi: float | None = None, lo_open: bool = False) -> float:
    """A finite number in [lo, hi] (or (lo, hi] with lo_open)."""
    rng = f"{'(' if lo_open else '['}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}]"
    if not _is_number(value) or not np.isfinite(value):
        raise SceneFileError(f"{where}: expected a finite number in {rng}, got {_kind(value)} {_show(value)}")
    v = float(value)
    if (lo is not None and (v <= lo if lo_open else v < lo)) or (hi is not None and v > hi):
        raise SceneFileError(f"{where}: expected a number in {rng}, got {_show(value)}")
    if abs(v) > MAX_MAGNITUDE:
        raise SceneFileError(f"{where}: expected a number of magnitude at most {MAX_MAGNITUDE:g}, got {_show(value)}")
    return v


MAX_MAGNITUDE = 1e12  # coordinates, scales, colours: larger ones overflow float32 products (NaN pixels)


def _vec(where: str, value: Any, n: int = 3, lo: float | None = None) -> np.ndarray:
    """n finite numbers (a single number fills all n) of magnitude <= MAX_MAGNITUDE, each >= lo if given."""
    items = value if isinstance(value, list) else [value]
    _no_huge_items(where, items)
    if not all(_is_number(v) for v in items):
        raise SceneFileError(f"{where}: expected {n} numbers, got {_kind(value)} {_show(value)}")
    a = np.asarray(items, np.float64).reshape(-1)
    if a.size == 1 and n > 1:
        a = np.repeat(a, n)
    if a.size != n or not np.isfinite(a).all():
        raise SceneFileError(f"{where}: expected {n} finite numbers, got {_show(value)}")
    if lo is not None and (a < lo).any():
        raise SceneFileError(f"{where}: expected numbers >= {lo}, got {_show(value)}")
    if (np.abs(a) > MAX_MAGNITUDE).any():
        raise SceneFileError(f"{where}: expected numbers of magnitude at most {MAX_MAGNITUDE:g}, got {_show(value)}")
    return a


def _no_huge_items(where: str, items: list) -> None:
    """An integer no float can hold, named by its position in the array."""
    for i, v in enumerate(items):
        if _too_big(v):
            raise SceneFileError(f"{where}: component {i + 1} is an integer {_show(v)}")


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
        if (np.abs(s) < 1.0 / MAX_MAGNITUDE).any():
            raise SceneFileError(
                f"{where}.scale: expected factors of magnitude {1 / MAX_MAGNITUDE:g} or more, got {_show(t['scale'])}"
            )
        out["scale"] = s
    return out


def _resolve_paths(where: str, values: dict, base: Path, material: Material) -> dict:
    out = dict(values)
    for p in material.params:
        if p.kind == "texture" and p.name in out and out[p.name] not in (None, ""):
            path = Path(_str(f"{where}.{p.name}", out[p.name]))
            out[p.name] = path if path.is_absolute() else absolute(base / path)
    return out


def _material_values(where: str, material: Material, values: dict) -> Material:
    """material.update(values) with errors naming the table: unknown parameters, types and ranges."""
    pm = material.param_map
    for k, v in values.items():
        if k == "subsurface_radius_scale":
            raise SceneFileError(
                f"{where}.subsurface_radius_scale: OpenPBR's radius pair (a mean free path in scene units) goes "
                "in an openpbr table with its subsurface_radius ([materials.NAME.openpbr]); Skinlab's "
                "subsurface_radius is the artist radius in mm (docs/scenes.md)"
            )
        if k not in pm:
            raise SceneFileError(f"{where}: unknown material parameter {k!r}; known: {', '.join(pm)}")
        if isinstance(v, list):
            _no_huge_items(f"{where}.{k}", v)
        if pm[k].kind in ("float", "color", "vec3", "vec2") and not (
            _is_number(v) or (isinstance(v, list) and all(_is_number(x) for x in v))
        ):
            n = {"float": "a number", "vec2": "2 numbers"}.get(pm[k].kind, "3 numbers")
            raise SceneFileError(f"{where}.{k}: expected {n}, got {_kind(v)} {_show(v)}")
        if pm[k].kind == "choice" and not isinstance(v, str):
            raise SceneFileError(f"{where}.{k}: expected one of {', '.join(pm[k].choices)}, got {_show(v)}")
        try:
            material.values[k] = pm[k].check(v)
        except ValueError as exc:
            raise SceneFileError(f"{where}.{exc}") from None
    return material


def _material_table(where: str, material: Material, values: dict, base: Path, mm_per_unit: float) -> Material:
    """A [materials.NAME] table (or overrides) onto `material`: ``preset`` first (a Jensen 2001
    medium), then the parameters (aliases such as subsurface_weight name theirs), then ``openpbr``
    (OpenPBR's subsurface set, skinlab/scene/openpbr.py, converted with the scene's mm_per_unit)."""
    from .materials import canonical_names
    from .openpbr import openpbr_to_skinlab

    values = dict(values)
    preset_name = values.pop("preset", None)
    openpbr = values.pop("openpbr", None)
    if preset_name is not None:  # a measured medium (skinlab/assets/presets/jensen2001_table1.csv) first
        try:
            material.apply_preset(_str(f"{where}.preset", preset_name))
        except ValueError as e:
            raise SceneFileError(f"{where}.{str(e).split(': ', 1)[-1]}") from None
    try:
        values = canonical_names(values, f"{where}: ")
    except ValueError as e:
        raise SceneFileError(str(e)) from None
    _material_values(where, material, _resolve_paths(where, values, base, material))
    if openpbr is not None:
        ow = f"{where}.openpbr"
        try:
            material.update(openpbr_to_skinlab(_table(ow, openpbr), material.values, mm_per_unit, ow))
        except ValueError as e:
            raise SceneFileError(str(e)) from None
    _check_textures(where, material)
    return material


def _check_textures(where: str, material: Material) -> None:
    """Every map set on the material exists and decodes (cached: the renderer reuses the pixels)."""
    from .textures import read_texture

    for p in material.params:
        tex = material.values.get(p.name) if p.kind == "texture" else None
        if tex is None:
            continue
        try:
            read_texture(tex)
        except (ValueError, OSError) as exc:
            raise SceneFileError(f"{where}.{p.name}: {exc}") from None


def _environment_map(env: dict, base: Path, scene: Scene) -> None:
    """[environment] map and its settings: the file found and checked (skinlab/scene/envmap.py)."""
    from .envmap import EnvironmentMapError, load_pixels, resolve_map

    if "map" not in env:
        for key in ("rotation_deg", "intensity", "show_background"):
            if key in env:
                raise SceneFileError(f"[environment].{key}: needs an environment map ([environment] map)")
        return
    try:
        path = resolve_map(_str("[environment].map", env["map"]), base)
        load_pixels(path)
    except EnvironmentMapError as exc:
        raise SceneFileError(f"[environment].map: {exc}") from None
    e = scene.environment
    e.map = path
    e.ambient = np.zeros(3)  # with a map the uniform ambient is off unless given
    if "rotation_deg" in env:
        e.rotation_deg = _num("[environment].rotation_deg", env["rotation_deg"])
    if "intensity" in env:
        e.intensity = _num("[environment].intensity", env["intensity"], 0.0)
    if "show_background" in env:
        e.show_background = _bool("[environment].show_background", env["show_background"])


def resolve_scene_path(path: str | Path | None) -> Path:
    """A file that exists, else a bundled scene of that name; FileNotFoundError naming both tries."""
    if not path:
        return DEFAULT_SCENE
    p = Path(path)
    if p.exists():
        return p
    bundled = scene_by_name(p.with_suffix("").as_posix() if p.suffix.lower() == ".toml" else p.as_posix())
    if bundled is not None:
        return bundled
    names = ", ".join(s.name for s in bundled_scenes() if "/" not in s.name)
    raise FileNotFoundError(
        f"scene file not found: {path} (and no bundled scene of that name: {names}, ...; `skinlab scenes` lists all)"
    )


def load_scene(path: str | Path | None = None, edits=None) -> Scene:
    """Read a TOML scene file (or a mesh file: see :func:`scene_from_mesh`), or a bundled scene by
    name (``"head"``, ``"bunny-marble"``: ``skinlab scenes`` lists them); errors name the file and
    the offending key. ``edits`` (skinlab/scene/scene_edits.py SceneEdits: a preset, mm_per_unit,
    --set KEY=VALUE) change the file's data before it is built, validated like the file's own keys."""
    path = resolve_scene_path(path)
    if path.is_dir():
        raise SceneFileError(f"{path}: is a folder, expected a scene file (.toml) or a mesh file")
    if path.suffix.lower() in SUPPORTED:
        return scene_from_mesh(path, edits=edits)
    data = read_scene_data(path)
    try:
        return _build(path, apply_edits(data, edits))
    except SceneFileError as exc:
        raise SceneFileError(f"{path}: {exc}") from None
    except (ValueError, FileNotFoundError) as exc:
        raise SceneFileError(f"{path}: {exc}") from None


def read_scene_data(path: Path) -> dict:
    """A scene file's TOML data (errors name the file)."""
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneFileError(f"{path}: not UTF-8 text (byte {exc.start}): is this a scene file?") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneFileError(f"{path}: not valid TOML: {exc}") from None
    except ValueError as exc:  # Python's limit on integer digits (4300)
        raise SceneFileError(f"{path}: a number too long to read ({str(exc).split(';')[0]})") from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise SceneFileError(f"{path}: arrays or inline tables nested too deeply (hundreds of levels)") from None
    return data


TOP_LEVEL = ("scene", "environment", "camera", "materials", "meshes", "lights", "measure")


def _build(path: Path, data: dict) -> Scene:
    """A Scene from a scene file's data: each table read by the function named after it."""
    base = path.parent
    _known("top level", data, set(TOP_LEVEL))
    scene = _scene_table(path, _table("[scene]", data.get("scene", {})))
    _environment_table(_table("[environment]", data.get("environment", {})), base, scene)
    materials = SceneMaterials(_material_tables(data.get("materials", {}), base, scene.mm_per_unit), base, scene)
    for i, entry in enumerate(_tables("[meshes]", data.get("meshes", []))):
        _mesh_entry(f"[[meshes]] #{i + 1}", entry, scene, materials)
    for i, entry in enumerate(_tables("[lights]", data.get("lights", []))):
        scene.add(_light(f"[[lights]] #{i + 1}", entry, i))
    if "camera" in data:
        scene.add(_camera_table(_table("[camera]", data["camera"])))
    if "measure" in data:
        scene.measure = _measure_table(_table("[measure]", data["measure"]))
    if not scene.mesh_nodes(visible_only=False):
        raise SceneFileError("the scene has no meshes (add a [[meshes]] entry with a file)")
    if scene.camera is None:
        scene.add(default_camera(scene))
    return scene


def _read(where: str, table: dict, section: str, name: str) -> Any:
    """Key `name` of `table` (called `where` in errors), read as its declaration in SCENE_FILE_KEYS
    [section] says; the declared default where the table does not have it."""
    f = scene_key(section, name)
    if name not in table:
        if f.kind == "table":
            return {}  # an empty table (shown "{}")
        return np.asarray(f.default, np.float64) if f.kind in _VECTOR_KEYS and f.default is not None else f.default
    value, w = table[name], f"{where}.{name}"
    lo, hi = f.range if f.range is not None else (-math.inf, math.inf)
    if f.kind == "string":
        return _str(w, value)
    if f.kind == "bool":
        return _bool(w, value)
    if f.kind == "choice":
        if _str(w, value) not in f.choices:
            raise SceneFileError(f"{w}: expected one of {', '.join(f.choices)}, got {value!r}")
        return value
    if f.kind == "float":
        return _num(w, value, None if lo == -math.inf else lo, None if hi == math.inf else hi, f.lo_open)
    if f.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise SceneFileError(f"{w}: expected an integer in [{lo:g}, {hi:g}], got {_show(value)}")
        return int(value)
    if f.kind in _VECTOR_KEYS:
        return _vec(w, value, _VECTOR_KEYS[f.kind], lo=None if lo == -math.inf else lo)
    if f.kind == "table":
        return _table(w, value)
    raise TypeError(f"{w}: a {f.kind} key is read where it is used")


_VECTOR_KEYS = {"vec3": 3, "color": 3, "vec4": 4}


def _scene_table(path: Path, sc: dict) -> Scene:
    """[scene]: the name (default the file's stem) and the physical scale."""
    _known("[scene]", sc, _keys("[scene]"))
    name = _read("[scene]", sc, "[scene]", "name") if "name" in sc else path.stem
    scene = Scene(name, _read("[scene]", sc, "[scene]", "mm_per_unit"))
    scene.source = path
    return scene


def _environment_table(env: dict, base: Path, scene: Scene) -> None:
    """[environment]: exposure, the uniform ambient and the environment map with its settings."""
    _known("[environment]", env, _keys("[environment]"))
    scene.environment.exposure = _read("[environment]", env, "[environment]", "exposure")
    scene.environment.ambient = _read("[environment]", env, "[environment]", "ambient")
    _environment_map(env, base, scene)
    if "ambient" in env:  # given beside a map, it stays
        scene.environment.ambient = _read("[environment]", env, "[environment]", "ambient")


def _material_tables(tables: Any, base: Path, mm_per_unit: float) -> dict[str, Material]:
    """[materials.NAME] tables, by name."""
    materials: dict[str, Material] = {}
    for name, values in _table("[materials]", tables).items():
        where = f"[materials.{name}]"
        materials[name] = _material_table(where, Material(name), _table(where, values), base, mm_per_unit)
    return materials


class SceneMaterials:
    """The material a mesh node gets: a named [materials.NAME] table, else the mesh file's own (glTF:
    one Material per file and material), else the default; the entry's and node's overrides on top."""

    def __init__(self, named: dict[str, Material], base: Path, scene: Scene) -> None:
        self.named, self.base, self.mm_per_unit = named, base, scene.mm_per_unit
        self.from_files: dict[tuple[str, int], Material] = {}

    def choose(self, where: str, name: Any, overrides: Any, own=None, mfile: Path | None = None) -> Material:
        if name is None and own is not None:
            key = (str(mfile), own.index)
            if key not in self.from_files:
                self.from_files[key] = _file_material(f"{where} ({Path(str(mfile)).name})", own, self.mm_per_unit)
            mat = self.from_files[key]
        elif name is None:
            mat = Material("default")
        elif _str(f"{where}.material", name) not in self.named:
            raise SceneFileError(
                f"{where}.material: no material named {name!r} (defined: {', '.join(self.named) or 'none'})"
            )
        else:
            mat = self.named[name]
        if overrides:
            ow = f"{where}.overrides"
            mat = Material(f"{mat.name}+overrides", dict(mat.values), mat.params)
            _material_table(ow, mat, _table(ow, overrides), self.base, self.mm_per_unit)
        return mat


def _mesh_entry(where: str, entry: dict, scene: Scene, materials: SceneMaterials) -> Node:
    """One [[meshes]] entry: a node holding the file's nodes, with the entry's transform, materials,
    overrides and per-node settings."""
    sec = "[[meshes]]"
    _known(where, entry, _keys(sec))
    if "file" not in entry:
        raise SceneFileError(f"{where}: missing 'file'")
    mpath = Path(_read(where, entry, sec, "file"))
    mpath = mpath if mpath.is_absolute() else materials.base / mpath
    flip, atlas = _read(where, entry, sec, "flip_v"), _read(where, entry, sec, "generate_uvs")
    top = Node(_read(where, entry, sec, "name") if "name" in entry else mpath.stem, **_trs(where, entry))
    top.visible = _read(where, entry, sec, "visible")
    levels = _read(where, entry, sec, "subdivide")
    top.file_info = {"file": mpath, "flip_v": flip, "generate_uvs": atlas, "subdivide": levels}
    scene.add(top)
    node_cfg = _table(f"{where}.nodes", entry.get("nodes", {}))
    try:
        loaded = load_mesh_file(mpath, scene.warnings)
    except (ValueError, FileNotFoundError) as exc:
        raise SceneFileError(f"{where}.file: {exc}") from None
    names = {n.name for n in loaded}
    for nname, cfg in node_cfg.items():
        _table(f"{where}.nodes.{nname}", cfg)
        if nname not in names:
            raise SceneFileError(
                f"{where}.nodes.{nname}: {mpath.name} has no node named {nname!r} (it has: {', '.join(sorted(names))})"
            )
    if flip:
        loaded = [replace(ln, mesh=flip_v(ln.mesh)) for ln in loaded]
    if atlas:  # an xatlas atlas where none
        loaded = [replace(ln, mesh=ln.mesh and with_atlas(ln.mesh)) for ln in loaded]
    if levels:  # the same smoothed surface for the frame and the truth
        from .mesh_subdivide import loop_subdivide

        loaded = [replace(ln, mesh=ln.mesh and loop_subdivide(ln.mesh, levels)) for ln in loaded]
    _file_nodes(where, entry, top, loaded, node_cfg, mpath, materials)
    _check_world_transforms(where, top)
    return top


def _file_nodes(where, entry: dict, top: Node, loaded, node_cfg: dict, mpath: Path, materials: SceneMaterials):
    """The mesh file's nodes under `top`, each with its material (the entry's, or its node table's)."""
    mesh_overrides = _read(where, entry, "[[meshes]]", "overrides")
    entry_mats: dict = {}  # the entry's material (with its overrides) per file material
    created: dict[str, Node] = {}
    for ln in loaded:
        nwhere = f"{where}.nodes.{ln.name}"
        cfg = node_cfg.get(ln.name, {})
        _known(nwhere, cfg, _keys("[meshes.nodes.NAME]"))
        if ln.mesh is not None:
            own = ln.material if "material" not in entry else None  # a named material wins
            key = own.index if own is not None else None
            if key not in entry_mats:
                entry_mats[key] = materials.choose(where, entry.get("material"), mesh_overrides, own, mpath)
            mat = entry_mats[key]
            if "material" in cfg or "overrides" in cfg:
                mat = materials.choose(
                    nwhere,
                    cfg.get("material", entry.get("material")),
                    {**mesh_overrides, **_read(nwhere, cfg, "[meshes.nodes.NAME]", "overrides")},
                    ln.material if "material" not in cfg and "material" not in entry else None,
                    mpath,
                )
            node: Node = MeshNode(ln.name, ln.mesh, mat)
        else:
            node = Node(ln.name)
        node.set_matrix(ln.matrix)
        node.visible = _read(nwhere, cfg, "[meshes.nodes.NAME]", "visible")
        (created[ln.parent] if ln.parent else top).add(node)
        created[ln.name] = node


def _camera_table(cam: dict) -> CameraNode:
    """[camera]: where it is, what it looks at, its field of view and clipping distances."""
    _known("[camera]", cam, _keys("[camera]"))
    key = lambda name: _read("[camera]", cam, "[camera]", name)  # noqa: E731
    znear, zfar = key("znear"), key("zfar")
    if zfar <= znear:
        raise SceneFileError(f"[camera].zfar: must be greater than znear ({znear}), got {zfar}")
    c = CameraNode("camera", np.radians(key("yfov_deg")), znear, zfar)
    eye, target, up = key("position"), key("target"), key("up")
    if np.allclose(eye, target):
        raise SceneFileError(f"[camera].target: the camera looks at its own position {eye.tolist()}")
    if np.linalg.norm(up) == 0:
        raise SceneFileError("[camera].up: must be non-zero")
    c.look_at(eye, target, up)
    return c


def _measure_table(table: dict):
    """[measure]: what the scene tests, for the accuracy ledger (skinlab/scene/measure.py)."""
    from .measure import parse_measure

    _known("[measure]", table, _keys("[measure]"))
    try:
        return parse_measure(table, _num, _vec, _str, _bool)
    except ValueError as exc:
        raise SceneFileError(str(exc)) from None


def _check_world_transforms(where: str, top: Node) -> None:
    """The entry's scale, rotation and translation times the file's own transforms stay renderable."""
    for node in top.walk():
        problem = transform_problem(node.world_matrix) if isinstance(node, MeshNode) else None
        if problem:
            raise SceneFileError(
                f"{where}: mesh node {node.name!r}: with this entry's translation, rotation and scale its world "
                f"transform {problem}; {TRANSFORM_RANGE}"
            )


# the keys each light type takes besides name, type, color, intensity and cast_shadow
_LIGHT_KEYS = {
    "directional": ("direction",),
    "point": ("position",),
    "spot": ("position", "direction", "inner_deg", "outer_deg"),
    "rect": ("position", "direction", "width", "height"),
    "sphere": ("position", "radius"),
}


def _light(where: str, entry: dict, i: int) -> LightNode:
    """One [[lights]] entry: its kind, the keys that kind has (the others are errors), colour and power."""
    sec = "[[lights]]"
    _known(where, entry, _keys(sec))
    key = lambda name: _read(where, entry, sec, name)  # noqa: E731
    kind = key("type")
    own = _LIGHT_KEYS[kind]
    for name in ("direction", "position", "inner_deg", "outer_deg", "width", "height", "radius"):
        if name in entry and name not in own:
            hint = {
                "position": " (use direction)",
                "direction": " (it shines every way: remove direction)" if kind in ("point", "sphere") else "",
            }.get(name, "")
            raise SceneFileError(f"{where}.{name}: a {kind} light has no {name}{hint}")
    shape = {name: key(name) for name in own if name not in ("position", "direction")}
    try:
        light = LightNode(
            key("name") if "name" in entry else f"light{i + 1}",
            kind,
            key("color"),
            key("intensity"),
            key("cast_shadow"),
            **shape,
        )
    except ValueError as exc:
        raise SceneFileError(f"{where}: {exc}") from None
    light.visible = key("visible")
    if "position" in own:
        if "position" not in entry:
            raise SceneFileError(f"{where}: a {kind} light needs 'position'")
        light.translation = key("position")
    if "direction" in own:
        d = key("direction")
        if np.linalg.norm(d) == 0:
            raise SceneFileError(f"{where}.direction: must be non-zero")
        light.rotation = tf.look_at_rotation(np.zeros(3), d)
    return light


def _file_material(where: str, own, mm_per_unit: float) -> Material:
    """A Material from a mesh file's own material (skinlab/scene/gltf_materials.py FileMaterial); a
    scattering volume's extinction becomes the radius at the scene's scale."""
    from .gltf_materials import volume_radius_mm

    m = Material(own.name)
    values = dict(own.values)
    if own.volume is not None:
        values["subsurface_radius"] = volume_radius_mm(own.volume, mm_per_unit)
    try:
        m.update(values)
    except ValueError as exc:
        raise SceneFileError(f"{where}: {exc}") from None
    _check_textures(f"{where}: material {own.name!r}", m)
    return m


# What a mesh file opened directly gets: a key light with a shadow from the upper left, a cool fill.
MESH_FILE_LIGHTS = (
    {
        "name": "key",
        "direction": [-0.55, -0.35, -0.75],
        "color": [1.0, 0.96, 0.9],
        "intensity": 3.0,
        "cast_shadow": True,
    },
    {"name": "fill", "direction": [0.7, -0.1, -0.5], "color": [0.55, 0.65, 0.85], "intensity": 0.6},
)


def mesh_file_data(path: Path, mm_per_unit: float = 1.0) -> dict:
    """The scene-file data a mesh file opened directly stands for (:func:`scene_from_mesh`)."""
    return {
        "scene": {"name": path.stem, "mm_per_unit": mm_per_unit},
        "meshes": [{"file": str(path.resolve()), "name": path.stem}],
        "lights": [dict(light, type="directional") for light in MESH_FILE_LIGHTS],
    }


def scene_from_mesh(path: str | Path, mm_per_unit: float = 1.0, edits=None) -> Scene:
    """A mesh file opened directly (``skinlab render model.obj``): its own nodes with the file's own
    materials (glTF) or the default material (plain principled, no subsurface), a camera on +Z
    framing it, a shadow-casting key light from the upper left and a cool fill: the scene file with
    only ``[[meshes]] file`` and those lights (:func:`mesh_file_data`), `edits` applied to it."""
    path = Path(path)
    load_mesh_file(path)  # the file's own errors first, without a scene-file key around them
    try:
        return _build(path, apply_edits(mesh_file_data(path, mm_per_unit), edits))
    except (ValueError, FileNotFoundError) as exc:
        raise SceneFileError(f"{path}: {exc}") from None


_FLIPPED: dict[int, Mesh] = {}


def flip_v(mesh: Mesh | None) -> Mesh | None:
    """The mesh with v -> 1 - v (for assets whose UV origin is the image's top-left corner)."""
    if mesh is None or mesh.uvs is None:
        return mesh
    if mesh.uid not in _FLIPPED:
        uv = mesh.uvs.copy()
        uv[:, 1] = 1.0 - uv[:, 1]
        _FLIPPED[mesh.uid] = Mesh(
            mesh.name, mesh.positions, mesh.indices, mesh.normals, uv, None, mesh.source, colors=mesh.colors
        )
    return _FLIPPED[mesh.uid]


def default_camera(scene: Scene, yfov_deg: float | None = None) -> CameraNode:
    """A camera on +Z framing the scene's bounds (field of view: [camera] yfov_deg's declared default)."""
    yfov_deg = scene_key("[camera]", "yfov_deg").default if yfov_deg is None else yfov_deg
    lo, hi = scene.world_bounds()
    centre = (lo + hi) / 2
    radius = max(np.linalg.norm(hi - lo) / 2, 1e-6)
    dist = radius / np.sin(np.radians(yfov_deg) / 2)
    cam = CameraNode("camera", np.radians(yfov_deg), znear=dist * 0.05, zfar=dist * 4)
    cam.look_at(centre + [0, 0, dist], centre)
    return cam
