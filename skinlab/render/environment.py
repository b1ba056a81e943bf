"""Environment light in the frame: an HDR map (``[environment] map``; skinlab/scene/envmap.py) lights
every surface, for every technique, through the shared ambient code (skinlab/shaders/lib/ambient.glsl).

Planned by the core (skinlab/render/plan.py, :func:`plan_environment`):

* ``environment``: the map prepared on the CPU (its bright sources taken out as directional lights,
  the rest as an irradiance map for every normal, 9 SH coefficients and prefiltered GGX levels;
  cached by the file's content, on disk under ``$SKINLAB_CACHE_DIR/environment`` when it took more
  than 50 ms) and uploaded: the levels as
  one texture's mip chain, the irradiance map, the split-sum BRDF table, and the map itself when it is
  drawn behind the scene. A uniform map is one radiance (no prefilter, one level); a black map plans nothing.
* ``sky_occlusion``: the share of the map's light each vertex's rays see (the interreflection's rays,
  skinlab/scene/interreflection.py ``sky_visible_share``, against the map's smooth part prefiltered at
  ``SKY_LOD``), so a surface receives the map's light less what the scene hides of it; per map and
  rotation (computed on the CPU, a few tens of ms on the head); skipped when no ray meets anything.
* the map's sources as directional lights with shadow maps (``skinlab.scene.envmap.environment_lights``),
  after the scene's own lights.

The passes that shade ambient light (forward, texture-space irradiance, the interreflection's
exitance) compile with ``ENV_MAP`` (and ``SKY_OCCLUSION``) from :func:`environment_defines` and bind
the per-frame uniforms with :func:`bind_environment`: the SH coefficients turned to world axes and
scaled by the intensity, the rotation for the specular lookups. Turning the map or changing its
intensity re-uploads nothing: only the passes whose inputs hold the light run again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from skinlab.cache import Memo
from skinlab.gl.uniforms import set_array, set_uniform, set_uniforms
from skinlab.scene import envmap
from skinlab.scene.optics import sh, split_sum

from .frame_plan import PlannedPass
from .technique import RenderPass

if TYPE_CHECKING:
    from pathlib import Path

    from skinlab.scene.graph import MeshNode, Scene
    from skinlab.scene.interreflection import BounceTransfer

    from .frame import Frame
    from .frame_plan import FramePlan
    from .settings import RenderSettings
    from .texture_units import TextureUnits

ENV_PASS = "environment"
SKY_PASS = "sky_occlusion"
DATA_KEY = "environment"  # frame.data: the prepared map and its textures
SKY_KEY = "sky_occlusion"  # frame.data: {"offsets": node uid -> first vertex}
SKY_WIDTH = 1024  # vertices per row of the sky-occlusion texture (one texel each)
# the prefiltered level (GGX roughness SKY_LOD / 5) the rays read the map's smooth part at: smooth enough
# that a vertex's 64 rays do not alias a small bright part of it (level 0: 4.1 % on the studio head's
# blocks), sharp enough to keep where it is (level 2: 2.8 %, 3: 3.3 %; level 1: 2.4 %)
SKY_LOD = 1


@dataclass
class EnvironmentParams:
    prepared: envmap.PreparedMap
    path: str | Path  # the map file (the background reads its pixels)
    background: bool


@dataclass
class SkyParams:
    transfer: BounceTransfer
    prepared: envmap.PreparedMap
    rotation_deg: float
    meshes: list | None = None  # the transfer's mesh nodes (rays toward the smooth part's small sources)


def smooth_sources(prepared: envmap.PreparedMap) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The bright small regions left in the map's smooth part (past the frame's shadowed sources: the
    studio map's third lamp), found as envmap.extract_sources finds sources, in the map's frame:
    (directions (J, 3), irradiances (J, 3), the smooth part without them at the level SKY_LOD,
    its irradiance map). Cached on disk per prepared map (a prefilter: seconds)."""
    from skinlab.cache import stored

    def make():
        found, rest = envmap.extract_sources(prepared.levels[0])
        width = prepared.levels[0].shape[1]
        level = split_sum.prefilter(rest, width=width)[min(SKY_LOD, split_sum.LEVELS - 1)] if found else np.zeros(0)
        irr = split_sum.irradiance_map(rest) if found else np.zeros(0)
        d = np.array([s.direction for s in found], np.float64).reshape(-1, 3)
        e = np.array([s.irradiance for s in found], np.float64).reshape(-1, 3)
        return d, e, np.asarray(level, np.float32), np.asarray(irr, np.float32)

    if prepared.uniform or len(prepared.levels) <= SKY_LOD:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    return _SMOOTH.get(
        prepared.key, lambda: stored("environment", f"{prepared.key}-sky", make, "sky sources", code=__name__)
    )


_SMOOTH = Memo(4)  # prepared map key -> smooth_sources


def sky_share(
    transfer: BounceTransfer, prepared: envmap.PreparedMap, rotation_deg: float, meshes: list | None = None
) -> np.ndarray:
    """(V, 4) the sky occlusion's per-vertex record (lib/sky_blocked.glsl): the share of the map's
    smooth part each vertex sees, per channel, and the share of its rays that leave the scene. The
    vertex's rays read the smooth part at level SKY_LOD; with `meshes` (the transfer's nodes) the small
    bright regions left in it (smooth_sources) are taken out of that and seen along one ray per vertex
    each instead: share = (s' E'(n) + sum_j open_j E_j max(n.l_j, 0)) / (E'(n) + sum_j E_j max(n.l_j, 0)),
    s' the rays' share of the rest without them, E' its irradiance at the vertex normal."""
    from skinlab.scene.interreflection import open_toward, sky_visible_share, world_geometry

    directions, irradiances, level_rest, irr_rest = smooth_sources(prepared)
    lamps = meshes is not None and len(directions) > 0
    level = level_rest if lamps else prepared.levels[min(SKY_LOD, len(prepared.levels) - 1)]
    u, v = _SKY_UV.get(transfer.key, lambda: split_sum.equirect_uv(transfer.sky_directions.astype(np.float64)))
    # the map turned by R_y(rotation) about +Y reads a world direction at u + rotation / 360 (equirect_uv)
    out = sky_visible_share(transfer, split_sum.bilinear(level, np.mod(u + rotation_deg / 360.0, 1.0), v))
    if not lamps:
        return out
    assert meshes is not None
    rot = envmap.rotation_y(rotation_deg)
    normals = np.concatenate([world_geometry(n)[1] for n in meshes])
    nu, nv = split_sum.equirect_uv(normals @ rot)  # the normals in the map's frame (u_env_to_map)
    e_rest = split_sum.bilinear(irr_rest, nu, nv)
    toward = directions @ rot.T  # world directions of the sources
    e_lamps = np.maximum(normals @ toward.T, 0.0)[..., None] * irradiances[None]  # (V, J, 3)
    seen = open_toward(meshes, transfer.key, toward)[..., None]
    num = out[:, :3] * e_rest + (seen * e_lamps).sum(1)
    den = e_rest + e_lamps.sum(1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out[:, :3] = np.where(den > 0.0, np.clip(num / np.where(den > 0.0, den, 1.0), 0.0, 1.0), out[:, :3])
    return out


_SKY_UV = Memo(4)  # transfer key -> the rays' (u, v) in the unturned map's frame


def plan_environment(
    scene: Scene, settings: RenderSettings, meshes: list[MeshNode], plan: FramePlan
) -> tuple[list[PlannedPass], list]:
    """The environment's passes and the map's sources as lights (none without a map)."""
    env = scene.environment
    if env.map is None:
        return [], []
    envmap.check_settings("[environment]", env.rotation_deg, env.intensity)
    prepared = envmap.prepare(env.map)
    if prepared.black:
        plan.skipped.append((ENV_PASS, f"map '{prepared.name}' is black: no light from it"))
        return [], []
    if env.intensity == 0 and not env.show_background:
        plan.skipped.append((ENV_PASS, f"map '{prepared.name}' at intensity 0: no light from it"))
        return [], []
    how = {"memory": "prepared earlier", "disk": "prepared earlier, read from the cache"}.get(
        prepared.cached, f"prepared in {prepared.seconds:.2f} s"
    )
    if prepared.uniform:
        what = "uniform map: one radiance, no prefilter"
    else:
        what = f"{len(prepared.levels)} prefiltered GGX levels (split sum), 9 SH coefficients"
        if prepared.sources:
            what += f", {len(prepared.sources)} bright source(s) lit as directional lights with shadows"
    passes = [
        PlannedPass(
            ENV_PASS,
            "environment",
            "env_radiance+env_brdf" + ("+env_background" if env.show_background else ""),
            (prepared.levels[0].shape[1], prepared.levels[0].shape[0]),
            f"map '{prepared.name}' {prepared.width}x{prepared.height} ({how}): {what}"
            + (f"; {prepared.negative_texels} negative texel(s) read as 0" if prepared.negative_texels else "")
            + ("; drawn behind the scene" if env.show_background else ""),
            EnvironmentParams(prepared, env.map, bool(env.show_background)),
            inputs=(prepared.key, bool(env.show_background)),
        )
    ]
    return passes, envmap.environment_lights(scene)


def sky_rays(settings: RenderSettings, meshes: list[MeshNode]) -> int:
    """Rays per vertex the sky occlusion casts (the interreflection's, within its budget)."""
    from skinlab.scene.interreflection import MAX_RAYS

    vertices = sum(len(n.mesh.positions) for n in meshes)
    return min(settings.bounce_rays, MAX_RAYS // max(vertices, 1))


def prefetch_sky(scene: Scene, settings: RenderSettings, meshes: list[MeshNode]) -> None:
    """Start casting the sky occlusion's rays on a worker thread (the interreflection's records, shared
    with it: skinlab/cache.py in_background), so that they are cast while the technique plans."""
    from skinlab.cache import in_background
    from skinlab.scene.interreflection import MIN_RAYS, build_transfer

    if scene.environment.map is not None and settings.sky_occlusion and meshes:
        rays = sky_rays(settings, meshes)
        if rays >= MIN_RAYS:
            in_background(build_transfer, list(meshes), rays)


def plan_sky(
    scene: Scene, settings: RenderSettings, meshes: list[MeshNode], plan: FramePlan, environment: list
) -> PlannedPass | None:
    """The sky-occlusion pass of a frame with an environment map (`environment`: its planned passes)."""
    from skinlab.scene.interreflection import MAX_RAYS, MIN_RAYS, build_transfer

    if not environment:
        return None
    if not settings.sky_occlusion:
        plan.skipped.append((SKY_PASS, "sky occlusion off (sky_occlusion = false)"))
        return None
    if not meshes:
        return None
    vertices = sum(len(n.mesh.positions) for n in meshes)
    rays = sky_rays(settings, meshes)
    if rays < MIN_RAYS:
        plan.skipped.append((SKY_PASS, f"{vertices} vertices: over the ray budget ({MAX_RAYS:,} rays)"))
        return None
    transfer = build_transfer(meshes, rays)
    if not transfer.any_blocked:
        plan.skipped.append((SKY_PASS, "nothing hides the sky: every ray from every vertex leaves the scene"))
        return None
    prepared = environment[0].params.prepared
    rotation = 0.0 if prepared.uniform else float(scene.environment.rotation_deg)  # a uniform map is the same turned
    return PlannedPass(
        SKY_PASS,
        "sky_occlusion",
        "sky_blocked",
        (SKY_WIDTH, max(1, math.ceil(transfer.total_vertices / SKY_WIDTH))),
        f"what the scene hides of the sky: {transfer.total_vertices} vertices x {transfer.rays} rays "
        "(the interreflection's) against the map's smooth part, the visible share per channel; one ray "
        "per vertex toward each small bright region left in it",
        SkyParams(transfer, prepared, rotation, list(meshes)),
        inputs=(transfer.key, prepared.key, rotation),
    )


def environment_state(scene: Scene) -> tuple:
    """What light from all around depends on (a pass's reuse inputs): the ambient radiance and the
    map's content, rotation and intensity."""
    env = scene.environment
    amb = np.asarray(env.ambient, np.float64).tobytes()
    if env.map is None:
        return (amb,)
    return (amb, envmap.map_key(env.map), float(env.rotation_deg), float(env.intensity))


# -- the GPU side ------------------------------------------------------------------------------------

_TABLE: np.ndarray | None = None


def brdf_table() -> np.ndarray:
    """The split-sum table (computed once per process: about 50 ms)."""
    global _TABLE
    if _TABLE is None:
        _TABLE = split_sum.brdf_table().astype(np.float32)
    return _TABLE


def upload_levels(ctx: moderngl.Context, levels: list[np.ndarray]) -> moderngl.Texture:
    """The prefiltered levels as one RGB float texture's mip chain (trilinear, repeat across u)."""
    base = levels[0]
    tex = ctx.texture((base.shape[1], base.shape[0]), 3, np.ascontiguousarray(base, np.float32).tobytes(), dtype="f4")
    if len(levels) > 1:
        tex.build_mipmaps(0, len(levels) - 1)
        for k, lv in enumerate(levels[1:], start=1):
            tex.write(np.ascontiguousarray(lv, np.float32).tobytes(), level=k)
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    else:
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x, tex.repeat_y = True, False
    return tex


def upload_kernels(ctx: moderngl.Context, kernels: np.ndarray) -> moderngl.TextureArray:
    """The kernel maps (layers, h, w, 3) as an RGB float texture array (bilinear in each layer, repeat
    across u, clamped in v; lib/environment.glsl env_kernel)."""
    layers, h, w, _ = kernels.shape
    tex = ctx.texture_array((w, h, layers), 3, np.ascontiguousarray(kernels, np.float32).tobytes(), dtype="f4")
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x, tex.repeat_y = True, False
    return tex


def upload_table(ctx: moderngl.Context, table: np.ndarray) -> moderngl.Texture:
    """The split-sum table as an RG float texture (bilinear, clamped)."""
    tex = ctx.texture(
        (table.shape[1], table.shape[0]), 2, np.ascontiguousarray(table, np.float32).tobytes(), dtype="f4"
    )
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = False
    return tex


class EnvironmentPass(RenderPass):
    """Uploads the prepared map (plan_environment); its textures are kept per map."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self.held: dict | None = None  # key, radiance, brdf, background (or None)

    def _textures(self, prm: EnvironmentParams) -> dict:
        prepared = prm.prepared
        held = self.held
        if held is not None and held["key"] == prepared.key and (held["background"] is not None) >= prm.background:
            return held
        self.release()
        ctx = self.r.ctx
        tex = upload_levels(ctx, prepared.levels)
        brdf = upload_table(ctx, brdf_table())
        assert prepared.irradiance is not None  # envmap.prepare makes it
        irr = upload_levels(ctx, [prepared.irradiance])
        assert prepared.kernels is not None  # envmap.prepare makes them
        kernels = upload_kernels(ctx, prepared.kernels)
        bg = None
        if prm.background:
            pixels, _ = envmap.load_pixels(prm.path)
            bg = ctx.texture((pixels.shape[1], pixels.shape[0]), 3, pixels.tobytes(), dtype="f4")
            bg.filter = (moderngl.LINEAR, moderngl.LINEAR)
            bg.repeat_x, bg.repeat_y = True, False
        self.held = {
            "key": prepared.key, "radiance": tex, "brdf": brdf, "irradiance": irr, "kernels": kernels,
            "background": bg,
        }  # fmt: skip
        return self.held

    def release(self) -> None:
        if self.held is not None:
            for name in ("radiance", "brdf", "irradiance", "kernels", "background"):
                if self.held[name] is not None:
                    self.held[name].release()
            self.held = None

    def outputs(self, frame, p) -> tuple:
        held = self._textures(p.params)
        return tuple(
            held[k] for k in ("radiance", "brdf", "irradiance", "kernels", "background") if held[k] is not None
        )

    def publish(self, frame: Frame, p) -> None:
        prm: EnvironmentParams = p.params
        held = self._textures(prm)
        frame.data[DATA_KEY] = {
            "prepared": prm.prepared,
            "radiance": held["radiance"],
            "brdf": held["brdf"],
            "irradiance": held["irradiance"],
            "kernels": held["kernels"],
            "background": held["background"] if prm.background else None,
        }

    def run(self, frame: Frame, p) -> None:
        self.publish(frame, p)  # the textures are made (uploaded) on first use


class SkyOcclusionPass(RenderPass):
    """Uploads each vertex's blocked-sky coefficients (plan_sky) to a vertex-space texture."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self.held: tuple | None = None  # ((transfer key, map key, rotation), texture)

    def _texture(self, prm: SkyParams) -> moderngl.Texture:
        transfer = prm.transfer
        key = (transfer.key, prm.prepared.key, prm.rotation_deg)
        if self.held is not None and self.held[0] == key:
            return self.held[1]
        self.release()
        n = transfer.total_vertices
        rows = max(1, math.ceil(n / SKY_WIDTH))
        data = np.ones((rows * SKY_WIDTH, 4), np.float32)
        data[:n] = sky_share(transfer, prm.prepared, prm.rotation_deg, prm.meshes)
        tex = self.r.ctx.texture((SKY_WIDTH, rows), 4, data.tobytes(), dtype="f4")
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.held = (key, tex)
        return tex

    def release(self) -> None:
        if self.held is not None:
            self.held[1].release()
            self.held = None

    def outputs(self, frame, p) -> tuple:
        return (self._texture(p.params),)

    def publish(self, frame: Frame, p) -> None:
        tr = p.params.transfer
        frame.targets["sky_blocked"] = self._texture(p.params)
        frame.data[SKY_KEY] = {"offsets": dict(tr.offsets)}

    def run(self, frame: Frame, p) -> None:
        self.publish(frame, p)


# -- the receiving side: every pass that shades ambient light --------------------------------------


def environment_defines(frame: Frame, node: MeshNode | None = None) -> dict:
    """``ENV_MAP`` when this frame has an environment map, ``SKY_OCCLUSION`` when `node` has sky
    occlusion data (lib/ambient.glsl, lib/sky_vertex.glsl)."""
    if DATA_KEY not in frame.data:
        return {}
    sky = frame.data.get(SKY_KEY)
    occluded = sky is not None and node is not None and node.uid in sky["offsets"]
    return {"ENV_MAP": 1, **({"SKY_OCCLUSION": 1} if occluded else {})}


def env_uniforms(scene: Scene, prepared: envmap.PreparedMap) -> dict:
    """The per-frame uniforms of lib/environment.glsl (the rotation and intensity applied here)."""
    env = scene.environment
    return {
        "u_env_sh": envmap.world_sh(prepared, env.rotation_deg, env.intensity),
        "u_env_to_map": envmap.rotation_y(env.rotation_deg).T,
        "u_env_intensity": float(env.intensity),
        "u_env_max_lod": float(len(prepared.levels) - 1),
    }


def bind_environment(frame: Frame, node: MeshNode | None, prog, units: TextureUnits) -> None:
    """The map's uniforms and textures for a program compiled with :func:`environment_defines`."""
    data = frame.data.get(DATA_KEY)
    if data is None:
        return
    values = env_uniforms(frame.scene, data["prepared"])
    set_array(prog, "u_env_sh", values.pop("u_env_sh"), 9)
    set_uniforms(prog, values)
    units.bind(prog, "u_env_radiance", data["radiance"])
    units.bind(prog, "u_env_brdf", data["brdf"])
    units.bind(prog, "u_env_irradiance", data["irradiance"])
    units.bind(prog, "u_env_kernels", data["kernels"])
    sky = frame.data.get(SKY_KEY)
    if sky is not None and node is not None and node.uid in sky["offsets"]:
        units.bind(prog, "u_sky_blocked", frame.targets["sky_blocked"])
        set_uniform(prog, "u_sky_offset", sky["offsets"][node.uid])


@lru_cache(maxsize=256)
def _band_tables(alpha: tuple, colour: tuple, eta: float, ggx_alpha: float) -> tuple[np.ndarray, np.ndarray]:
    from skinlab.scene.optics.boundary import entry_kernel_coefficients, single_band_tables

    a, c = np.array(alpha), np.array(colour)
    return single_band_tables(a, c, eta), entry_kernel_coefficients(a, c, eta, ggx_alpha)


def bind_env_bands(prog, material) -> None:
    """The tables of lib/env_single.glsl (single scattering: the SH-band factors at eta > 1, alpha /
    A_colour for the kernel maps at eta = 1) and lib/ambient_entering.glsl (the light entering the
    multiple scattering: the kernel coefficients) for a mesh shaded as scattering; zeros for the others."""
    names = ("u_sss_single_band1", "u_sss_single_band2", "u_sss_entry_kernel", "u_sss_env_single")
    if not any(n in prog or f"{n}[0]" in prog for n in names):
        return
    from skinlab.render.boundary import boundary_ggx_alpha
    from skinlab.scene.optics.boundary import ANGULAR_NODES, SMOOTH_ALPHA
    from skinlab.scene.optics.material_medium import material_medium, subsurface_albedo

    if material is None or not material.has_subsurface:
        single, entry, ratio = np.zeros((3, ANGULAR_NODES, 3)), np.zeros((3, 3)), np.zeros(3)
    else:  # the same medium and colour as the boundary's tables (skinlab/render/boundary.py material_boundary)
        m = material_medium(material.values)
        alpha = tuple(round(float(x), 9) for x in np.clip(m.alpha_arr, 0.0, 1.0))
        colour = tuple(round(float(x), 9) for x in np.clip(np.ravel(subsurface_albedo(material.values)), 0.0, 1.0))
        ga = boundary_ggx_alpha(material)
        single, entry = _band_tables(alpha, colour, round(float(m.eta), 6), round(ga if ga >= SMOOTH_ALPHA else 0.0, 9))
        ratio = np.where(np.array(colour) > 0, np.array(alpha) / np.maximum(colour, 1e-30), 0.0)
    set_array(prog, "u_sss_single_band1", single[1], ANGULAR_NODES)
    set_array(prog, "u_sss_single_band2", single[2], ANGULAR_NODES)
    set_array(prog, "u_sss_entry_kernel", entry, 3)
    set_uniform(prog, "u_sss_env_single", tuple(float(x) for x in ratio))


def env_band_ratio(world_sh: np.ndarray, n, bands, uniform, limit: float = 4.0) -> np.ndarray:
    """NumPy twin of lib/environment.glsl env_band_ratio: (..., 3) what a zonal kernel of band factors
    `bands` (3, ..., 3) gathers from the radiance coefficients (9, 3) at normals n, per unit of the SH
    irradiance there, clamped to [0, limit x uniform]; `uniform` where the SH irradiance vanishes."""
    y = sh.sh9_basis(n)
    c = np.asarray(world_sh, np.float64)
    s = [y[..., :1] * c[0], y[..., 1:4] @ c[1:4], y[..., 4:9] @ c[4:9]]
    got = sum(np.asarray(bands[k]) * s[k] for k in range(3))
    irr = sum(sh.SH_A[k] * s[k] for k in range(3))
    uniform = np.broadcast_to(np.asarray(uniform, np.float64), irr.shape)
    ok = irr > 1e-6 * np.maximum(s[0], 1e-20)
    return np.where(ok, np.clip(got / np.where(ok, irr, 1.0), 0.0, limit * uniform), uniform)


def env_single(kernels: np.ndarray, n_map, mu, single) -> np.ndarray:
    """NumPy twin of lib/env_single.glsl env_single at index 1, intensity 1: (..., 3) the single
    scattering of the map toward a view at cosine mu, per unit base colour, from the kernel maps
    (split_sum.kernel_maps) at map-frame normals n_map, linear in mu between the 17 view cosines,
    times `single` (alpha / A_colour)."""
    x = np.clip(np.asarray(mu, np.float64), 0.0, 1.0) * (split_sum.KERNEL_NODES - 1)
    i = np.minimum(np.floor(x).astype(int), split_sum.KERNEL_NODES - 2)
    f = (x - i)[..., None]
    u, v = split_sum.equirect_uv(n_map)
    out = np.zeros(np.shape(u) + (3,))
    for j in np.unique(np.concatenate([np.ravel(i), np.ravel(i) + 1])):
        w = np.where(i == j, 1.0, 0.0)[..., None] * (1 - f) + np.where(i + 1 == j, 1.0, 0.0)[..., None] * f
        out += w * split_sum.bilinear(kernels[j], u, v)
    return np.asarray(single, np.float64) * out


def env_entering(kernels: np.ndarray, irradiance: np.ndarray, n_map, coefficients) -> np.ndarray:
    """NumPy twin of lib/ambient_entering.glsl's map term at intensity 1, unoccluded: (..., 3) c_0 E(n)
    + c_1 int L t^2 dw + c_2 int L t^3 dw per unit base colour (boundary.entry_kernel_coefficients),
    clamped at 0, from the irradiance map and the kernel maps at map-frame normals n_map."""
    c = np.asarray(coefficients, np.float64)
    u, v = split_sum.equirect_uv(n_map)
    e = c[0] * split_sum.bilinear(irradiance, u, v)
    for k in range(1, len(c)):
        e = e + c[k] * split_sum.bilinear(kernels[split_sum.KERNEL_NODES + k - 1], u, v)
    return np.maximum(e, 0.0)


def env_diffuse(irradiance, sky=None) -> np.ndarray:
    """NumPy twin of lib/sky_occlusion.glsl env_diffuse_irradiance: the unoccluded irradiance
    `irradiance` (..., 3) (the irradiance map's lookup at the normal) times the share of the map's light
    the point sees, the sky occlusion's record `sky` (..., 4) (sky_share: RGB share, then the rays'
    share) clamped to [0, 1] (env_sky_share); unoccluded without it."""
    e = np.asarray(irradiance, np.float64)
    if sky is None:
        return e
    return e * np.clip(np.asarray(sky, np.float64)[..., :3], 0.0, 1.0)
