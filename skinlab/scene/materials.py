"""Materials declare their parameters once; uniforms, shader variants and UI derive from that.

A parameter is a :class:`skinlab.declare.Field` (name, kind, default, range, unit, meaning). Kinds:
- ``float`` / ``color`` / ``vec3`` / ``vec2``: plain values, uploaded as uniforms ``u_<name>``;
- ``texture``: a file path; when set it selects a shader variant (``HAS_<NAME>``) and binds a sampler;
- ``choice``: an option the renderer reads on the CPU (the SSS model picks the profile a technique
  plans with); it is no uniform and no define.

The GLSL declarations of the uniforms and samplers come from the same declaration: the virtual
include ``skinlab/material.glsl`` (:func:`glsl_material_uniforms`), so a renamed parameter is a
compile error in the shaders that use it, not a uniform silently left at zero.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skinlab.declare import NUMERIC_KINDS, Field

SSS_MODELS = ("none", "dipole", "burley", "blender-burley", "gaussians", "pbd")
ALPHA_MODES = ("opaque", "mask", "blend")


# One meaning per parameter, stated here once: the panel's tooltips, the docs (docs/scenes.md, generated
# from this table by `python -m skinlab.scene.scene_docs`) and errors all read it.
PRINCIPLED_PARAMS: tuple[Field, ...] = (
    Field(
        "base_color",
        "color",
        (0.8, 0.8, 0.8),
        (0.0, 1.0),
        unit="linear RGB",
        doc="albedo of the plain diffuse part (weight 1 - subsurface) and a metal's F0; x the colour map",
    ),
    Field(
        "base_color_map",
        "texture",
        None,
        colorspace="srgb",
        doc="colour map (sRGB file): multiplies base_color and subsurface_color per texel; its mean colour "
        "also goes into the medium's albedo (the colour rule above)",
    ),
    Field("roughness", "float", 0.5, (0.0, 1.0), doc="perceptual roughness; GGX alpha = roughness^2"),
    Field("roughness_map", "texture", None, doc="roughness map (R channel, linear); multiplies roughness"),
    Field("metallic", "float", 0.0, (0.0, 1.0), doc="0 dielectric, 1 metal (base_color becomes the specular F0)"),
    Field("specular", "float", 0.5, (0.0, 1.0), doc="dielectric F0 = 0.08 * specular (0.5 -> 4 %, index 1.5)"),
    Field("normal_map", "texture", None, doc="tangent-space normal map (linear, OpenGL +Y)"),
    Field("normal_scale", "float", 1.0, (0.0, 4.0), doc="strength of the normal map (0: off)"),
    Field("occlusion_map", "texture", None, doc="ambient occlusion (R channel, linear); multiplies the ambient light"),
    Field(
        "occlusion_strength",
        "float",
        1.0,
        (0.0, 1.0),
        doc="how much of the occlusion map applies: ambient x (1 + strength (map - 1)) "
        "(glTF occlusionTexture.strength)",
    ),
    Field("metallic_map", "texture", None, doc="metalness map (R channel, linear); multiplies metallic"),
    Field(
        "emissive",
        "color",
        (0.0, 0.0, 0.0),
        (0.0, 1.0e4),
        unit="linear RGB radiance",
        doc="light the surface emits (added to what it reflects; glTF emissiveFactor x emissive_strength); "
        "lights nothing else",
    ),
    Field("emissive_map", "texture", None, colorspace="srgb", doc="emission map (sRGB file); multiplies emissive"),
    Field(
        "alpha",
        "float",
        1.0,
        (0.0, 1.0),
        doc="opacity x the colour map's alpha channel x the vertex colour's alpha (glTF baseColorFactor[3]); "
        "read only when alpha_mode is mask or blend",
    ),
    Field(
        "alpha_mode",
        "choice",
        "opaque",
        choices=ALPHA_MODES,
        doc="opaque: alpha ignored; mask: a pixel with alpha < alpha_cutoff is not there (colour, shadows, the "
        "path-traced truth); blend: drawn after the opaque meshes, far to near, over them, casting no shadow "
        "(glTF alphaMode)",
    ),
    Field("alpha_cutoff", "float", 0.5, (0.0, 1.0), doc="the alpha below which a masked surface is cut away"),
    Field(
        "uv_offset",
        "vec2",
        (0.0, 0.0),
        (-1000.0, 1000.0),
        doc="texture transform (glTF KHR_texture_transform, in its UV convention, origin at the image's top-left): "
        "every map is read at uv_offset + R(uv_rotation) diag(uv_scale) uv; texture-space diffusion's layout keeps "
        "the mesh's own UVs",
    ),
    Field("uv_scale", "vec2", (1.0, 1.0), (-1000.0, 1000.0), doc="the texture transform's scale (see uv_offset)"),
    Field(
        "uv_rotation",
        "float",
        0.0,
        (-100.0, 100.0),
        unit="radians",
        doc="the texture transform's rotation of the UVs, counter-clockwise (see uv_offset)",
    ),
    Field(
        "diffuse_transmission",
        "float",
        0.0,
        (0.0, 1.0),
        doc="the share of the plain diffuse part sent through a thin surface to the other side, Lambertian "
        "(glTF KHR_materials_diffuse_transmission: leaves, paper, lash cards); light from behind shows through",
    ),
    Field(
        "diffuse_transmission_color",
        "color",
        (1.0, 1.0, 1.0),
        (0.0, 1.0),
        unit="linear RGB",
        doc="the colour of the light diffuse_transmission lets through",
    ),
    Field(
        "subsurface",
        "float",
        0.0,
        (0.0, 1.0),
        doc="weight of subsurface scattering against plain diffuse (Blender: Subsurface Weight)",
    ),
    Field(
        "subsurface_radius",
        "vec3",
        (1.0, 0.2, 0.1),
        (0.0, 1000.0),
        unit="mm",
        doc="artist radius R = 4 pi l per channel (l: mean free path), millimetres; Blender's Subsurface Radius "
        "x Subsurface Scale in mm",
    ),
    Field(
        "subsurface_map",
        "texture",
        None,
        doc="subsurface weight map (R channel, linear); multiplies subsurface per texel (every technique)",
    ),
    Field(
        "subsurface_radius_map",
        "texture",
        None,
        doc="subsurface radius scale map (R channel, linear): subsurface_radius x 2 R per texel (mid grey keeps "
        "it; ears and nostrils scatter further than the forehead); honoured by disk (per-pixel sample radius), "
        "tsd and exact (through the stretch map); ssss, tint and preintegrated keep one radius per material",
    ),
    Field(
        "subsurface_color",
        "color",
        (0.8, 0.4, 0.3),
        (0.0, 1.0),
        unit="linear RGB",
        doc="the subsurface albedo (OpenPBR's subsurface_color: the multiple-scattering albedo, the colour the "
        "scattering part shows from afar), x the colour map per texel; the medium's single-scattering albedo is "
        "inverted from it x the map's mean by photon beam diffusion at the material's index",
    ),
    Field(
        "subsurface_scatter_anisotropy",
        "float",
        0.0,
        (-0.95, 0.95),
        doc="the medium's Henyey-Greenstein g (OpenPBR's name): > 0 forward scattering. subsurface_color and "
        "subsurface_radius give the reduced (similarity) medium the diffusion uses, so g changes the "
        "single-scattering term (Jensen's phase) and the path-traced truth's phase and coefficients",
    ),
    Field(
        "sss_model",
        "choice",
        "burley",
        choices=SSS_MODELS,
        doc="diffusion profile for subsurface scattering (none: plain diffuse)",
    ),
)


# Other names users know for a parameter, each with exactly its meaning (OpenPBR Surface's subsurface set:
# docs/scenes.md; the rest of that set, the radius pair in scene units, is in skinlab/scene/openpbr.py).
PARAM_ALIASES: dict[str, str] = {"subsurface_weight": "subsurface"}


def canonical_names(values: Mapping[str, Any], where: str = "") -> dict[str, Any]:
    """`values` with aliases replaced by the parameter they name; both given is an error naming them."""
    out = dict(values)
    for alias, name in PARAM_ALIASES.items():
        if alias in out:
            if name in out:
                raise ValueError(f"{where}give {name} or its alias {alias}, not both")
            out[name] = out.pop(alias)
    return out


def preset_values(name: str) -> dict[str, Any]:
    """What ``preset = NAME`` sets (scene files, ``Material.apply_preset``, the viewer, ``--preset``): a
    Jensen et al. 2001 medium (skinlab/assets/presets/) as base and subsurface colour, radius,
    subsurface weight 1 and the specular of its index (:func:`medium_values`)."""
    from skinlab.scene.optics.media import preset

    return medium_values(preset(name))


@dataclass
class Material:
    """A principled material: a name and values for the declared parameters."""

    name: str = "default"
    values: dict[str, Any] = field(default_factory=dict)
    params: tuple[Field, ...] = PRINCIPLED_PARAMS

    def __post_init__(self) -> None:
        given = dict(self.values)
        self.values = {p.name: p.check(p.default) if p.default is not None else None for p in self.params}
        self.update(given)

    @property
    def param_map(self) -> dict[str, Field]:
        return {p.name: p for p in self.params}

    def update(self, values: Mapping[str, Any]) -> Material:
        """Set parameters (validated; errors name the material and parameter). ``"preset"`` first
        applies a measured medium (:meth:`apply_preset`), then the other values; aliases
        (``subsurface_weight``) name their parameter."""
        pm = self.param_map
        values = canonical_names(values, f"material {self.name!r}: ")
        if "preset" in values:
            self.apply_preset(values.pop("preset"))
        for k, v in values.items():
            if k not in pm:
                raise ValueError(f"material {self.name!r}: unknown parameter {k!r}; known: {', '.join(pm)}")
            self.values[k] = pm[k].check(v, f"material {self.name!r}: {k}")
        return self

    def apply_preset(self, name: str) -> Material:
        """Take a Jensen et al. 2001 medium by name (``"marble"``, ``"skin1"``): :func:`preset_values`."""
        if not isinstance(name, str):
            raise ValueError(f"material {self.name!r}: preset: expected a preset name (string), got {name!r}")
        try:
            values = preset_values(name)
        except ValueError as exc:
            raise ValueError(f"material {self.name!r}: preset: {str(exc).removeprefix('preset: ')}") from None
        return self.update(values)

    def __getitem__(self, name: str) -> Any:
        return self.values[name]

    def with_overrides(self, overrides: Mapping[str, Any], name: str | None = None) -> Material:
        m = Material(name or self.name, dict(self.values), self.params)
        return m.update(overrides)

    # -- what the renderer derives from the declaration -------------------------------
    def uniforms(self) -> dict[str, Any]:
        return {p.uniform: self.values[p.name] for p in self.params if p.kind in NUMERIC_KINDS}

    def textures(self) -> dict[str, tuple[Path, str]]:
        """sampler uniform -> (path, colorspace) for the maps that are set."""
        return {
            p.uniform: (self.values[p.name], p.colorspace)
            for p in self.params
            if p.kind == "texture" and self.values[p.name] is not None
        }

    def defines(self) -> dict[str, str]:
        """Shader-variant defines: ``HAS_<MAP>`` for the maps that are set and ``ALPHA_MASK`` /
        ``ALPHA_BLEND`` for the alpha mode (plain values are uniforms, so materials that differ only in
        values share a program)."""
        out = {p.define: "1" for p in self.params if p.kind == "texture" and self.values[p.name] is not None}
        if self.values.get("alpha_mode", "opaque") != "opaque":
            out["ALPHA_" + self.values["alpha_mode"].upper()] = "1"
        if self.values.get("diffuse_transmission", 0.0) > 0.0:
            out["DIFFUSE_TRANSMISSION"] = "1"
        if any(self.values.get(k, d) != d for k, d in (("uv_offset", (0.0, 0.0)), ("uv_scale", (1.0, 1.0)),
                                                          ("uv_rotation", 0.0))):  # fmt: skip
            out["UV_TRANSFORM"] = "1"
        return out

    @property
    def has_subsurface(self) -> bool:
        return (
            self.values["subsurface"] > 0
            and self.values["sss_model"] != "none"
            and max(self.values["subsurface_radius"]) > 0
        )


_GLSL_TYPES = {"float": "float", "color": "vec3", "vec3": "vec3", "vec2": "vec2"}


def glsl_material_uniforms(params: tuple[Field, ...] = PRINCIPLED_PARAMS) -> str:
    """The material uniform and sampler declarations (the virtual include ``skinlab/material.glsl``):
    ``uniform <type> u_<name>;`` per plain value and ``uniform sampler2D u_<map>;`` inside
    ``#ifdef HAS_<MAP>`` per texture. Choices are read on the CPU and declare nothing."""
    lines = ["// generated from skinlab/scene/materials.py (PRINCIPLED_PARAMS): the material's uniforms"]
    for p in params:
        if p.kind in _GLSL_TYPES:
            unit = f" ({p.unit})" if p.unit else ""
            lines.append(f"uniform {_GLSL_TYPES[p.kind]} {p.uniform};" + (f"  // {p.doc}{unit}" if p.doc else ""))
        elif p.kind == "texture":
            lines += [f"#ifdef {p.define}", f"uniform sampler2D {p.uniform};  // {p.doc}", "#endif"]
    return "\n".join(lines) + "\n"


def medium_values(medium) -> dict[str, Any]:
    """Principled-material values that reproduce a homogeneous medium (a Jensen 2001 preset, say):
    its diffuse surface albedo as base and subsurface colour, its artist radius (4 pi l, Blender's
    convention) as subsurface_radius, and the specular whose F0 matches its index of refraction
    (F0 = ((eta - 1)/(eta + 1))^2 = 0.08 specular). Values are clipped to the declared ranges."""
    albedo = np.clip(np.asarray(medium.surface_albedo(), np.float64), 0.0, 1.0)
    radius = np.clip(np.asarray(medium.artist_radius_mm, np.float64), 0.0, 1000.0)
    f0 = ((medium.eta - 1.0) / (medium.eta + 1.0)) ** 2
    return {
        "base_color": tuple(float(x) for x in albedo),
        "subsurface_color": tuple(float(x) for x in albedo),
        "subsurface_radius": tuple(float(x) for x in radius),
        "subsurface": 1.0,
        "specular": float(min(f0 / 0.08, 1.0)),
    }
