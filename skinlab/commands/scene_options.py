"""The options that change a scene, shared by `skinlab render`, `skinlab reference`, `skinlab export` and
`skinlab view`: --preset NAME, --set KEY=VALUE (repeatable), --mm-per-unit MM before it is built
(skinlab/scene/scene_edits.py applies them to the scene file's data, so they are validated as its keys);
and, for the commands that draw it (render, view), --exposure and the environment map's options on the
built scene (:func:`scene_look_from_args`)."""

from __future__ import annotations

import math
from pathlib import Path


def add_scene_edit_options(p) -> None:
    p.add_argument(
        "--preset",
        metavar="NAME",
        help="a measured medium of Jensen et al. 2001 on every mesh's material (base and subsurface colour, radius, "
        "subsurface 1, the specular of its index; a colour map stays and multiplies the colour): skin1, skin2, "
        "marble, ketchup, wholemilk, ... (skinlab/assets/presets/jensen2001_table1.csv; default: none, each "
        "material's own values)",
    )
    p.add_argument(
        "--set",
        dest="sets",
        action="append",
        default=None,
        metavar="KEY=VALUE",
        help="change a material parameter on every mesh (roughness=0.3, subsurface_color=0.2,0.8,0.2, "
        "sss_model=dipole) or a scene key (environment.exposure=2, camera.yfov_deg=20, lights.key.intensity=2, "
        "materials.skin.roughness=0.4, meshes.head.scale=2); repeatable; docs/scenes.md lists every key "
        "(default: none)",
    )
    p.add_argument(
        "--mm-per-unit",
        type=float,
        default=None,
        metavar="MM",
        help="millimetres per scene unit, the scale subsurface_radius (mm) is measured against (default: the "
        "scene's [scene] mm_per_unit; 1 for a mesh file)",
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


def add_scene_look_options(p) -> None:
    """--exposure, --environment MAP, --environment-rotation, --environment-intensity, --background:
    how the built scene is lit and exposed (`skinlab render` and `skinlab view`)."""
    p.add_argument(
        "--exposure",
        type=float,
        default=None,
        help="linear multiplier on radiance before tone mapping, > 0 (default: the scene's [environment] exposure, "
        "1.0 if unset); EXR output is radiance, unaffected",
    )
    p.add_argument(
        "--environment",
        metavar="MAP",
        default=None,
        help="light the scene with an HDR environment map: a bundled one by name (studio, city, courtyard, "
        "interior) or an .exr/.hdr file (replaces the scene's [environment] map; a scene without one "
        "loses its uniform ambient, as with a map in the scene file)",
    )
    p.add_argument("--environment-rotation", type=float, default=None, metavar="DEG", help="turn the map about +Y")
    p.add_argument("--environment-intensity", type=float, default=None, metavar="X", help="scale the map's radiance")
    p.add_argument("--background", action="store_true", help="draw the environment map behind the scene")


def scene_look_from_args(args):
    """A function applying --exposure and the environment options to a built scene (errors name the
    option); the values that need no scene are checked now, before a scene is loaded."""
    exposure = getattr(args, "exposure", None)
    if exposure is not None and not (exposure > 0 and exposure < float("inf")):
        raise ValueError(f"--exposure: expected a finite multiplier > 0, got {exposure}")
    rotation = getattr(args, "environment_rotation", None)
    if rotation is not None and not math.isfinite(rotation):
        raise ValueError(f"--environment-rotation: expected a finite angle in degrees, got {rotation}")
    intensity = getattr(args, "environment_intensity", None)
    if intensity is not None and not (math.isfinite(intensity) and intensity >= 0):
        raise ValueError(f"--environment-intensity: expected a finite number >= 0, got {intensity}")
    map_path = None
    if getattr(args, "environment", None) is not None:  # the map is read (and checked) before any scene
        from skinlab.scene.envmap import load_pixels, resolve_map

        map_path = resolve_map(args.environment, Path.cwd())
        load_pixels(map_path)

    def apply(scene) -> None:
        if exposure is not None:
            scene.environment.exposure = exposure
        environment_from_args(args, scene, map_path)

    return apply


def environment_from_args(args, scene, map_path: Path | None = None) -> None:
    """--environment, --environment-rotation, --environment-intensity, --background on the scene
    (``map_path``: --environment's map, resolved and read already)."""
    from skinlab.scene.envmap import load_pixels, resolve_map

    env = scene.environment
    if getattr(args, "environment", None) is not None:
        path = map_path or resolve_map(args.environment, Path.cwd())
        load_pixels(path)  # cached by the file's stamp: a changed file is read again
        if env.map is None:
            env.ambient = env.ambient * 0.0
        env.map = path
    background = getattr(args, "background", False)
    given = [f for f in ("environment_rotation", "environment_intensity") if getattr(args, f, None) is not None]
    if (given or background) and env.map is None:
        flag = "--" + (given[0] if given else "background").replace("_", "-")
        raise ValueError(f"{flag}: the scene has no environment map (give --environment MAP)")
    if getattr(args, "environment_rotation", None) is not None:
        env.rotation_deg = float(args.environment_rotation)
    if getattr(args, "environment_intensity", None) is not None:
        env.intensity = float(args.environment_intensity)
    if background:
        env.show_background = True
