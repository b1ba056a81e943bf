"""A Skinlab scene as a Blender scene (the EEVEE and Cycles peers of `skinlab bench accuracy --blender`),
as plain data: no bpy here. ``skinlab/bench/blender_child.py`` builds it with bpy in a child process.

The Blender scene is the path-traced truth's scene (``skinlab.truth.export.describe``): the same
meshes in the same reference frame (millimetres, centred on the media; holes capped so each medium is
closed; vertex normals and UVs), the same camera, the same lights, and each subsurface material as the
same homogeneous medium, written as a Principled BSDF. What each Blender input is and why
(docs/ground-truth.md "Blender as a peer and a second truth"; Cycles' code: docs/references.md#cycles-random-walk):

* units: one Blender unit is one millimetre (the reference frame's unit), so the subsurface radii
  are in millimetres as in Skinlab's materials;
* directional light: a Sun of strength = the irradiance on a surface facing it (W/m^2; checked
  numerically: a Lambertian plane of albedo 0.5 under strength 1 reads 0.5/pi in Cycles and
  EEVEE, ``tests/bench/test_blender_peer.py``), angle 0 (a delta light, as Skinlab's);
* point light: a Point of power P = 4 pi I (W) and radius 0, so that E = P / (4 pi d^2) = I / d^2
  with I the truth's intensity in the millimetre frame (Skinlab's intensity x 1000^2);
* spot light: a Spot of the same power as that point light, P = 4 pi I (Blender states a spot's power
  as a point light's that shines in every direction: the cone cuts light off, it does not concentrate
  it), ``spot_size`` = 2 x the outer half-angle and ``spot_blend`` = (cos inner - cos outer) /
  (1 - cos outer): Cycles' ``spot_light_attenuation`` is smoothstep((cos theta - cos outer) /
  (blend (1 - cos outer))), so full light within the inner half-angle and none past the outer, as
  Mitsuba's ``spot``; between them a smoothstep in cos theta, not Mitsuba's ramp linear in theta
  (:func:`spot_falloffs` gives both: for the default cone, 30 and 45 degrees, they differ by up to
  0.13 of the full light at 34 degrees and Blender's spot emits 2.2 % more power than Mitsuba's; no
  reference scene has a spot);
* rect light: an Area light, shape RECTANGLE, ``size`` x ``size_y`` the rect's width and height, its
  local -Z the way it shines (one-sided, as the truth's), power P = pi A L for radiance L over area A
  (Cycles' area light evaluates L = P / (pi A): ``eval_fac = M_1_PI_F * invarea``, light/area.h);
* sphere light: a Point of radius r (``shadow_soft_size``, soft falloff off), power P = 4 pi^2 r^2 L
  (a sphere of radiance L emits pi L per unit area over 4 pi r^2; Cycles' point light of radius r
  evaluates P / (4 pi) / (pi r^2)). Not a sphere mesh with an Emission shader, which would carry the
  radiance exactly: EEVEE takes no light from emitting meshes (only its light objects and the world),
  and the peers must light both engines alike. The truth's sphere is also a shape that blocks light;
  Blender's point of radius blocks none (keep it away from the objects' far side, as docs/lights.md
  asks of the truth's);
* ambient: the world's background colour (strength 1), hidden from the camera (film transparent);
* environment map: the World's Environment Texture (equirectangular, linear, the map's pixels), its
  Background's Strength the map's intensity; its vector the world direction turned by a Mapping node
  (type VECTOR, Euler XYZ) onto Blender's axes: Cycles reads direction b at u = 0.5 - atan2(b.y, b.x) /
  2 pi, v = acos(b.z) / pi from the top (``direction_to_equirectangular``, kernel/camera/projection.h),
  Mitsuba and Skinlab read m at u = atan2(m.x, -m.z) / 2 pi, v = acos(m.y) / pi from the top
  (skinlab/scene/envmap.py), so b = (m.z, m.x, m.y) with m = R_y(-rotation) w (:func:`environment_matrix`;
  the Blender scene keeps the truth's Y-up frame, so Blender's world Z is the frame's Z);
* a subsurface material: ``Subsurface Weight`` 1; the medium's mean free path per channel l =
  1/sigma_t' (the truth's, after its clamp) as Cycles' random walk reads it: ``Subsurface Radius``
  x ``Subsurface Scale`` = 4 pi l (Cycles' ``bssrdf_setup_radius`` multiplies by 1/(4 pi) and takes
  sigma_t = 1 / that); ``Base Color`` = the surface albedo A for which Cycles' albedo remap
  (``subsurface_random_walk_remap``, Chiang et al. 2016's fit) gives the medium's single-scattering
  albedo alpha: :func:`cycles_base_color` inverts :func:`cycles_rw_alpha`; for Random Walk (Skin),
  whose radius Cycles first multiplies by sqrt(3 (1 - alpha'_dipole(A, ior))), the radius is divided
  by that (:func:`cycles_skin_radius`), so both methods walk the truth's medium;
  ``Subsurface Anisotropy`` the medium's Henyey-Greenstein g where the material has one (the truth then
  holds the real coefficients; the radius is 4 pi / (sigma_t (1 - g)), since Cycles walks
  sigma_t = 1 / (d (1 - g))), else 0 (the reduced, isotropic medium);
  ``IOR`` the material's index (1 and ``Specular IOR Level`` 0 where it is index-matched: no
  specular layer), ``Subsurface IOR`` the index clamped as Cycles clamps it, [1.01, 3.8];
  ``Roughness``, the material's;
* a surface without subsurface scattering: a Principled BSDF with its base colour (map baked),
  roughness, metallic, IOR from its specular.

EEVEE renders the same materials: it reads ``Base Color`` as the surface albedo of its diffusion
profile and the radius as its scattering distance, so the medium mapping above is also what an
EEVEE user matching this medium would type.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

FOUR_PI = 4.0 * math.pi
SSS_IOR_RANGE = (1.01, 3.8)  # Cycles' bssrdf_setup clamps the subsurface index to this
CYCLES_MIN_ALPHA = 0.2  # Cycles raises a lower single-scattering albedo to this, scaling the path's weight
CYCLES_MAX_ALPHA = 0.999999  # and clamps a higher one
CYCLES_MAX_G = 0.9  # bssrdf_setup clamps the anisotropy to [0, 0.9]
CYCLES_WALK_BOUNCES = 256  # BSSRDF_MAX_BOUNCES: a walk still inside after this many scatterings is dropped


# -- Cycles' random-walk parameterisation (numerics of intern/cycles/kernel, re-derived here) -------------------


def _remap_coefficients(g: float):
    """The g-polynomials of Cycles' albedo remap (subsurface_random_walk_remap; for g = 0 the
    constants of Chiang et al. 2016's fit)."""
    g2, g3, g4, g5, g6, g7 = (g**k for k in range(2, 8))
    A = (
        1.8260523782
        - 1.28451056436 * g
        - 1.79904629312 * g2
        + 9.19393289202 * g3
        - 22.8215585862 * g4
        + 32.0234874259 * g5
        - 23.6264803333 * g6
        + 7.21067002658 * g7
    )
    B = 4.98511194385 + 0.127355959438 * math.exp(
        31.1491581433 * g
        - 201.847017512 * g2
        + 841.576016723 * g3
        - 2018.09288505 * g4
        + 2731.71560286 * g5
        - 1935.41424244 * g6
        + 559.009054474 * g7
    )
    C = (
        1.09686102424
        - 0.394704063468 * g
        + 1.05258115941 * g2
        - 8.83963712726 * g3
        + 28.8643230661 * g4
        - 46.8802913581 * g5
        + 38.5402837518 * g6
        - 12.7181042538 * g7
    )
    D = (
        0.496310210422
        + 0.360146581622 * g
        - 2.15139309747 * g2
        + 17.8896899217 * g3
        - 55.2984010333 * g4
        + 82.065982243 * g5
        - 58.5106008578 * g6
        + 15.8478295021 * g7
    )
    E = 4.23190299701 + 0.00310603949088 * math.exp(
        76.7316253952 * g
        - 594.356773233 * g2
        + 2448.8834203 * g3
        - 5576.68528998 * g4
        + 7116.60171912 * g5
        - 4763.54467887 * g6
        + 1303.5318055 * g7
    )
    F = (
        2.40602999408
        - 2.51814844609 * g
        + 9.18494908356 * g2
        - 79.2191708682 * g3
        + 259.082868209 * g4
        - 403.613804597 * g5
        + 302.85712436 * g6
        - 87.4370473567 * g7
    )
    return A, B, C, D, E, F


def cycles_rw_alpha(albedo, g: float = 0.0) -> np.ndarray:
    """The single-scattering albedo Cycles' random walk gives a surface albedo (Base Color) A:
    (1 - A^1/4) a atan(b A)^c + A^1/4 d atan(e A)^f, clamped to [0, 0.999999] (before its 0.2 floor)."""
    A = np.clip(np.asarray(albedo, np.float64), 0.0, 1.0)
    a, b, c, d, e, f = _remap_coefficients(float(g))
    blend = A**0.25
    alpha = (1.0 - blend) * a * np.arctan(b * A) ** c + blend * d * np.arctan(e * A) ** f
    return np.clip(alpha, 0.0, CYCLES_MAX_ALPHA)


def cycles_base_color(alpha, g: float = 0.0) -> np.ndarray:
    """The Base Color for which Cycles' remap gives single-scattering albedo `alpha` (the inverse of
    :func:`cycles_rw_alpha`, which rises monotonically from 0 at A = 0; by bisection, to 1e-12)."""
    target = np.clip(np.asarray(alpha, np.float64), 0.0, CYCLES_MAX_ALPHA)
    lo, hi = np.zeros_like(target), np.ones_like(target)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = cycles_rw_alpha(mid, g) < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def dipole_rd(alpha_prime, fourthird_a):
    """The classical dipole's diffuse reflectance of reduced albedo alpha' with A = fourthird_a / (4/3)
    (Cycles' bssrdf_dipole_compute_Rd)."""
    s = np.sqrt(3.0 * (1.0 - alpha_prime))
    return 0.5 * alpha_prime * (1.0 + np.exp(-fourthird_a * s)) * np.exp(-s)


def cycles_dipole_alpha_prime(rd, eta: float) -> np.ndarray:
    """Cycles' bssrdf_dipole_compute_alpha_prime: the reduced albedo whose classical dipole
    reflectance (Jensen's F_dr fit at index eta) is rd, by its 12-step bisection (the same steps,
    so the same value: 1 - alpha' is what the skin radius scales with)."""
    rd = np.asarray(rd, np.float64)
    inv = 1.0 / eta
    f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * eta
    k = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr)
    x0, x1 = np.zeros_like(rd), np.ones_like(rd)
    mid = 0.5 * (x0 + x1)
    for _ in range(12):
        mid = 0.5 * (x0 + x1)
        below = dipole_rd(mid, k) < rd
        x0, x1 = np.where(below, mid, x0), np.where(below, x1, mid)
    return np.where(rd < 1e-4, 0.0, np.where(rd >= 0.995, 0.999999, mid))


def clamp_sss_ior(eta: float) -> float:
    return float(min(max(eta, SSS_IOR_RANGE[0]), SSS_IOR_RANGE[1]))


def cycles_skin_radius(mfp, base_color, eta: float) -> np.ndarray:
    """The Subsurface Radius (x Scale) for which Random Walk (Skin) walks mean free path `mfp`: Cycles
    multiplies the radius by sqrt(3 (1 - alpha'_dipole(Base Color, ior))) and takes sigma_t' = 1 / it."""
    ap = cycles_dipole_alpha_prime(base_color, clamp_sss_ior(eta))
    return np.asarray(mfp, np.float64) / np.sqrt(3.0 * (1.0 - ap))


def sun_strength(irradiance) -> tuple[list[float], float]:
    """(colour, strength) of a Sun with this RGB irradiance (W/m^2 on a surface facing it)."""
    e = np.asarray(irradiance, np.float64)
    s = float(e.max())
    return ([1.0, 1.0, 1.0] if s <= 0 else (e / s).tolist()), s


def point_power(intensity) -> tuple[list[float], float]:
    """(colour, power W) of a Point light of this RGB radiant intensity (W/sr, in the frame's units):
    Blender's point of power P has intensity P / (4 pi)."""
    col, s = sun_strength(intensity)
    return col, FOUR_PI * s


def area_power(radiance, area: float) -> tuple[list[float], float]:
    """(colour, power W) of a one-sided Area light of this RGB radiance and area: P = pi A L."""
    col, s = sun_strength(radiance)
    return col, math.pi * float(area) * s


def sphere_power(radiance, radius: float) -> tuple[list[float], float]:
    """(colour, power W) of a Point light of radius r with this RGB radiance: P = 4 pi^2 r^2 L."""
    col, s = sun_strength(radiance)
    return col, FOUR_PI * math.pi * float(radius) ** 2 * s


def spot_blend(inner_deg: float, outer_deg: float) -> float:
    """Blender's ``spot_blend`` for a cone full within `inner_deg` and dark past `outer_deg`: the
    fraction of 1 - cos(outer) over which Cycles' smoothstep rises."""
    co = math.cos(math.radians(outer_deg))
    if co >= 1.0:
        return 0.0
    return float(min(max((math.cos(math.radians(inner_deg)) - co) / (1.0 - co), 0.0), 1.0))


def spot_falloffs(theta_deg, inner_deg: float, outer_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(Mitsuba's, Blender's) spot falloff at angles `theta_deg` from the axis: Mitsuba's linear in
    the angle from outer to inner; Blender's smoothstep((cos theta - cos outer) / (blend (1 - cos outer)))."""
    t = np.asarray(theta_deg, np.float64)
    width = outer_deg - inner_deg
    if width > 0:
        mitsuba = np.clip((outer_deg - t) / width, 0.0, 1.0)
    else:
        mitsuba = (t <= outer_deg).astype(np.float64)
    co = math.cos(math.radians(outer_deg))
    blend = spot_blend(inner_deg, outer_deg)
    x = np.cos(np.radians(t)) - co
    if blend > 0:
        x = np.clip(x / (blend * (1.0 - co)), 0.0, 1.0)
        blender = x * x * (3.0 - 2.0 * x)
    else:
        blender = (x > 0).astype(np.float64)
    return mitsuba, blender


# Blender's world axes from the frame's: b = (m.z, m.x, m.y) (a cyclic permutation: a rotation)
_MITSUBA_TO_BLENDER_ENV = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def environment_matrix(rotation_deg: float) -> np.ndarray:
    """(3, 3) M with b = M w: the direction Blender's Environment Texture must read for world
    direction w so that it finds the texel Mitsuba's envmap (turned by rotation_deg about +Y) finds."""
    from skinlab.scene.envmap import rotation_y

    return _MITSUBA_TO_BLENDER_ENV @ rotation_y(rotation_deg).T


def euler_xyz(m) -> list[float]:
    """Euler angles (radians, Blender's XYZ order: R = Rz Ry Rx) of the rotation matrix m."""
    m = np.asarray(m, np.float64)
    sy = -float(np.clip(m[2, 0], -1.0, 1.0))
    y = math.asin(sy)
    if abs(sy) < 1.0 - 1e-9:
        x = math.atan2(m[2, 1], m[2, 2])
        z = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: put it all in x
        z = 0.0  # then m[0, 1], m[0, 2] = sin(y) (sin x, cos x)
        x = math.atan2(m[0, 1], m[0, 2]) if sy > 0 else math.atan2(-m[0, 1], -m[0, 2])
    return [x, y, z]


def euler_matrix(e) -> np.ndarray:
    """Rz Ry Rx of Euler angles (x, y, z) (Cycles' euler_to_transform, util/transform.h)."""
    cx, cy, cz = (math.cos(a) for a in e)
    sx, sy, sz = (math.sin(a) for a in e)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


# -- the scene as data ---------------------------------------------------------------------------------------


@dataclass
class BlenderObject:
    name: str
    positions: np.ndarray  # (N, 3) float32, Blender units (mm)
    normals: np.ndarray  # (N, 3) float32
    faces: np.ndarray  # (M, 3) uint32, counter-clockwise seen from outside
    uvs: np.ndarray | None  # (N, 2) float32, Blender's convention (v = 0 at the image's bottom)
    material: dict  # {"name", "inputs": {socket: value}, "subsurface": {method: {socket: value}} | None}
    texture: np.ndarray | None = None  # linear RGB (H, W, 3), row 0 at the top, for "Base Color"


@dataclass
class BlenderSpec:
    width: int
    height: int
    camera: dict  # {"matrix": 4x4 camera to world (looks down -Z, +Y up), "fov_y_deg", "clip": [near, far]}
    lights: list[dict]  # {"name", "type": SUN | POINT | SPOT | AREA, "matrix", "color", "strength", "angle", ...}
    world: list[float] | None  # background radiance (ambient), or None
    objects: list[BlenderObject]
    notes: list[str] = field(default_factory=list)
    # the environment map: {"strength", "rotation_euler", "matrix"} and its pixels (H, W, 3), row 0 at the top
    environment: dict | None = None
    environment_pixels: np.ndarray | None = None

    def header(self) -> dict:
        return {
            "width": self.width,
            "height": self.height,
            "camera": self.camera,
            "lights": self.lights,
            "world": self.world,
            "environment": self.environment,
            "notes": self.notes,
            "objects": [{"name": o.name, "material": o.material} for o in self.objects],
        }


_ARRAYS = ("positions", "normals", "faces", "uvs", "texture")


def save_spec(spec: BlenderSpec, path: Path) -> Path:
    """One .npz the child reads (blender_child.py load_spec): a JSON header and the arrays."""
    arrays = {"header": np.frombuffer(json.dumps(spec.header()).encode(), np.uint8)}
    for i, o in enumerate(spec.objects):
        for a in _ARRAYS:
            v = getattr(o, a)
            if v is not None:
                arrays[f"obj{i}_{a}"] = np.ascontiguousarray(v)
    if spec.environment_pixels is not None:
        arrays["environment"] = np.ascontiguousarray(spec.environment_pixels, np.float32)
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)
    return Path(path)


def _look_along(z_axis: np.ndarray, position) -> list[list[float]]:
    """A 4x4 whose local +Z is z_axis (unit), at position."""
    z = np.asarray(z_axis, np.float64)
    z = z / np.linalg.norm(z)
    up = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, position
    return m.tolist()


def _light(e: dict) -> dict | None:
    name = e.get("light", e["kind"])
    if e["kind"] == "directional":
        col, s = sun_strength(e["irradiance"])
        # a Sun shines along its local -Z
        return {"name": name, "type": "SUN", "matrix": _look_along(-np.asarray(e["direction"]), [0.0, 0.0, 0.0]),
                "color": col, "strength": s, "angle": 0.0}  # fmt: skip
    if e["kind"] == "sun_disk":  # the truth's disk of angular diameter theta, radiance L: E = L pi sin^2(theta/2)
        dist = float(np.linalg.norm(e["centre"]))
        half = math.atan(e["radius"] / dist)
        col, s = sun_strength(np.asarray(e["radiance"]) * math.pi * math.sin(half) ** 2)
        return {"name": name, "type": "SUN", "matrix": _look_along(-np.asarray(e["normal"]), [0.0, 0.0, 0.0]),
                "color": col, "strength": s, "angle": 2 * half}  # fmt: skip
    if e["kind"] == "point":
        col, p = point_power(e["intensity"])
        return {"name": name, "type": "POINT", "matrix": _look_along([0.0, 0.0, 1.0], e["position"]),
                "color": col, "strength": p, "angle": 0.0}  # fmt: skip
    if e["kind"] == "spot":  # a Spot shines along its local -Z
        col, p = point_power(e["intensity"])
        return {"name": name, "type": "SPOT", "matrix": _look_along(-np.asarray(e["direction"]), e["position"]),
                "color": col, "strength": p, "angle": 0.0, "spot_size": math.radians(2.0 * e["cutoff_deg"]),
                "spot_blend": spot_blend(e["beam_deg"], e["cutoff_deg"])}  # fmt: skip
    if e["kind"] == "sphere":
        col, p = sphere_power(e["radiance"], e["radius"])
        return {"name": name, "type": "POINT", "matrix": _look_along([0.0, 0.0, 1.0], e["centre"]),
                "color": col, "strength": p, "angle": 0.0, "radius": float(e["radius"])}  # fmt: skip
    if e["kind"] == "rect":  # an Area light: size along its local X, size_y along Y, shining along -Z
        ex, ey, n = (np.asarray(e[k], np.float64) for k in ("ex", "ey", "normal"))
        n = n / np.linalg.norm(n)
        if np.dot(np.cross(ex, ey), n) > 0:  # right-handed with local Z = -n
            ey = -ey
        wx, wy = 2.0 * float(np.linalg.norm(ex)), 2.0 * float(np.linalg.norm(ey))
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = ex / np.linalg.norm(ex), ey / np.linalg.norm(ey), -n, e["centre"]
        col, p = area_power(e["radiance"], wx * wy)
        return {"name": name, "type": "AREA", "matrix": m.tolist(), "color": col, "strength": p, "angle": 0.0,
                "shape": "RECTANGLE", "size": wx, "size_y": wy}  # fmt: skip
    raise ValueError(f"Blender peers: a {e['kind']} emitter ({name}) has no Blender equivalent")


def subsurface_inputs(interior: dict, values: dict) -> tuple[dict, dict, list[str]]:
    """(common Principled inputs, per-method radius inputs, notes) for the truth's homogeneous medium
    `interior` (skinlab.truth.export.medium_dict) of a material with `values`."""
    from skinlab.scene.optics.material_medium import eta_from_specular

    alpha = np.asarray(interior["albedo"]["value"], np.float64)
    sigma_t = np.asarray(interior["sigma_t"]["value"], np.float64) * float(interior["scale"])  # 1/mm
    phase = interior.get("phase") or {"type": "isotropic"}
    g = float(phase.get("g", 0.0)) if phase.get("type") == "hg" else 0.0
    gc = min(max(g, 0.0), CYCLES_MAX_G)
    # Cycles walks sigma_t = 1 / (d (1 - g)) with d the radius after its setup: d = 1 / (sigma_t (1 - g))
    mfp = 1.0 / (sigma_t * (1.0 - gc))
    eta = eta_from_specular(values["specular"])
    base = cycles_base_color(alpha, gc)
    notes = []
    if gc != g:
        notes.append(f"anisotropy g = {g:g} is outside Cycles' [0, {CYCLES_MAX_G}]: walked at {gc:g}")
    low = [c for c, a in zip("RGB", alpha) if a < CYCLES_MIN_ALPHA]
    if low:
        notes.append(
            f"channels {''.join(low)}: single-scattering albedo below {CYCLES_MIN_ALPHA} is walked at "
            f"{CYCLES_MIN_ALPHA} with the path weight scaled down (Cycles' floor): not the same medium"
        )
    radius = FOUR_PI * mfp
    scale = float(radius.max())
    skin = cycles_skin_radius(mfp, base, eta)
    skin_scale = float(skin.max())
    common = {
        "Base Color": [*base.tolist(), 1.0],
        "Subsurface Weight": 1.0,
        "Subsurface Anisotropy": gc,
        "Subsurface IOR": clamp_sss_ior(eta),
        "IOR": max(eta, 1.0),
        "Specular IOR Level": 0.0 if eta <= 1.0 else 0.5,
        "Roughness": float(values["roughness"]),
        "Metallic": 0.0,
    }
    per_method = {
        "RANDOM_WALK": {"Subsurface Radius": (radius / scale).tolist(), "Subsurface Scale": scale},
        "RANDOM_WALK_SKIN": {"Subsurface Radius": (skin / skin_scale).tolist(), "Subsurface Scale": skin_scale},
    }
    return common, per_method, notes


def surface_inputs(values: dict) -> dict:
    from skinlab.scene.optics.material_medium import eta_from_specular

    eta = eta_from_specular(values["specular"])
    return {
        "Base Color": [*np.asarray(values["base_color"], np.float64).tolist(), 1.0],
        "Subsurface Weight": 0.0,
        "IOR": max(eta, 1.0),
        "Specular IOR Level": 0.0 if eta <= 1.0 else 0.5,
        "Roughness": float(values["roughness"]),
        "Metallic": float(values["metallic"]),
    }


def _blender_camera(desc) -> list[list[float]]:
    """The truth's Mitsuba camera frame (+X left, +Z forward) as Blender's (+X right, looks down -Z)."""
    m = np.asarray(desc.camera_to_world, np.float64)
    out = np.eye(4)
    out[:3, 0], out[:3, 1], out[:3, 2], out[:3, 3] = -m[:3, 0], m[:3, 1], -m[:3, 2], m[:3, 3]
    return out.tolist()


def blender_spec(scene, width: int, height: int, sun_deg: float = 0.0) -> BlenderSpec:
    """The Blender scene of `scene` at width x height: the truth's description
    (skinlab.truth.export.describe) with its media as Principled BSDFs."""
    from skinlab.truth.export import describe

    desc = describe(scene, width, height, sun_deg=sun_deg)
    nodes = {n.name: n for n in scene.mesh_nodes()}
    objects, notes = [], []
    for s in desc.shapes:
        values = nodes[s.name].material.values
        uvs = None if s.texcoords is None else np.column_stack([s.texcoords[:, 0], 1.0 - s.texcoords[:, 1]])
        if s.interior is not None:
            common, per_method, more = subsurface_inputs(s.interior, values)
            notes += [f"{s.name}: {n}" for n in more]
            mat = {"name": s.material, "inputs": common, "subsurface": per_method}
        else:
            mat = {"name": s.material, "inputs": surface_inputs(values), "subsurface": None}
        objects.append(
            BlenderObject(s.name, s.positions, s.normals, np.asarray(s.faces, np.uint32),
                          None if uvs is None else uvs.astype(np.float32), mat, s.texture)
        )  # fmt: skip
    lights, world, env = [], None, None
    for e in desc.emitters:
        if e["kind"] == "constant":
            world = [float(x) for x in e["radiance"]]
        elif e["kind"] == "envmap":
            m = environment_matrix(e["rotation_deg"])
            env = {"strength": float(e["scale"]), "rotation_euler": euler_xyz(m), "matrix": m.tolist()}
        else:
            lights.append(_light(e))
    if any(e["kind"] == "sphere" for e in desc.emitters):
        notes.append("sphere lights: Blender point lights of that radius, blocking no light (the truth's spheres do)")
    if any(e["kind"] == "spot" for e in desc.emitters):
        notes.append("spot lights: Blender's blend is a smoothstep in cos theta between the cone angles, Mitsuba's "
                     "a ramp linear in theta")  # fmt: skip
    camera = {"matrix": _blender_camera(desc), "fov_y_deg": desc.fov_y_deg, "clip": [desc.near, desc.far]}
    return BlenderSpec(
        int(width), int(height), camera, lights, world, objects, [*desc.notes, *notes],
        env, None if env is None else np.asarray(desc.environment, np.float32),
    )  # fmt: skip
