"""A Skinlab scene as a Mitsuba 3 scene for its volumetric path tracer (the image ground truth).

:func:`describe` turns the scene graph into a :class:`ReferenceDescription`: plain NumPy arrays and
plain dictionaries, no Mitsuba import, so the exporter is unit-tested without rendering.
:meth:`ReferenceDescription.to_mitsuba` builds the dictionary ``mitsuba.load_dict`` takes.

What the reference models (docs/ground-truth.md):
* every visible mesh node with its own vertex normals and UVs, in the reference frame: millimetres,
  centred on the bounds of the meshes that scatter (x_ref = (x_world - centre) mm_per_unit; the
  camera, lights and media follow). Mitsuba (float32) starts every ray that crosses a surface
  (1 + max|p|) 8.9e-5 scene units off it (``offset_p``, RayEpsilon = 1500 float epsilons): in metres
  that is 0.1 mm, a sixth of a dark medium's mean free path, and the camera ray that enters a null
  boundary skips that layer, so single scattering read 12-17 % dark (ketchup in metres against the
  same slab in millimetres, docs/ground-truth.md); in millimetres, centred, it is below 0.01 mm;
* the camera: same vertical field of view, position, orientation and aspect;
* directional lights with the same irradiance (Mitsuba ``directional`` ``irradiance``), point lights
  with the same intensity (Skinlab's falls off with the distance in metres: the Mitsuba intensity is
  multiplied by 1000^2 since the reference frame measures distances in millimetres);
* each subsurface material as a homogeneous medium inside its boundary, the medium Skinlab itself
  derives from the material (``skinlab.scene.optics.material_medium.material_medium``: subsurface_color is the surface
  albedo, subsurface_radius the artist radius R = 4 pi l, specular gives the index): reduced
  single-scattering albedo and reduced extinction 1/l per channel with an isotropic phase function
  (similarity theory, as the diffusion profiles assume), in 1/mm (the reference frame's unit); a
  material with subsurface_scatter_anisotropy g != 0 gets the real coefficients of that reduced medium
  and a Henyey-Greenstein phase of that g (skinlab/scene/optics/similarity.py);
  Mitsuba's RGB values must lie in [0, 1], so sigma_t is passed normalised, with ``scale``;
* the boundary: none at all (``null`` BSDF) where the material's index is 1 (specular 0), otherwise a
  rough dielectric with GGX alpha = roughness^2 (a smooth one below alpha 1e-3) and the index;
* materials without subsurface scattering as two-sided principled surfaces (base colour map baked
  with base_color; UVs flipped to Mitsuba's top-left origin); alpha_mode "mask" and "blend" inside
  Mitsuba's ``mask`` BSDF with the material's opacity (alpha x the colour map's alpha; cut at
  alpha_cutoff for "mask", as the frame discards: skinlab/render/alpha.py);
* ambient light as a constant environment of that radiance (Skinlab's ambient term is unshadowed,
  the environment is not);
* an environment map as Mitsuba's ``envmap`` of the same pixels (its bright sources included: the
  frame lights those as directional lights, the path tracer samples them from the map), turned about
  +Y by the same rotation (both use Mitsuba's axes, skinlab/scene/envmap.py) and scaled by the
  intensity; Mitsuba centres row j at theta = pi j / (H - 1), Skinlab at pi (j + 1/2) / H: the two
  differ by at most half a texel, at the poles;
* spot lights as Mitsuba's ``spot`` (the same intensity as a point light, ``cutoff_angle`` the outer
  half-angle, ``beam_width`` the inner: both fade linearly in angle between), area lights as shapes
  (``rectangle``, ``sphere``) with an ``area`` emitter of the same radiance and a black BSDF;
* optionally (``sun_deg`` > 0) each directional light as a distant disk of that angular diameter
  with the same irradiance, which BSDF sampling can hit (see ``docs/ground-truth.md``: delta lights
  behind a dielectric boundary).

Every way the reference differs from the realtime frame is listed in ``notes``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from skinlab.declare import Field
from skinlab.scene.graph import LightNode, MeshNode, Scene
from skinlab.scene.mesh_topology import boundary_loops, edge_report, weld
from skinlab.scene.optics.constants import MIN_MFP_MM
from skinlab.scene.optics.material_medium import eta_from_specular, material_medium
from skinlab.scene.optics.rough_dielectric import SMOOTH_ALPHA  # below it a smooth dielectric (rough one degenerates)
from skinlab.scene.optics.similarity import real_albedo, real_mfp

# the description and its Mitsuba objects live in a module that needs no scene (it runs where only
# numpy and Mitsuba are installed: a GPU machine rendering a saved description); re-exported here
from .description import ReferenceDescription, ShapeDesc, _rgb  # noqa: F401

# a mean free path is at least this (mm): a channel that does not scatter becomes a dense medium
# whose surface albedo is the colour (Mitsuba needs finite coefficients)
REFERENCE_MIN_MFP_MM = max(MIN_MFP_MM, 1e-3)


class ReferenceError(ValueError):
    """The scene cannot be represented for the reference renderer (the message names what)."""


# directional lights as distant disks (a ReferenceRequest's field and `skinlab reference --sun-deg`)
SUN_DEG = Field(
    "sun_deg",
    "float",
    0.0,
    (0.0, 10.0),
    unit="deg",
    doc="angular diameter of directional lights (0: a delta light as in the realtime frame; e.g. 0.53 for the sun: "
    "makes lights behind a dielectric boundary reachable by BSDF sampling)",
)


# -- the description -------------------------------------------------------------------------------


def medium_dict(values: dict, mm_per_unit: float = 1.0) -> dict[str, Any]:
    """The homogeneous medium of a subsurface material, coefficients in 1/unit for a frame of
    mm_per_unit millimetres per unit (the reference frame's: 1)."""
    m = material_medium(values)
    mfp = np.maximum(m.mfp_arr, REFERENCE_MIN_MFP_MM)
    albedo = np.clip(m.alpha_arr, 0.0, 1.0)
    phase: dict[str, Any] = {"type": "isotropic"}
    g = float(values.get("subsurface_scatter_anisotropy", 0.0))
    if g != 0.0:  # the real coefficients of the reduced medium (similarity), with its HG phase
        mfp, albedo = real_mfp(mfp, albedo, g), real_albedo(albedo, g)
        phase = {"type": "hg", "g": g}
    sigma_t = mm_per_unit / mfp  # 1/mm -> 1/scene-unit
    scale = float(sigma_t.max())
    return {
        "type": "homogeneous",
        "albedo": _rgb(albedo),
        "sigma_t": _rgb(sigma_t / scale),
        "scale": scale,
        "phase": phase,
    }


def boundary_bsdf(values: dict) -> dict:
    """Index 1 (specular 0): no interface; else a (rough) dielectric with the material's index."""
    eta = eta_from_specular(values["specular"])
    if eta <= 1.0:
        return {"type": "null"}
    alpha = float(values["roughness"]) ** 2
    if alpha < SMOOTH_ALPHA:
        return {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0}
    return {"type": "roughdielectric", "distribution": "ggx", "alpha": alpha, "int_ior": eta, "ext_ior": 1.0}


def surface_bsdf(values: dict, textured: bool) -> dict:
    inner = {
        "type": "principled",
        "roughness": float(values["roughness"]),
        "metallic": float(values["metallic"]),
        "specular": float(values["specular"]),
    }
    inner["base_color"] = {"type": "texture_ref"} if textured else _rgb(values["base_color"])
    return {"type": "twosided", "bsdf": inner}


def _world_geometry(node: MeshNode, origin: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Positions in the reference frame, (world - origin) * scale, computed in float64 before the
    float32 Mitsuba takes; unit normals (a uniform scale leaves them as they are)."""
    w = node.world_matrix
    p = (node.mesh.positions.astype(np.float64) @ w[:3, :3].T + w[:3, 3] - origin) * scale
    try:
        nm = np.linalg.inv(w[:3, :3]).T
    except np.linalg.LinAlgError:
        raise ReferenceError(f"mesh node {node.name!r}: its world transform is singular") from None
    n = node.mesh.normals.astype(np.float64) @ nm.T
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(ln > 0, n / np.where(ln > 0, ln, 1.0), np.array([0.0, 0.0, 1.0]))
    return p.astype(np.float32), n.astype(np.float32)


def close_holes(positions: np.ndarray, normals: np.ndarray, faces: np.ndarray):
    """A watertight copy for the medium: each boundary loop of the welded surface capped by a fan
    around its centroid, wound like the rest of the mesh. Returns (positions, normals, faces, loops
    closed). ValueError where the boundary does not form loops (mesh_topology.boundary_loops)."""
    loops = boundary_loops(weld(positions, faces).first_faces())
    if not loops:
        return positions, normals, faces, 0
    pos, nrm, tri = [positions], [normals], [faces]
    n = len(positions)
    for loop in loops:
        ring = positions[loop].astype(np.float64)
        c = ring.mean(axis=0)
        # the cap's outward normal: the loop runs in the cap's own winding
        area = np.cross(ring - c, np.roll(ring, -1, axis=0) - c).sum(axis=0)
        out = area / max(np.linalg.norm(area), 1e-30)
        pos.append(c[None].astype(np.float32))
        nrm.append(out[None].astype(np.float32))
        a = np.asarray(loop, np.int64)
        tri.append(np.column_stack([a, np.roll(a, -1), np.full(len(a), n)]).astype(np.uint32))
        n += 1
    return np.concatenate(pos), np.concatenate(nrm), np.concatenate(tri), len(loops)


def signed_volume(positions: np.ndarray, faces: np.ndarray) -> float:
    """Volume enclosed by a closed mesh, positive when its triangles wind counter-clockwise seen
    from outside."""
    p = positions.astype(np.float64)[faces]
    return float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6.0)


def _baked_base_color(values: dict) -> np.ndarray:
    from skinlab.scene.textures import load_texture

    tex = load_texture(values["base_color_map"], "srgb")[..., :3]
    if tex.shape[2] == 1:
        tex = np.repeat(tex, 3, axis=2)
    return (tex * np.asarray(values["base_color"], np.float32)).astype(np.float32)


def _opacity(values: dict) -> np.ndarray | float:
    """The surface's opacity: alpha x the colour map's alpha (a texture, row 0 at the top), or alpha."""
    alpha = float(values.get("alpha", 1.0))
    if values.get("base_color_map") is None:
        return alpha
    from skinlab.scene.textures import load_texture

    tex = load_texture(values["base_color_map"], "srgb")
    a = tex[..., 3] if tex.shape[2] == 4 else np.ones(tex.shape[:2], np.float32)
    return (a * alpha).astype(np.float32)


def _alpha_bsdf(values: dict, bsdf: dict, has_uv: bool) -> tuple[dict, np.ndarray | None]:
    """alpha_mode "mask": Mitsuba's mask BSDF with the opacity cut at alpha_cutoff (0 or 1, as the frame
    discards); "blend": the mask with the opacity itself (the frame's premultiplied blend). A texture
    (the colour map's alpha) needs UVs."""
    op = _opacity(values)
    if values["alpha_mode"] == "mask":
        op = (np.asarray(op) >= float(values["alpha_cutoff"])).astype(np.float32)
    if np.ndim(op) == 0 or not has_uv:
        return {"type": "mask", "opacity": float(np.mean(op)), "bsdf": bsdf}, None
    texture = np.ascontiguousarray(np.asarray(op)[..., None])
    return {"type": "mask", "opacity": {"type": "opacity_ref"}, "bsdf": bsdf}, texture


def _scatters(values: dict) -> bool:
    return values["subsurface"] > 0 and max(values["subsurface_radius"]) > 0


def frame_origin(scene: Scene) -> np.ndarray:
    """The world point at the reference frame's origin: the centre of the bounds of the meshes that
    scatter below their surface (the ray offset matters where rays enter a medium: it grows with the
    distance from the origin), of every mesh when none does."""
    nodes = [n for n in scene.mesh_nodes() if n.material is not None and _scatters(n.material.values)]
    nodes = nodes or list(scene.mesh_nodes())
    if not nodes:
        return np.zeros(3)
    p = np.concatenate([n.mesh.bound_corners() @ n.world_matrix[:3, :3].T + n.world_matrix[:3, 3] for n in nodes])
    return ((p.min(0) + p.max(0)) / 2).astype(np.float64).round(9)


def _camera_frame(scene: Scene, origin: np.ndarray, scale: float) -> np.ndarray:
    w = scene.active_camera().world_matrix
    x, y, z = (w[:3, i] / np.linalg.norm(w[:3, i]) for i in range(3))
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = -x, y, -z  # Skinlab looks down -Z, +X right
    m[:3, 3] = (w[:3, 3] - origin) * scale
    return m


def _emitter(
    light: LightNode, origin: np.ndarray, scale: float, sun_deg: float, radius: float, centre: np.ndarray
) -> dict:
    """The light in the reference frame (millimetres: `scale` mm per world unit, `origin` at 0);
    radius and centre of the scene's bounds in that frame."""
    rad = np.asarray(light.radiance, np.float64)
    if light.kind == "directional":
        d = light.direction
        if sun_deg > 0:
            # a disk facing the scene, far away, subtending sun_deg: radiance L with
            # irradiance E = L pi sin^2(theta/2) at normal incidence
            half = math.radians(sun_deg) / 2
            dist = 1000.0 * max(radius, 1e-6)
            return {
                "kind": "sun_disk",
                "centre": (centre - d * dist).tolist(),
                "normal": d.tolist(),
                "radius": dist * math.tan(half),
                "radiance": (rad / (math.pi * math.sin(half) ** 2)).tolist(),
                "light": light.name,
            }
        return {"kind": "directional", "direction": d.tolist(), "irradiance": rad.tolist(), "light": light.name}
    if light.kind == "point":
        metres = 1e-3  # Skinlab: E = I / d_m^2; Mitsuba: E = I / d_units^2, units of the frame (mm)
        return {
            "kind": "point",
            "position": ((np.asarray(light.world_position, np.float64) - origin) * scale).tolist(),
            "intensity": (rad / metres**2).tolist(),
            "light": light.name,
        }
    pos = ((np.asarray(light.world_position, np.float64) - origin) * scale).tolist()
    if light.kind == "spot":
        return {
            "kind": "spot",
            "position": pos,
            "direction": light.direction.tolist(),
            "intensity": (rad / 1e-6).tolist(),  # as a point light's: distances in mm
            "cutoff_deg": float(light.outer_deg),
            "beam_deg": float(light.inner_deg),
            "light": light.name,
        }
    if light.kind == "sphere":
        return {
            "kind": "sphere",
            "centre": pos,
            "radius": light.radius * scale,
            "radiance": rad.tolist(),
            "light": light.name,
        }
    if light.kind == "rect":
        ex, ey = light.half_extents()
        return {
            "kind": "rect",
            "centre": pos,
            "ex": (ex * scale).tolist(),
            "ey": (ey * scale).tolist(),
            "normal": light.direction.tolist(),
            "radiance": rad.tolist(),
            "light": light.name,
        }
    raise ReferenceError(f"light {light.name!r}: type {light.kind!r} has no reference equivalent")


def describe(
    scene: Scene,
    width: int,
    height: int,
    *,
    sun_deg: float = 0.0,
    max_depth: int = -1,
    rr_depth: int = 64,
    sss_override: str | None = None,
) -> ReferenceDescription:
    """The Mitsuba description of `scene` seen by its camera at width x height pixels."""
    if scene.camera is None:
        raise ReferenceError(f"scene {scene.name!r}: has no camera")
    try:
        SUN_DEG.check(sun_deg)
    except ValueError as exc:
        raise ReferenceError(str(exc)) from None
    notes: list[str] = []
    shapes: list[ShapeDesc] = []
    lo, hi = scene.world_bounds()
    origin = frame_origin(scene)
    scale = float(scene.mm_per_unit)  # the reference frame: millimetres, centred on the media
    for node in scene.mesh_nodes():
        mesh, mat = node.mesh, node.material
        if mesh is None or len(mesh.indices) == 0:
            raise ReferenceError(f"mesh node {node.name!r}: has no faces")
        values = dict(mat.values)
        if sss_override is not None:
            values["sss_model"] = sss_override
        pos, nrm = _world_geometry(node, origin, scale)
        uv = None if mesh.uvs is None else np.column_stack([mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]]).astype(np.float32)
        scatters = _scatters(values)
        if scatters:
            interior = medium_dict(values)
            faces = mesh.indices
            try:
                pos, nrm, faces, closed = close_holes(pos, nrm, faces)
            except ValueError:  # an open boundary that does not close (a fin, a non-manifold edge)
                closed = 0
                notes.append(f"{node.name}: the mesh's boundary does not form loops: its holes are left open")
            if closed:
                notes.append(f"{node.name}: {closed} hole(s) in the mesh capped so that the medium is closed")
                uv = None
            bad = edge_report(mesh).non_manifold
            if bad:  # three or more triangles on an edge: which side is inside is ambiguous there
                notes.append(
                    f"{node.name}: {bad} non-manifold edge(s): the medium's inside is ambiguous there (repair the mesh)"
                )
            if signed_volume(pos, faces) < 0:  # Mitsuba tells inside from outside by the winding
                faces = faces[:, ::-1].copy()
            bsdf = boundary_bsdf(values)
            if values["subsurface"] < 1:
                notes.append(
                    f"{node.name}: subsurface = {values['subsurface']:g} is rendered as a full medium "
                    "(the realtime frame mixes in plain diffuse)"
                )
            if values.get("base_color_map") is not None:
                notes.append(
                    f"{node.name}: base_color_map's mean colour is in the medium's albedo; its variation is not "
                    "(the reference medium is homogeneous)"
                )
            for key in ("normal_map", "roughness_map", "occlusion_map"):
                if values.get(key) is not None:
                    notes.append(f"{node.name}: {key} is ignored (the reference medium is homogeneous)")
            if values["metallic"] > 0:
                notes.append(f"{node.name}: metallic = {values['metallic']:g} is ignored inside a medium")
            if values["sss_model"] == "none":
                notes.append(
                    f"{node.name}: sss_model 'none' is a diffusion-profile choice of the realtime frame; "
                    "the reference renders the material's medium (the light transport the profile stands for)"
                )
            shapes.append(ShapeDesc(node.name, mat.name, pos, nrm, faces, uv, bsdf, interior))
        else:
            tex = None
            if values.get("base_color_map") is not None:
                if uv is None:
                    raise ReferenceError(f"mesh node {node.name!r}: base_color_map needs UVs, the mesh has none")
                tex = _baked_base_color(values)
            for key in ("normal_map", "roughness_map", "occlusion_map"):
                if values.get(key) is not None:
                    notes.append(f"{node.name}: {key} is not exported")
            bsdf, opacity = surface_bsdf(values, tex is not None), None
            if values.get("alpha_mode", "opaque") != "opaque":  # cut-outs and see-through surfaces
                bsdf, opacity = _alpha_bsdf(values, bsdf, uv is not None)
            shapes.append(
                ShapeDesc(node.name, mat.name, pos, nrm, mesh.indices, uv, bsdf, None, tex, opacity)
            )  # fmt: skip
    if not shapes:
        raise ReferenceError(f"scene {scene.name!r}: no visible mesh")
    radius = float(np.linalg.norm(np.asarray(hi) - np.asarray(lo)) / 2) * scale
    emitters = [_emitter(l, origin, scale, sun_deg, radius, np.zeros(3)) for l in scene.lights()]
    if any(l.is_area for l in scene.lights()):
        names = ", ".join(l.name for l in scene.lights() if l.is_area)
        notes.append(
            f"area lights ({names}) are shapes here (black, hidden from the camera) that also block light behind "
            "them; in the frame they block nothing"
        )
    if any(not l.cast_shadow for l in scene.lights()):
        names = ", ".join(l.name for l in scene.lights() if not l.cast_shadow)
        notes.append(f"lights without cast_shadow ({names}) are unshadowed in the realtime frame, shadowed here")
    amb = np.asarray(scene.environment.ambient, np.float64)
    if (amb > 0).any():
        emitters.append({"kind": "constant", "radiance": amb.tolist()})
        notes.append("ambient: a constant environment here (shadowed, seen through the medium); unshadowed in Skinlab")
    environment = _environment_emitter(scene, emitters, notes)
    if not emitters:  # an all-black map (or one at intensity 0) is said, as the reason
        black = [n for n in notes if n.startswith("environment map") and "black" in n]
        raise ReferenceError(
            f"scene {scene.name!r}: no light (and no ambient): the reference would be black"
            + "".join(f"; {n}" for n in black)
        )
    cam = scene.camera
    return ReferenceDescription(
        width=int(width),
        height=int(height),
        camera_to_world=_camera_frame(scene, origin, scale),
        fov_y_deg=math.degrees(cam.yfov),
        near=cam.znear * scale,
        far=cam.zfar * scale,
        shapes=shapes,
        emitters=emitters,
        # volpathmis: spectral MIS between the colour channels' free-flight distributions (Miller et al.
        # 2019). Plain volpath weights a path by the pdf of the one channel it sampled; with channels of
        # different extinction (every skin and milk) its estimate is so heavy-tailed that it reads 30 %
        # low at thousands of samples (docs/ground-truth.md: the index-matched slab against Chandrasekhar).
        # hide_emitters: the environment is not drawn behind the object (alpha = coverage, as Skinlab's)
        integrator={
            "type": "volpathmis",
            "max_depth": int(max_depth),
            "rr_depth": int(rr_depth),
            "hide_emitters": True,
        },
        notes=notes,
        frame_origin=origin,
        frame_scale=scale,
        environment=environment,
    )


def _environment_emitter(scene: Scene, emitters: list, notes: list) -> np.ndarray | None:
    """The scene's environment map as an ``envmap`` emitter (appended); its pixels, or None."""
    from skinlab.scene.envmap import check_settings, load_pixels, map_key

    env = scene.environment
    if env.map is None:
        return None
    check_settings("[environment]", env.rotation_deg, env.intensity)
    pixels, negative = load_pixels(env.map)
    if env.intensity == 0 or not (pixels > 0).any():
        notes.append(f"environment map {Path(env.map).name}: black (or at intensity 0): no light from it")
        return None
    emitters.append(
        {
            "kind": "envmap",
            "map": Path(env.map).name,
            "key": map_key(env.map),
            "rotation_deg": float(env.rotation_deg),
            "scale": float(env.intensity),
        }
    )
    notes.append(
        "environment map: the map as Mitsuba's envmap, its bright sources sampled from it; the frame lights them "
        "as directional lights with soft shadow maps and the rest by an irradiance map (diffuse) and prefiltered "
        "levels (specular)"
    )
    if negative:
        notes.append(f"environment map: {negative} negative texel(s) read as 0 in both renderers")
    return pixels
