"""The options that change a scene, shared by `skinlab render`, `skinlab reference`, `skinlab export` and
`skinlab view`: --preset NAME, --set KEY=VALUE (repeatable), --mm-per-unit MM before it is built
(skinlab/scene/scene_edits.py applies them to the scene file's data, so they are validated as its keys);
and, for the commands that draw it (render, view), --exposure and the environment map's options on the
built scene (:func:`scene_look_from_args`)."""

from __future__ import annotations

import math
from pathlib import Path

from skinlab.declare import Field

# --set KEY=VALUE: any scene key or material parameter (each validated by its own declaration when the
# edited data is read); declared here for its help
SET_OPTION = Field(
    "set",
    "string",
    doc="change a material parameter on every mesh (roughness=0.3, subsurface_color=0.2,0.8,0.2, "
    "sss_model=dipole) or a scene key (environment.exposure=2, camera.yfov_deg=20, lights.key.intensity=2, "
    "materials.skin.roughness=0.4, meshes.head.scale=2); repeatable; docs/scenes.md lists every key",
    panel=False,
)


def add_scene_edit_options(p) -> None:
    """--preset, --set and --mm-per-unit: edits of the scene file's data, validated as the keys they
    edit ([materials.NAME] preset on every material, any key, [scene] mm_per_unit)."""
    from skinlab.scene.scene_keys import scene_key

    preset = scene_key("[materials.NAME]", "preset")
    p.add_argument(
        "--preset",
        metavar="NAME",
        help=f"on every mesh's material: {preset.doc}; a colour map stays and multiplies the colour (skin1, skin2, "
        "marble, ketchup, wholemilk, ...: skinlab/assets/presets/jensen2001_table1.csv; default: none, each "
        "material's own values)",
    )
    p.add_argument("--set", dest="sets", action="append", default=None, metavar="KEY=VALUE", help=SET_OPTION.help())
    mm = scene_key("[scene]", "mm_per_unit")
    p.add_argument(
        "--mm-per-unit",
        type=float,
        default=None,
        metavar="MM",
        help=f"{mm.doc} (default: the scene's [scene] mm_per_unit; 1 for a mesh file)",
    )


def scene_edits_from_args(args):
    """SceneEdits from the options (errors name the option); None when none is given."""
    from skinlab.scene.scene_edits import make_edits

    return make_edits(
        getattr(args, "preset", None),
        getattr(args, "mm_per_unit", None),
        getattr(args, "sets", None) or [],
        option="--",
    )


# --exposure and the environment map's options: the scene-file keys of the same meaning, applied to the
# built scene (the scene's own value is the default)
LOOK_OPTIONS = (
    ("--exposure", "exposure", None),
    ("--environment", "map", "MAP"),
    ("--environment-rotation", "rotation_deg", "DEG"),
    ("--environment-intensity", "intensity", "X"),
    ("--background", "show_background", None),
)


# the scene's camera turned before the first frame (`skinlab render`, `skinlab view`)
CAMERA_ORBIT = Field(
    "camera_orbit",
    "float",
    0.0,
    (-math.inf, math.inf),
    unit="deg",
    doc="swing the scene's camera this many degrees about the vertical axis through the meshes' centre "
    "(positive: the camera moves to its right)",
)

MAP_REPLACES = (
    "; a file given here is relative to the working folder, and it replaces the scene's map (a scene without one "
    "loses its uniform ambient, as a map in the file does)"
)


def _look_dest(key: str) -> str:
    return f"scene_look__{key}"


def add_scene_look_options(p) -> None:
    """--exposure, --environment MAP, --environment-rotation, --environment-intensity, --background,
    --camera-orbit: how the built scene is lit, exposed and seen (`skinlab render` and `skinlab view`), each from the
    [environment] key of the same meaning (skinlab/scene/scenefile.py SCENE_FILE_KEYS)."""
    from skinlab.commands.field_options import add_command_options, add_setting_option
    from skinlab.scene.scene_keys import scene_key

    for flag, key, metavar in LOOK_OPTIONS:
        f = scene_key("[environment]", key)
        values = "" if f.kind in ("bool", "string") else f"; {f.expected()}"
        doc = f.doc + (MAP_REPLACES if key == "map" else "")
        unit = f" {f.unit}" if f.unit else ""
        if f.kind == "bool":
            p.add_argument(flag, dest=_look_dest(key), action="store_true", help=f"{doc} (default: the scene's)")
            continue
        help = f"{doc}{values} (default: the scene's [environment] {key}, {f.default_text()}{unit} if unset)"
        add_setting_option(p, f, _look_dest(key), [flag], help=help, metavar=metavar)
    add_command_options(p, [CAMERA_ORBIT])


def _look_values(args) -> dict:
    """The given --exposure and environment options, checked against their scene keys' declarations."""
    from skinlab.commands.field_options import setting_value
    from skinlab.scene.scene_keys import scene_key

    out = {}
    for flag, key, _ in LOOK_OPTIONS:
        value = setting_value(scene_key("[environment]", key), getattr(args, _look_dest(key), None), flag)
        if value is not None and value is not False:
            out[key] = value
    return out


def scene_look_from_args(args):
    """A function applying --exposure and the environment options to a built scene (errors name the
    option); the values that need no scene are checked now, before a scene is loaded."""
    from skinlab.commands.field_options import check_command_options

    look = _look_values(args)
    check_command_options(args, [CAMERA_ORBIT])  # a finite angle
    orbit = getattr(args, "camera_orbit", 0.0)
    map_path = None
    if "map" in look:  # the map is read (and checked) before any scene
        from skinlab.scene.envmap import load_pixels, resolve_map

        map_path = resolve_map(look["map"], Path.cwd())
        load_pixels(map_path)

    def apply(scene) -> None:
        if "exposure" in look:
            scene.environment.exposure = look["exposure"]
        environment_from_args(args, scene, map_path)
        if orbit:
            scene.orbit_camera(orbit)

    return apply


def environment_from_args(args, scene, map_path: Path | None = None) -> None:
    """--environment, --environment-rotation, --environment-intensity, --background on the scene
    (``map_path``: --environment's map, resolved and read already)."""
    from skinlab.scene.envmap import load_pixels, resolve_map

    env, look = scene.environment, _look_values(args)
    if "map" in look:
        path = map_path or resolve_map(look["map"], Path.cwd())
        load_pixels(path)  # cached by the file's stamp: a changed file is read again
        if env.map is None:
            env.ambient = env.ambient * 0.0
        env.map = path
    needs_map = [(flag, key) for flag, key, _ in LOOK_OPTIONS[2:] if key in look]
    if needs_map and env.map is None:
        raise ValueError(f"{needs_map[0][0]}: the scene has no environment map (give --environment MAP)")
    for _, key in needs_map:
        setattr(env, key, look[key])
