"""Every key of every scene-file table, declared once (skinlab/declare.py Field) with its typed default,
range, unit and meaning: skinlab/scene/scenefile.py reads each through its declaration and refuses any
other, docs/scenes.md is generated from these (skinlab/scene/scene_docs.py), and the command-line options
of the same meaning (--exposure, --environment ..., --mm-per-unit) take theirs from them. Material
parameters are declared in skinlab/scene/materials.py."""

from __future__ import annotations

import math
from typing import Any

from skinlab.declare import Field

from .graph import LightNode
from .measure import RR_DEPTH_RANGE, SIZE_LIMIT, SPP_RANGE

INF = math.inf


def _key(name: str, kind: str, default: Any = None, range=None, doc: str = "", **kw: Any) -> Field:
    """A scene-file key: a Field that is neither a command-line option nor a panel widget of its own."""
    return Field(name, kind, default, range, doc=doc, cli=False, panel=False, **kw)


# Every key of every table, declared once with its typed default: reading (_read), validation (unknown
# keys are rejected) and docs/scenes.md (skinlab/scene/scene_docs.py) come from this. `shown` is the
# default in words where it is computed; `type_text` the type in words where a relation bounds it.
# Material parameters come from skinlab.scene.materials.
SCENE_FILE_KEYS: dict[str, tuple[Field, ...]] = {
    "[scene]": (
        _key("name", "string", shown="the file's stem", doc="shown in the viewer's title and output names"),
        _key(
            "mm_per_unit",
            "float",
            1.0,
            (1e-12, INF),
            doc="millimetres per scene unit: the physical scale that subsurface_radius (mm) is measured against",
        ),
    ),
    "[environment]": (
        _key(
            "ambient",
            "color",
            (0.03, 0.03, 0.035),
            (0.0, INF),
            shown="[0.03, 0.03, 0.035]; 0 with a map",
            doc="uniform ambient radiance, linear RGB (unshadowed; added to the map's light)",
        ),
        _key(
            "exposure",
            "float",
            1.0,
            (0.0, INF),
            lo_open=True,
            doc="linear multiplier on radiance before tone mapping (PNG only; EXR output is radiance, unaffected)",
        ),
        _key(
            "map",
            "string",
            doc="an HDR environment map lighting the scene: an equirectangular (2:1) linear .exr or .hdr, relative "
            "to the scene file, or a bundled map by name (studio, city, courtyard, interior; skinlab/assets/hdri/). "
            "Mitsuba's axes: +Y up, the image's centre toward +Z; bright small sources become directional "
            "lights with shadows (docs/environment.md)",
        ),
        _key(
            "rotation_deg",
            "float",
            0.0,
            (-INF, INF),
            unit="degrees",
            doc="turns the map about +Y, counter-clockwise seen from above (needs map)",
        ),
        _key("intensity", "float", 1.0, (0.0, INF), doc="multiplier on the map's radiance (needs map)"),
        _key(
            "show_background",
            "bool",
            False,
            doc="draw the map behind the scene (the image's alpha stays the meshes' coverage; needs map)",
        ),
    ),
    "[camera]": (
        _key("position", "vec3", (0.0, 0.0, 10.0), unit="scene units", doc="eye position"),
        _key("target", "vec3", (0.0, 0.0, 0.0), unit="scene units", doc="point looked at; must differ from position"),
        _key("up", "vec3", (0.0, 1.0, 0.0), type_text="3 numbers, non-zero", doc="up direction"),
        _key("yfov_deg", "float", 30.0, (0.0, 179.0), lo_open=True, unit="degrees", doc="vertical field of view"),
        _key("znear", "float", 0.1, (0.0, INF), lo_open=True, unit="scene units", doc="near clipping distance"),
        _key(
            "zfar",
            "float",
            1000.0,
            (0.0, INF),
            lo_open=True,
            unit="scene units",
            type_text="number > znear",
            doc="far clipping distance",
        ),
    ),
    "[materials.NAME]": (
        _key(
            "preset",
            "string",
            doc="a Jensen et al. 2001 medium (assets/presets/): sets base_color, subsurface_color, subsurface_radius, "
            "subsurface = 1 and specular first; the table's other keys then override",
        ),
        _key(
            "openpbr",
            "table",
            shown="{}",
            doc="OpenPBR Surface's subsurface parameters with OpenPBR's meanings, applied after the table's other "
            "keys ([materials.NAME.openpbr] below)",
        ),
        _key("subsurface_weight", "float", 0.0, (0.0, 1.0), doc="an exact alias of subsurface (OpenPBR's name)"),
    ),
    # read by skinlab/scene/openpbr.py, which converts them
    "[materials.NAME.openpbr]": (
        _key(
            "subsurface_weight",
            "float",
            None,
            (0.0, 1.0),
            shown="the material's subsurface",
            doc="weight of subsurface scattering",
        ),
        _key(
            "subsurface_color",
            "color",
            None,
            (0.0, 1.0),
            type_text="3 numbers in [0, 1]",
            shown="the material's",
            doc="the multiple-scattering albedo (Skinlab's subsurface_color, the same meaning)",
        ),
        _key(
            "subsurface_radius",
            "float",
            1.0,
            (0.0, INF),
            shown="1 (with subsurface_radius_scale)",
            unit="scene units",
            doc="length scale of the mean free path",
        ),
        _key(
            "subsurface_radius_scale",
            "color",
            (1.0, 0.5, 0.25),
            (0.0, INF),
            shown="[1, 0.5, 0.25] (with subsurface_radius)",
            doc="per-channel multiplier: radius x scale is the real mean free path 1/sigma_t per channel",
        ),
        _key(
            "subsurface_scatter_anisotropy",
            "float",
            None,
            (-0.95, 0.95),
            shown="the material's",
            doc="Henyey-Greenstein g (Skinlab's parameter of the same name)",
        ),
    ),  # fmt: skip
    "[[meshes]]": (
        _key(
            "file",
            "string",
            shown="-",
            type_text="string (required)",
            doc="mesh file (.glb .gltf .obj .ply .stl .off), relative to the scene file",
        ),
        _key("name", "string", shown="the file's stem", doc="name of the node that holds the file's nodes"),
        _key("material", "string", shown="a default material", doc="name of a [materials.NAME] table"),
        _key("overrides", "table", shown="{}", doc="material parameters for this mesh only, e.g. { roughness = 0.4 }"),
        _key("nodes", "tables", shown="{}", doc="per node of the file, by name: material, overrides, visible"),
        _key("translation", "vec3", (0.0, 0.0, 0.0), unit="scene units", doc="the entry's translation"),
        _key("rotation", "vec4", (0.0, 0.0, 0.0, 1.0), doc="quaternion x, y, z, w (not with rotation_deg)"),
        _key(
            "rotation_deg",
            "vec3",
            (0.0, 0.0, 0.0),
            unit="degrees",
            doc="Euler angles about X, Y, Z (not with rotation)",
        ),
        _key(
            "scale",
            "scale",
            1.0,
            type_text="1 or 3 numbers, magnitude 1e-12 to 1e12",
            doc="scale factor(s); with the file's own node transforms a mesh's world transform must scale by 1e-12 "
            "to 1e12 and move by at most 1e12 (errors name the node)",
        ),
        _key("visible", "bool", True, doc="false hides the mesh and all its nodes"),
        _key("flip_v", "bool", False, doc="v -> 1 - v: for files whose UV origin is the image's top-left"),
        _key(
            "generate_uvs",
            "bool",
            False,
            doc="make an xatlas UV atlas where the file has none (cached by mesh content in ~/.cache/skinlab)",
        ),
        _key(
            "subdivide",
            "int",
            0,
            (0, 3),
            type_text="integer in [0, 3]",
            doc="Loop subdivision levels (each splits a triangle in four and smooths the surface), for the frame "
            "and the path-traced truth alike: an index-matched truth has no shading normals, so a coarse mesh's "
            "facets show in its light (skinlab/scene/mesh_subdivide.py)",
        ),
    ),
    "[meshes.nodes.NAME]": (
        _key("material", "string", shown="the mesh's material", doc="name of a [materials.NAME] table"),
        _key(
            "overrides", "table", shown="{}", doc="material parameters for this node (on top of the mesh's overrides)"
        ),
        _key("visible", "bool", True, doc="false hides this node"),
    ),
    "[[lights]]": (
        _key("name", "string", shown="lightN", doc="the viewer's key light is the one named 'key'"),
        _key(
            "type",
            "choice",
            "directional",
            choices=LightNode.KINDS,
            type_text="string",
            doc='"directional" (uses direction), "point" (position), "spot" (position, direction, inner_deg, '
            'outer_deg), "rect" (position, direction, width, height) or "sphere" (position, radius)',
        ),
        _key(
            "direction",
            "vec3",
            (0.0, 0.0, -1.0),
            type_text="3 numbers, non-zero",
            doc="the way a directional, spot or rect light shines",
        ),
        _key(
            "position",
            "vec3",
            shown="(required but for directional)",
            unit="scene units",
            doc="the light's position (centre)",
        ),
        _key("color", "color", (1.0, 1.0, 1.0), (0.0, INF), unit="linear RGB", doc="the light's colour"),
        _key(
            "intensity",
            "float",
            1.0,
            (0.0, INF),
            doc="multiplier on color: irradiance (directional), intensity (point, spot: falls off with the inverse "
            "square of the distance in metres) or emitted radiance (rect, sphere)",
        ),
        _key("cast_shadow", "bool", False, doc="render a shadow map (at most 2 lights; needed for translucency)"),
        _key("visible", "bool", True, doc="false: the light is off, kept in the scene (the viewer's Ctrl+S writes it)"),
        _key(
            "inner_deg",
            "float",
            30.0,
            (0.0, 90.0),
            unit="degrees",
            type_text="number in [0, outer_deg]",
            doc="spot: half-angle of the full beam",
        ),
        _key(
            "outer_deg",
            "float",
            45.0,
            (0.0, 90.0),
            lo_open=True,
            unit="degrees",
            doc="spot: half-angle past which it is dark; between the two the light fades linearly in angle",
        ),
        _key(
            "width",
            "float",
            1.0,
            (0.0, INF),
            lo_open=True,
            unit="scene units",
            doc="rect: extent across (horizontal when the light does not point straight up or down); one-sided, "
            "shining along direction",
        ),
        _key(
            "height",
            "float",
            1.0,
            (0.0, INF),
            lo_open=True,
            unit="scene units",
            doc="rect: extent along its other side",
        ),
        _key("radius", "float", 0.5, (0.0, INF), lo_open=True, unit="scene units", doc="sphere: radius"),
    ),
    # what the scene tests, for the accuracy ledger (read by skinlab/scene/measure.py parse_measure;
    # docs/ledger.md "Edges and profiles")
    "[measure]": (
        _key("tests", "string", "", doc="what the scene tests, in a sentence (shown in the ledger)"),
        _key(
            "profile",
            "choice",
            "none",
            choices=("none", "line", "edge"),
            type_text="string",
            doc='"line": a slit or stripe of light (the ledger plots the line spread function), "edge": a shadow or '
            'light edge (edge spread function), "none"',
        ),
        _key(
            "profile_origin", "vec3", shown="(required for a profile)", doc="a point on the line's centre or the edge"
        ),
        _key(
            "profile_axis",
            "vec3",
            shown="(required for a profile)",
            type_text="3 numbers, non-zero",
            doc="the direction across the line or edge: the profile's coordinate; pixels are averaged along the line",
        ),
        _key(
            "profile_range_mm",
            "float",
            30.0,
            (0.0, INF),
            lo_open=True,
            unit="mm",
            doc="the profile spans +-this many mm across the line or edge",
        ),
        _key(
            "profile_band_mm",
            "float",
            None,
            (0.0, INF),
            lo_open=True,
            unit="mm",
            shown="all",
            doc="only pixels within this many mm of the origin along the line",
        ),
        _key(
            "line_width_mm", "float", 0.0, (0.0, INF), unit="mm", doc="the line's (slit's) width, for its edge region"
        ),
        _key(
            "edge_mm",
            "float",
            None,
            (0.0, INF),
            unit="mm",
            shown="3 diffusion lengths",
            doc="the edge region (errors within it are reported apart): within this many mm of the declared edge or "
            "the line's sides, else of the plain frame's light edges; default 3 x 1/sigma_tr of the scene's most "
            "diffuse channel",
        ),
        _key(
            "ledger",
            "bool",
            True,
            doc="false: left out of the ledger's default scene list (`--scenes` still takes it)",
        ),
        _key(
            "truth_size",
            "string",
            None,
            shown="the sweep's truth size",
            type_text=f'"WxH" or [W, H], integers in [1, {SIZE_LIMIT}]',
            unit="px",
            doc="the size of this scene's path-traced truth in the ledger (and of the frames compared with it), "
            "instead of the sweep's square one: a close-up's own frame shape (\"256x16\" for a slit)",
        ),
        _key(
            "truth_spp",
            "int",
            None,
            SPP_RANGE,
            type_text=f"integer in [{SPP_RANGE[0]}, {SPP_RANGE[1]}]",
            shown="the sweep's truth spp",
            doc="samples per pixel of this scene's truth in the ledger (every cached pass counts)",
        ),
        _key(
            "truth_rr_depth",
            "int",
            None,
            RR_DEPTH_RANGE,
            type_text=f"integer in [{RR_DEPTH_RANGE[0]}, {RR_DEPTH_RANGE[1]}]",
            shown="64 (`skinlab reference`'s)",
            doc="path depth from which Russian roulette ends the truth's paths (a medium of single-scattering albedo "
            "near 1 needs about 1 / (1 - albedo) or more: slit-marble takes 1024); part of the truth's cache key",
        ),
        _key(
            "deep_shadow",
            "bool",
            False,
            doc="true: the ledger measures the deep shadow's level (camera-visible points the first light does not "
            "reach, more than 2 mm from a lit one, found by ray casting, not by the shadow maps) as a share of the "
            "lit surface's, against the truth's (skinlab/bench/closeup.py)",
        ),
        _key(
            "mesh_energy",
            "bool",
            False,
            doc="true: the ledger measures the energy of each visible mesh apart (its pixels found by ray casting) "
            "against the truth's: light through one part and through another (skinlab/bench/closeup.py)",
        ),
    ),  # fmt: skip
}


def scene_key(section: str, name: str) -> Field:
    """The declaration of one scene-file key (KeyError naming the section and key)."""
    for f in SCENE_FILE_KEYS[section]:
        if f.name == name:
            return f
    raise KeyError(f"{section}: no key {name!r}")
