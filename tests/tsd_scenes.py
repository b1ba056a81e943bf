"""Small scenes for texture-space diffusion tests: a flat square slab of skin-like material seen
straight from above by a far, narrow camera (nearly orthographic), lit by a directional light."""

from __future__ import annotations

import math

import numpy as np

from skinlab.scene import transform as tf
from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.mesh import Mesh
from skinlab.scene.primitives import box_mesh


def quad_mesh(name, x0, x1, y0, y1, z=0.0, uv=((0, 0), (1, 1))) -> Mesh:
    """A quad in the plane z; it faces +z, or -z where the corners run the other way (x0 > x1 or
    y0 > y1, not both): its normals follow its winding."""
    (u0, v0), (u1, v1) = uv
    pos = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], np.float32)
    uvs = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]], np.float32)
    facing = 1.0 if (x1 - x0) * (y1 - y0) >= 0 else -1.0
    normals = np.tile([0, 0, facing], (4, 1))
    return Mesh(name, pos, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), normals=normals, uvs=uvs)


def skin(model="burley", radius=(8.0, 4.0, 2.0), color=(0.8, 0.6, 0.5), base=(1.0, 1.0, 1.0), **kw) -> Material:
    return Material(
        "slab",
        {
            "base_color": base,
            "subsurface": 1.0,
            "subsurface_radius": radius,
            "subsurface_color": color,
            "sss_model": model,
            "roughness": 0.5,
            "specular": 0.0,
            **kw,
        },
    )


def light_from(direction, intensity=1.0, shadow=False) -> LightNode:
    d = np.asarray(direction, np.float64)
    d /= np.linalg.norm(d)
    l = LightNode("sun", "directional", intensity=intensity, cast_shadow=shadow)
    l.rotation = tf.look_at_rotation(np.zeros(3), d)
    return l


def slab_scene(
    half=1.0, mm_per_unit=20.0, material=None, light_dir=(0, 0, -1), occluder=False, mesh=None, ambient=0.0
) -> Scene:
    """A 2 half x 2 half slab in z = 0 (UVs fill [0, 1]^2). occluder: an opaque plane at height
    half covering x < -half (outside the camera's view) that, with light travelling along (1, 0, -1),
    casts a shadow edge across x = 0."""
    s = Scene("slab", mm_per_unit)
    s.environment.ambient = np.full(3, ambient)
    s.add(MeshNode("slab", mesh or quad_mesh("slab", -half, half, -half, half), material or skin()))
    if occluder:
        h = half * 1.02
        s.add(
            MeshNode(
                "occluder",
                quad_mesh("occluder", -3 * half, -h, -1.2 * half, 1.2 * half, z=h),
                Material("black", {"base_color": (0, 0, 0), "specular": 0.0}),
            )
        )
        light_dir = (1.0, 0.0, -1.0)
    s.add(light_from(light_dir, shadow=occluder))
    dist = half / np.tan(np.radians(1.0))
    cam = CameraNode("cam", yfov=np.radians(2.0), znear=0.5 * dist, zfar=2.0 * dist)
    cam.look_at((0, 0, dist), (0, 0, 0))
    s.add(cam)
    return s


def pixel_x(width: int, half: float) -> np.ndarray:
    """World x of each pixel column's centre in slab_scene's view (the view spans exactly [-half, half])."""
    return ((np.arange(width) + 0.5) / width * 2.0 - 1.0) * half


def exact_profile(model, medium):
    """The exact radial profile of a material's sss_model (R(r_mm) -> (N, 3))."""
    from skinlab.scene.optics.profile_fit import MODEL_PROFILES
    from skinlab.scene.optics.profiles import get_profile

    return lambda r: get_profile(MODEL_PROFILES[model]).evaluate(np.asarray(r, np.float64), medium)


def entry_ramp_mm(scene: Scene, grid_mm: float, node: str = "slab", averaged: bool = False):
    """Where the light feeding the diffusion of slab_scene entered, spread as the frame spreads it
    (skinlab/scene/optics/oblique.py entry_ramp_weights; lib/surface_inputs.glsl sss_entry_ramp): the
    three lookups' shifts along +x (mm, (3,); rounded to whole cells of grid_mm unless averaged: the
    light sampled at the cells' centres, whose boundaries fall on x = 0, moves the sampled edge by whole
    cells; averaged over each cell, the texture-space irradiance's texels, by the shift itself) and their
    weights per channel (3 channels, 3 lookups)."""
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.optics.oblique import (
        entry_diffusion_k,
        entry_offset,
        entry_ramp_means,
        entry_ramp_nodes,
        entry_ramp_weights,
    )

    medium = material_medium(scene.find(node).material.values)
    z0 = np.asarray(medium.mfp_arr)
    to_light = -scene.lights()[0].direction
    b = float(-entry_offset(np.array([[0.0, 0.0, 1.0]]), to_light[None], z0, medium.eta, 1.0)[0][0])
    m = entry_ramp_means(z0, entry_diffusion_k(medium.alpha_arr, float(to_light[2]), medium.eta))
    shifts = entry_ramp_nodes(m) * b
    if not averaged:
        shifts = np.round(shifts / grid_mm) * grid_mm
    return shifts, entry_ramp_weights(m)


def entered(response, x_mm, scene: Scene, grid_mm: float, node: str = "slab", averaged: bool = False):
    """An edge response of the light that left at x_mm (pixel positions, mm; response(x) -> (N, 3) with
    x measured from where the light entered), summed over entry_ramp_mm's lookups with their weights."""
    shifts, w = entry_ramp_mm(scene, grid_mm, node, averaged)
    return sum(w[None, :, k] * response(np.asarray(x_mm) - shifts[k]) for k in range(3))


def sky_slab(color, mfp=(1.0, 1.0, 1.0)) -> Scene:
    """A slab many mean free paths wide and deep (index-matched) under a uniform sky of radiance 1,
    seen straight from above through a narrow camera (the path tracers' flat-medium tests)."""
    s = Scene("sky-slab", 1.0)
    s.environment.ambient = np.ones(3)
    mat = skin(radius=tuple(4 * math.pi * l for l in mfp), color=color, specular=0.0)
    s.add(MeshNode("slab", box_mesh((800.0, 800.0, 400.0)), mat, translation=(0.0, 0.0, -200.0)))
    cam = CameraNode("cam", yfov=math.radians(2.0), znear=100.0, zfar=3000.0)
    cam.look_at((0.0, 0.0, 1000.0), (0.0, 0.0, 0.0))
    s.add(cam)
    return s


# Three directional lights around the 3 mm back-lit slab (reference/slab-thin-backlit-skin1.toml): the
# direction each travels, its intensity, whether it casts a shadow. "back" reaches the camera only through
# the slab. For the tests that the lights' order and shadow slots do not change a frame.
SLAB_LIGHTS = {
    "back": ((0.5, 0.0, 0.866), 3.0, True),
    "key": ((0.3, 0.2, -1.0), 1.0, True),
    "fill": ((-0.4, -0.1, -1.0), 0.5, False),
}


def backlit_slab_with(names) -> Scene:
    """The back-lit slab's reference scene with its own light hidden and SLAB_LIGHTS' `names` added in
    that order (the shadow-casting ones take the shadow slots in that order)."""
    from skinlab.resources import assets_root
    from skinlab.scene.scenefile import load_scene

    s = load_scene(assets_root() / "scenes" / "reference" / "slab-thin-backlit-skin1.toml")
    for node in s.lights():
        node.visible = False
    for n in names:
        d, intensity, shadow = SLAB_LIGHTS[n]
        d = np.asarray(d, np.float64) / np.linalg.norm(d)
        light = LightNode(n, "directional", color=(1.0, 0.9, 0.8), intensity=intensity, cast_shadow=shadow)
        light.rotation = tf.look_at_rotation(np.zeros(3), d)
        s.add(light)
    return s
