"""The options that change a scene before it is built, shared by `skinlab render`, `skinlab reference`
and `skinlab view`: --preset NAME, --set KEY=VALUE (repeatable), --mm-per-unit MM
(skinlab/scene/scene_edits.py applies them to the scene file's data, so they are validated as its keys)."""

from __future__ import annotations


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
