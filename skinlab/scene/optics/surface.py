"""NumPy twins of skinlab/shaders/lib/surface.glsl: the surface inputs a glTF material brings beyond the
principled BRDF (occlusion strength, opacity and its mask, the texture transform, diffuse transmission),
and the map-free parts of lib/material_sample.glsl and lib/surface_inputs.glsl.
Same names, same clamps."""

from __future__ import annotations

import numpy as np


def occlusion_at_strength(map_r, strength):
    """1 + strength (map - 1): glTF's occlusionTexture.strength (0: no occlusion, 1: the map)."""
    return 1.0 + np.clip(strength, 0.0, 1.0) * (np.clip(map_r, 0.0, 1.0) - 1.0)


def surface_alpha(alpha, map_a, vertex_a):
    """Opacity: the material's alpha x the colour map's alpha x the vertex colour's alpha, in [0, 1]."""
    return np.clip(np.asarray(alpha, np.float64) * map_a * vertex_a, 0.0, 1.0)


def alpha_kept(a, cutoff):
    """A masked surface is there where its opacity reaches the cutoff (glTF alphaMode MASK)."""
    return np.asarray(a) >= cutoff


def texture_transform(uv, offset, scale, rotation):
    """glTF KHR_texture_transform of OpenGL-convention uvs (..., 2): in glTF's convention g = (u, 1 - v),
    g' = offset + R S g, R = [[cos, sin], [-sin, cos]], S = diag(scale); back as (g'_u, 1 - g'_v)."""
    uv = np.asarray(uv, np.float64)
    g = np.stack([uv[..., 0], 1.0 - uv[..., 1]], axis=-1) * np.asarray(scale, np.float64)
    c, s = np.cos(rotation), np.sin(rotation)
    t = np.asarray(offset, np.float64) + np.stack([c * g[..., 0] + s * g[..., 1], -s * g[..., 0] + c * g[..., 1]], -1)
    return np.stack([t[..., 0], 1.0 - t[..., 1]], axis=-1)


def diffuse_transmission_btdf(NoL, weight, colour):
    """The Lambertian BTDF of glTF KHR_materials_diffuse_transmission: colour x weight / pi for light from
    the other side (NoL < 0), else 0; (..., 3)."""
    NoL = np.asarray(NoL, np.float64)[..., None]
    w = np.clip(np.asarray(weight, np.float64), 0.0, 1.0)[..., None] if np.ndim(weight) else np.clip(weight, 0, 1)
    return np.where(NoL < 0.0, np.asarray(colour, np.float64) * w / np.pi, 0.0)


def material_sample(values, vertex_color):
    """NumPy twin of lib/material_sample.glsl material_sample for a material without maps and without
    a texture transform: `values` the material's plain values (base_color, subsurface_color, alpha,
    roughness, metallic), `vertex_color` (..., 4). A dict of the struct's fields."""
    c = np.asarray(vertex_color, np.float64)
    return {
        "base": np.asarray(values["base_color"], np.float64) * c[..., :3],
        "sss_albedo": np.asarray(values["subsurface_color"], np.float64) * c[..., :3],
        "alpha": surface_alpha(values["alpha"], 1.0, c[..., 3]),
        "roughness": np.full(c.shape[:-1], float(values["roughness"])),
        "metallic": np.full(c.shape[:-1], float(values["metallic"])),
        "occlusion": np.ones(c.shape[:-1]),
    }


def surface_inputs(world, normal, tangent, camera, front):
    """NumPy twin of lib/surface_inputs.glsl surface_inputs' geometry for a material without a normal
    map: the geometric normal turned to the side seen (`front` False: a back face), the tangent turned
    with it, the view direction and dot(n, v). Arrays (..., 3) ((..., 4) for the tangent)."""
    world, camera = np.asarray(world, np.float64), np.asarray(camera, np.float64)
    side = np.where(np.asarray(front), 1.0, -1.0)[..., None]
    ng = np.asarray(normal, np.float64)
    ng = ng / np.linalg.norm(ng, axis=-1, keepdims=True) * side
    v = camera - world
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    t = np.asarray(tangent, np.float64)
    tangent_seen = np.concatenate([t[..., :3] * side, t[..., 3:]], axis=-1)
    return {"ng": ng, "n": ng, "tangent": tangent_seen, "v": v, "NoV": (ng * v).sum(-1)}
