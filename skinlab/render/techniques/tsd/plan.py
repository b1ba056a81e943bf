"""Planning texture-space diffusion for a frame: which meshes need it, with which Gaussian chain.

A mesh node gets TSD passes only when its (effective) material scatters below the surface: a
subsurface weight above 0, a model other than "none" and a radius above 0, and a kernel wider than a
texel. A scattering mesh whose Gaussians are all narrower than a texel needs no blur: it is shaded
locally (the light that enters leaves where it entered, with the same entry, exit and single
scattering as the blurred case; skinlab/shaders/techniques/tsd/local.glsl). Everything decided here is recorded
in the plan (pass reasons, skipped items, warnings).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from skinlab.cache import content_key, stored
from skinlab.render.compute import PassPath
from skinlab.render.environment import environment_state
from skinlab.render.frame_plan import PlannedPass, shadow_pass_name
from skinlab.render.reuse import light_state, material_state, node_geometry
from skinlab.render.scattering import scattering_material
from skinlab.render.translucency import plan_translucency
from skinlab.scene.mesh import mesh_key, with_atlas
from skinlab.scene.mesh_thickness import thinner_than
from skinlab.scene.optics.material_medium import material_medium, subsurface_albedo
from skinlab.scene.optics.profile_fit import profile_fit
from skinlab.scene.optics.translucency_reach import REACH_EPS, translucency_reach_mm
from skinlab.scene.optics.tsd import (
    NEGLIGIBLE_WEIGHT,
    TSD_SUBTEXEL_SIGMA,
    BlurStep,
    DiffusionKernel,
    design_kernel,
)
from skinlab.scene.uv_checks import analyse_uvs

from .seams import node_seams, seam_band_texels, seams_summary

if TYPE_CHECKING:
    from skinlab.scene.graph import MeshNode
    from skinlab.scene.materials import Material
    from skinlab.scene.uv_seams import SeamExtension

DILATE_RINGS = 4  # texels of dilation past chart borders (irradiance and stretch)
# the path `compute = auto` takes on software GL for the dilations and the blurs (skinlab/render/compute.py;
# measured: docs/architecture.md "Compute passes")
DILATE_ON_SOFTWARE = "fragment"
BLUR_ON_SOFTWARE = "fragment"

# A mesh's texture space is sized from its surface and its size on screen: this many texels per
# screen pixel, along a line, where the mesh comes nearest the camera (the whole surface counted, the
# back too, over the part of the UV square its charts cover), rounded up to a power of two, at least
# FITTED_MIN and at most the `size` setting (TsdSettings.fit_size). The head in a 96-pixel frame gets
# 512 texels, in a 48-pixel one 256; a quad 8 pixels wide gets 32, not 512: 80 of them cost about
# what their pixels cost.
TEXELS_PER_PIXEL = 2.0
FITTED_MIN = 32


def model_scale(world: np.ndarray) -> float:
    return float(abs(np.linalg.det(world[:3, :3])) ** (1.0 / 3.0))


_UV_CACHE: dict = {}


def uv_report(node, mm_per_unit: float, size: int):
    mesh = node.mesh
    key = (mesh.uid, mesh.version, float(mm_per_unit), round(model_scale(node.world_matrix), 9), size)
    r = _UV_CACHE.get(key)
    if r is None:
        if len(_UV_CACHE) > 512:  # a scene of hundreds of parts keeps them all from frame to frame
            _UV_CACHE.pop(next(iter(_UV_CACHE)))
        scale, grid = model_scale(node.world_matrix), min(512, size)
        r = _UV_CACHE[key] = stored(  # on disk too: the head's layout takes about 0.1 s to check
            "uv_report",
            content_key(mesh_key(mesh), float(mm_per_unit), scale, size, grid),
            lambda: analyse_uvs(mesh, mm_per_unit, texels=size, grid=grid, model_scale=scale),
            f"the UV check of mesh {mesh.name!r}",
            code=analyse_uvs.__module__,
        )
    return r


_SURFACE: dict = {}


def _surface(mesh) -> tuple[float, float]:
    """(surface area in the mesh's units squared, fraction of the UV square its triangles cover),
    once per mesh version."""
    key = (mesh.uid, mesh.version)
    if key not in _SURFACE:
        f = mesh.indices.astype(np.int64)
        p = mesh.positions.astype(np.float64)
        area = 0.5 * float(np.linalg.norm(np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]), axis=1).sum())
        cover = 1.0
        if mesh.uvs is not None:
            t = mesh.uvs.astype(np.float64)[f]
            d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
            cover = float(np.nansum(0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])))
        if len(_SURFACE) > 512:
            _SURFACE.clear()
        _SURFACE[key] = (area, min(max(cover, 0.05), 1.0))
    return _SURFACE[key]


def pixels_per_unit(node, scene, settings) -> float | None:
    """Screen pixels per scene unit where the node's bounds come nearest the camera (None: no
    camera, or the node is behind it)."""
    cam = scene.camera
    if cam is None:
        return None
    world = np.asarray(node.world_matrix, np.float64)
    view = np.asarray(cam.view_matrix(), np.float64)
    corners = node.mesh.bound_corners() @ world[:3, :3].T + world[:3, 3]
    depth = -(corners @ view[:3, :3].T + view[:3, 3])[:, 2]  # distance in front of the camera
    if depth.max() <= 0:
        return None
    nearest = max(float(depth.min()), cam.znear)
    return settings.render_size[1] / (2.0 * nearest * math.tan(cam.yfov / 2.0))


def fitted_size(node, scene, settings, size: int) -> tuple[int, str]:
    """Texels per side for the node's texture space (see TEXELS_PER_PIXEL) and a reason for the plan."""
    if scene.camera is None:
        return size, ""
    ppu = pixels_per_unit(node, scene, settings)
    if ppu is None:
        return min(FITTED_MIN, size), "behind the camera"
    area, cover = _surface(node.mesh)
    area_world = area * model_scale(np.asarray(node.world_matrix, np.float64)) ** 2
    side = math.sqrt(area_world / cover) * ppu * TEXELS_PER_PIXEL
    if not math.isfinite(side):
        return size, ""
    fitted = max(1 << max(int(math.ceil(math.log2(max(side, 1.0)))), 0), FITTED_MIN)
    if fitted >= size:
        return size, ""
    return fitted, (
        f"{fitted} texels a side, from the mesh's ~{side / TEXELS_PER_PIXEL:.0f} pixels on screen at "
        f"{TEXELS_PER_PIXEL:g} texels a pixel; the size setting, {size}, is the most"
    )


CHANNELS = ("red", "green", "blue")
MAX_SIZE = 8192  # TsdSettings.size's range


def subtexel_note(mesh_name: str, fit, p50: float, size: int, mm_per_pixel: float) -> str | None:
    """A note for the render summary when the Gaussians narrower than a texel (folded into the
    unblurred term) carry most of some channel's light: the texels per side that would blur at least
    half of it in every such channel, or that it would hardly show (they are narrower than half a
    pixel on screen too). None when no channel loses most of its blur."""
    sigma = np.sqrt(np.maximum(np.asarray(fit.variances_mm2, np.float64), 0.0))
    w = np.asarray(fit.weights, np.float64).reshape(len(sigma), 3)
    used = w.max(axis=1) >= NEGLIGIBLE_WEIGHT
    sub = used & (sigma / p50 < TSD_SUBTEXEL_SIGMA)
    total = w[used].sum(axis=0)
    lost = np.where(total > 0, w[sub].sum(axis=0) / np.where(total > 0, total, 1.0), 0.0)
    channels = [c for c in range(3) if lost[c] > 0.5]
    if not channels:
        return None
    lit = [CHANNELS[c] for c in channels]
    names = ", ".join(lit[:-1]) + " and " + lit[-1] if len(lit) > 1 else lit[0]
    head = (
        f"mesh {mesh_name!r}: {int(sub.sum())} of {int(used.sum())} Gaussians of the profile are narrower than a "
        f"texel ({p50:.2g} mm at {size} texels a side) and not blurred, so most {names} light leaves where it "
        "entered"
    )
    visible = sub & (sigma >= 0.5 * mm_per_pixel)  # the ones a blur would show at this image's pixel size
    if not visible.any():
        return (
            head
            + f"; they are narrower than half a pixel here too ({mm_per_pixel:.2g} mm): more texels would hardly show"
        )
    need = float(sigma[visible].min())
    side = 1 << int(math.ceil(math.log2(max(size * p50 * TSD_SUBTEXEL_SIGMA / max(need, 1e-12), 1.0))))
    which = f"the {int(visible.sum())} of them wider than half a pixel ({mm_per_pixel:.2g} mm) here"
    if side > MAX_SIZE:
        return (
            head + f"; blurring {which} would take {side} texels a side, more than the {MAX_SIZE} a texture space takes"
        )
    return head + f"; {side} texels a side would blur {which} (--tsd-size {side})"


@dataclass
class TsdNodePlan:
    node: MeshNode
    material: Material
    kernel: DiffusionKernel
    size: int
    seams: SeamExtension | None = None  # skinlab/scene/uv_seams.py; None: no seams or switched off
    seam_band: int = 0  # texels the extension reaches past each seam
    size_note: str = ""  # why the texture space is smaller than the size setting (fitted_size)


# -- the passes' typed parameters ----------------------------------------------------------------------


@dataclass
class TsdNodeParams:
    """What every texture-space pass of one mesh node needs."""

    node: MeshNode
    size: int  # texels per side
    material: Material  # the effective material
    kernel: DiffusionKernel  # the Gaussian chain (and the translucency's Gaussians)
    dilate: int = DILATE_RINGS
    seams: SeamExtension | None = None  # SeamExtension: light crosses UV seams (seams.py); None: not used
    compute: bool = False  # the pass's compute shader (skinlab/render/compute.py), where it has one


@dataclass
class TsdIrradianceParams(TsdNodeParams):
    lights: list = field(default_factory=list)
    shadow_lights: list = field(default_factory=list)
    translucency: bool = False
    mix: float = 0.5  # pre-/post-scatter texturing: albedo^mix before the blur
    gather: DiffusionKernel | None = None  # the forward pass's gather weights (None: kernel)
    # shade each texel once from a G-buffer of the rasterised surface (techniques/tsd/surface.glsl), the
    # same light; else shade while rasterising the mesh (a software rasteriser shades whole blocks of
    # texels for each small UV triangle)
    deferred: bool = False


@dataclass
class TsdBlurParams(TsdNodeParams):
    step: BlurStep = field(kw_only=True)


@dataclass
class TsdExactParams(TsdNodeParams):
    model: str = ""


# the exact convolution writes level 0, which the gather reads with weight 1
UNIT_KERNEL = DiffusionKernel((BlurStep(0, 0.0, 0.0, 0, (1.0, 1.0, 1.0)),), np.zeros(3))


def plan_tsd_node(
    node,
    ctx,
    size: int,
    gaussians: int,
    taps: int | None,
    seams: bool = True,
    local: dict | None = None,
    fit_size: bool = False,
) -> TsdNodePlan | None:
    """Decide TSD for one visible mesh node (PlanContext `ctx`); record skips and warnings in its plan.
    A scattering node whose profile is narrower than a texel goes into `local` (uid -> material).
    The node's texture space is `size` texels per side, or with `fit_size` fewer for a mesh small on
    screen (:func:`fitted_size`)."""
    label = f"tsd[{node.name}]"
    plan, scene = ctx.plan, ctx.scene
    mat = scattering_material(node, ctx.settings, plan, label)
    if mat is None:
        return None
    size, size_note = fitted_size(node, scene, ctx.settings, size) if fit_size else (size, "")
    mesh = node.mesh
    if mesh.uvs is None:
        plan.warnings.append(
            f"mesh {mesh.name!r} ({mesh.source or 'no file'}) has no UVs; texture-space "
            "diffusion generated an atlas with xatlas (set generate_uvs = true in the scene "
            "file to do it at load time)"
        )
        node.mesh = mesh = with_atlas(mesh)  # a copy: the loader's cached mesh stays as the file has it
    rep = uv_report(node, scene.mm_per_unit, size)
    for w in rep.warnings():
        if w not in plan.warnings:
            plan.warnings.append(w)
    for n in rep.notes():
        plan.skipped.append((f"uv[{mesh.name}] slivers", n))
    pct = rep.mm_per_texel_percentiles
    p10 = float(np.nanmin(pct["p10"])) if pct else math.nan
    p50 = float(np.nanmean(pct["p50"])) if pct else math.nan
    if not (np.isfinite(p10) and np.isfinite(p50) and p50 > 0):
        plan.warnings.append(
            f"mesh {mesh.name!r}: no triangle with a usable UV-to-surface scale; rendered without subsurface scattering"
        )
        plan.skipped.append((label, "no usable UV layout"))
        return None
    fit = profile_fit(mat["sss_model"], material_medium(mat.values), gaussians)
    kernel = design_kernel(fit, max(p10, 1e-9), p50, taps=taps)
    ppu = pixels_per_unit(node, scene, ctx.settings)
    mm_per_pixel = scene.mm_per_unit / ppu if ppu else math.inf
    note = subtexel_note(mesh.name, fit, p50, size, mm_per_pixel)
    if note and note not in plan.notes:
        plan.notes.append(note)
    for what, why in kernel.skipped:
        plan.skipped.append((f"{label} {what}", why))
    if kernel.levels == 0:
        plan.skipped.append(
            (label, "every Gaussian of the profile is narrower than a texel or negligible; scattered locally")
        )
        if local is not None:
            local[node.uid] = mat
        return None
    if not seams:
        plan.skipped.append((f"tsd_seams[{node.name}]", "switched off in the settings: blurs stop at UV seams"))
        return TsdNodePlan(node, mat, kernel, size, size_note=size_note)
    band = seam_band_texels(kernel, p10)
    ext = node_seams(mesh, band, size)
    if ext is None:
        plan.skipped.append((f"tsd_seams[{node.name}]", f"mesh {mesh.name!r} has no UV seam"))
    return TsdNodePlan(node, mat, kernel, size, ext, band, size_note)


def plan_tsd(
    ctx,
    size: int,
    gaussians: int,
    taps: int | None,
    mix: float,
    translucency: bool,
    exact: PassPath | None = None,
    seams: bool = True,
    fit_size: bool = False,
):
    """The texture-space passes of every scattering mesh (stretch, the seam map where the mesh has
    UV seams and `seams` is on, irradiance, dilation, then the Gaussian blurs, or with `exact` - the
    path of technique exact's pass, skinlab/render/compute.py - the brute-force convolution) and
    whether translucency runs; (passes, node plans, translucency, local: uid -> material of the
    meshes scattered locally)."""
    plan = ctx.plan
    local: dict = {}
    nodes = [
        t
        for t in (plan_tsd_node(n, ctx, size, gaussians, taps, seams, local, fit_size) for n in ctx.meshes)
        if t is not None
    ]
    use_translucency = plan_translucency(ctx, bool(nodes), translucency)
    if not nodes and not local:
        plan.skipped.append(("texture-space diffusion", "no visible material needs it"))
    passes, any_translucent = [], False
    for t in nodes:
        node_translucency = use_translucency and can_shine_through(t, ctx.scene, plan)
        any_translucent |= node_translucency
        passes += _node_passes(t, ctx, mix, node_translucency, exact)
    return passes, nodes, any_translucent, local


def can_shine_through(t: TsdNodePlan, scene, plan) -> bool:
    """Whether light can cross some part of the node's mesh: a part thinner than the thickness past
    which its material lets through less than REACH_EPS of the light a surface facing it receives
    (skinlab/scene/optics/translucency_reach.py; thickness along the inward normals, skinlab/scene/mesh_thickness.py).
    When none is, the node's irradiance pass runs without the translucency variant (no distance-map
    lookups, no slab evaluation) and the plan says so."""
    mat, node = t.material, t.node
    medium = material_medium(mat.values)
    reach_mm = translucency_reach_mm(medium.alpha_arr, medium.mfp_arr, medium.eta, subsurface_albedo(mat.values))
    if not math.isfinite(reach_mm):
        return True
    # the node's world transform shrinks no length by more than its smallest singular value
    shrink = float(np.linalg.svd(np.asarray(node.world_matrix, np.float64)[:3, :3], compute_uv=False).min())
    if shrink <= 0:
        return True
    if reach_mm > 0 and thinner_than(node.mesh, reach_mm / (scene.mm_per_unit * shrink)):
        return True
    plan.skipped.append(
        (
            f"translucency[{node.name}]",
            f"no part of mesh '{node.mesh.name}' is thinner than {reach_mm:.3g} mm, past which material "
            f"'{mat.name}' lets through less than {REACH_EPS:g} of the light a surface facing it receives",
        )
    )
    return False


def stretch_inputs(node, scene) -> tuple:
    """What a stretch map depends on: the mesh (identity, version), the scene scale, the metric
    of the node's world transform (M^T M of its linear part: a translation or rotation changes
    no length on the surface) and the material's subsurface radius map (it divides the stretch)."""
    m = np.asarray(node.world_matrix, np.float64)[:3, :3]
    radius_map = str(node.material.values.get("subsurface_radius_map"))
    return (node.mesh.uid, node.mesh.version, (m.T @ m).round(12).tobytes(), float(scene.mm_per_unit), radius_map)


def irradiance_inputs(t: TsdNodePlan, ctx, mix: float, translucency: bool) -> tuple:
    """What the texture-space irradiance depends on besides the shadow maps it reads: the node's
    geometry and transform, its material, the lights, the ambient light, the scene scale (the
    translucency's thickness in mm), the albedo mix and the translucency's Gaussians, whether the oblique
    entry's shadow is spread (RenderSettings.entry_spread), whether the light through thin parts comes
    from the transfer through the medium (RenderSettings.through_kernel). Not the camera."""
    k = t.kernel
    trans = (
        (tuple(s.variance_mm2 for s in k.steps), np.asarray(k.weights(), np.float64).tobytes())
        if translucency
        else None
    )
    return (
        node_geometry(t.node),
        material_state(t.material),
        tuple(light_state(l) for l in ctx.lights),
        tuple(l.uid for l in ctx.shadow_lights),
        environment_state(ctx.scene),
        float(ctx.scene.mm_per_unit),
        float(mix),
        trans,
        ctx.settings.max_lights,
        ctx.settings.entry_spread,
        ctx.settings.through_kernel and translucency,
    )


def deferred_irradiance(device) -> bool:
    """Whether the irradiance pass shades from its surface G-buffer (TsdIrradianceParams.deferred): on
    software GL, where it takes about half the time of shading while rasterising the UV layout
    (docs/tsd.md "Cost"), the same light to fp32 rounding; on a GPU, which shades 2x2 quads, the
    direct raster (not measured there yet)."""
    return device is not None and device.software


def _node_passes(t, ctx, mix, translucency, exact) -> list[PlannedPass]:
    node, n, k = t.node, t.size, t.kernel
    base = dict(node=node, size=n, material=t.material, kernel=k, dilate=DILATE_RINGS, seams=t.seams)
    res = (n, n)
    stretch, irradiance, dilated = (f"tsd_{x}[{node.name}]" for x in ("stretch", "irradiance", "dilate"))
    seam_key = (t.seam_band, t.seams.band_uv) if t.seams is not None else None
    seam_pass = f"tsd_seams[{node.name}]"
    seam_after = (seam_pass,) if t.seams is not None else ()
    dilation = ctx.path(DILATE_ON_SOFTWARE)
    out = [
        PlannedPass(
            stretch,
            "tsd_stretch",
            "tsd_stretch",
            res,
            f"mm per texel of '{node.mesh.name}' (depends on the geometry and the scene scale); its dilation"
            + dilation.note,
            TsdNodeParams(**base, compute=dilation.compute),
            inputs=(stretch_inputs(node, ctx.scene), DILATE_RINGS, seam_key, dilation.compute),
            reads_light=False,
        )
    ]
    if t.seams is not None:
        out.append(
            PlannedPass(
                seam_pass,
                "tsd_seams",
                "tsd_seams",
                res,
                f"light crosses UV seams: {seams_summary(t.seams, t.seam_band)} (unfolded once per mesh, "
                "cached); the irradiance's gutter and every blurred level's are filled from across the seams",
                TsdNodeParams(**base),
                inputs=(node.mesh.uid, node.mesh.version, seam_key),
                reads_light=False,
            )
        )
    out.append(
        PlannedPass(
            irradiance,
            "tsd_irradiance",
            "tsd_irradiance",
            res,
            f"material '{t.material.name}' scatters ({t.material['sss_model']}): light entering the surface in UV space"
            + (f"; {t.size_note}" if t.size_note else "")
            + (
                "; each texel shaded once from the rasterised surface (a G-buffer)"
                if deferred_irradiance(ctx.device)
                else ""
            )
            + (
                ", translucency through thin parts (its record's gutter filled "
                + ("across UV seams and " if t.seams is not None else "")
                + "one texel past chart borders)"
                if translucency
                else ""
            ),
            TsdIrradianceParams(
                **base,
                lights=ctx.lights,
                shadow_lights=ctx.shadow_lights,
                translucency=translucency,
                mix=mix,
                gather=UNIT_KERNEL if exact is not None else k,
                deferred=deferred_irradiance(ctx.device),
            ),
            inputs=irradiance_inputs(t, ctx, mix, translucency),
            # the light-through record is filled across the seams from the seam map
            after=(*(shadow_pass_name(l) for l in ctx.shadow_lights), *(seam_after if translucency else ())),
        )
    )
    out.append(
        PlannedPass(
            dilated,
            "tsd_dilate",
            "tsd_irradiance",
            res,
            ("fill the gutter across UV seams from the seam map, then push" if t.seams is not None else "push")
            + f" irradiance {DILATE_RINGS} texels past UV chart borders"
            + dilation.note,
            TsdNodeParams(**base, compute=dilation.compute),
            inputs=(DILATE_RINGS, seam_key, dilation.compute),
            after=(irradiance, *seam_after),
        )
    )
    if exact is not None:
        out.append(
            PlannedPass(
                f"tsd_exact[{node.name}]",
                "tsd_exact",
                "tsd_level0",
                res,
                f"brute-force convolution with the exact {t.material['sss_model']} profile (image reference; slow "
                "on purpose)" + exact.note,
                TsdExactParams(**base, model=t.material["sss_model"], compute=exact.compute),
                inputs=(t.material["sss_model"], material_state(t.material), exact.compute),
                after=(dilated, stretch),
            )
        )
        return out
    previous = dilated
    blur = ctx.path(BLUR_ON_SOFTWARE)
    for s in k.steps:
        w = ", ".join(f"{x:.3f}" for x in s.weight)
        name = f"tsd_blur[{node.name}]{s.level}"
        out.append(
            PlannedPass(
                name,
                "tsd_blur",
                f"tsd_level{s.level}",
                res,
                f"Gaussian v={s.variance_mm2:.4g} mm2 (step sigma {s.sigma_mm:.3g} mm, {s.taps} taps), "
                f"weight RGB ({w})" + ("; gutter filled across UV seams" if t.seams is not None else "") + blur.note,
                TsdBlurParams(**base, step=s, compute=blur.compute),
                inputs=(s.level, s.sigma_mm, s.taps, seam_key, blur.compute),
                after=(previous, stretch, *seam_after),
            )
        )
        previous = name
    return out
