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

import numpy as np

from skinlab.render.environment import environment_state
from skinlab.render.frame_plan import PlannedPass, shadow_pass_name
from skinlab.render.reuse import light_state, material_state, node_geometry
from skinlab.render.scattering import scattering_material
from skinlab.render.translucency import plan_translucency
from skinlab.scene.mesh import with_atlas
from skinlab.scene.mesh_thickness import thinner_than
from skinlab.scene.optics.translucency_reach import REACH_EPS, translucency_reach_mm
from skinlab.scene.optics.tsd import (
    BlurStep,
    DiffusionKernel,
    design_kernel,
    material_medium,
    profile_fit,
    subsurface_albedo,
)
from skinlab.scene.uv_checks import analyse_uvs

from .seams import node_seams, seam_band_texels, seams_summary

DILATE_RINGS = 4  # texels of dilation past chart borders (irradiance and stretch)


def model_scale(world: np.ndarray) -> float:
    return float(abs(np.linalg.det(world[:3, :3])) ** (1.0 / 3.0))


_UV_CACHE: dict = {}


def uv_report(node, mm_per_unit: float, size: int):
    mesh = node.mesh
    key = (mesh.uid, mesh.version, float(mm_per_unit), round(model_scale(node.world_matrix), 9), size)
    r = _UV_CACHE.get(key)
    if r is None:
        if len(_UV_CACHE) > 64:
            _UV_CACHE.clear()
        r = _UV_CACHE[key] = analyse_uvs(
            mesh, mm_per_unit, texels=size, grid=512, model_scale=model_scale(node.world_matrix)
        )
    return r


@dataclass
class TsdNodePlan:
    node: object
    material: object
    kernel: DiffusionKernel
    size: int
    seams: object = None  # the mesh's SeamExtension (skinlab/scene/uv_seams.py), None: no seams or switched off
    seam_band: int = 0  # texels the extension reaches past each seam


# -- the passes' typed parameters ----------------------------------------------------------------------


@dataclass
class TsdNodeParams:
    """What every texture-space pass of one mesh node needs."""

    node: object
    size: int  # texels per side
    material: object  # the effective material
    kernel: DiffusionKernel  # the Gaussian chain (and the translucency's Gaussians)
    dilate: int = DILATE_RINGS
    seams: object = None  # SeamExtension: light crosses UV seams (seams.py); None: not used


@dataclass
class TsdIrradianceParams(TsdNodeParams):
    lights: list = field(default_factory=list)
    shadow_lights: list = field(default_factory=list)
    translucency: bool = False
    mix: float = 0.5  # pre-/post-scatter texturing: albedo^mix before the blur
    gather: DiffusionKernel | None = None  # the forward pass's gather weights (None: kernel)


@dataclass
class TsdBlurParams(TsdNodeParams):
    step: BlurStep | None = None


@dataclass
class TsdExactParams(TsdNodeParams):
    model: str = ""


# the exact convolution writes level 0, which the gather reads with weight 1
UNIT_KERNEL = DiffusionKernel((BlurStep(0, 0.0, 0.0, 0, (1.0, 1.0, 1.0)),), np.zeros(3))


def plan_tsd_node(
    node, ctx, size: int, gaussians: int, taps: int | None, seams: bool = True, local: dict | None = None
) -> TsdNodePlan | None:
    """Decide TSD for one visible mesh node (PlanContext `ctx`); record skips and warnings in its plan.
    A scattering node whose profile is narrower than a texel goes into `local` (uid -> material)."""
    label = f"tsd[{node.name}]"
    plan, scene = ctx.plan, ctx.scene
    mat = scattering_material(node, ctx.settings, plan, label)
    if mat is None:
        return None
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
        return TsdNodePlan(node, mat, kernel, size)
    band = seam_band_texels(kernel, p10)
    ext = node_seams(mesh, band, size)
    if ext is None:
        plan.skipped.append((f"tsd_seams[{node.name}]", f"mesh {mesh.name!r} has no UV seam"))
    return TsdNodePlan(node, mat, kernel, size, ext, band)


def plan_tsd(
    ctx,
    size: int,
    gaussians: int,
    taps: int | None,
    mix: float,
    translucency: bool,
    exact: bool = False,
    seams: bool = True,
):
    """The texture-space passes of every scattering mesh (stretch, the seam map where the mesh has
    UV seams and `seams` is on, irradiance, dilation, then the Gaussian blurs, or with `exact` the
    brute-force convolution) and whether translucency runs; (passes, node plans, translucency,
    local: uid -> material of the meshes scattered locally)."""
    plan = ctx.plan
    local: dict = {}
    nodes = [
        t for t in (plan_tsd_node(n, ctx, size, gaussians, taps, seams, local) for n in ctx.meshes) if t is not None
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
    translucency's thickness in mm), the albedo mix and the translucency's Gaussians. Not the camera."""
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
    )


def _node_passes(t, ctx, mix, translucency, exact) -> list[PlannedPass]:
    node, n, k = t.node, t.size, t.kernel
    base = dict(node=node, size=n, material=t.material, kernel=k, dilate=DILATE_RINGS, seams=t.seams)
    res = (n, n)
    stretch, irradiance, dilated = (f"tsd_{x}[{node.name}]" for x in ("stretch", "irradiance", "dilate"))
    seam_key = (t.seam_band, t.seams.band_uv) if t.seams is not None else None
    seam_pass = f"tsd_seams[{node.name}]"
    seam_after = (seam_pass,) if t.seams is not None else ()
    out = [
        PlannedPass(
            stretch,
            "tsd_stretch",
            "tsd_stretch",
            res,
            f"mm per texel of '{node.mesh.name}' (depends on the geometry and the scene scale)",
            TsdNodeParams(**base),
            inputs=(stretch_inputs(node, ctx.scene), DILATE_RINGS, seam_key),
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
                gather=UNIT_KERNEL if exact else k,
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
            + f" irradiance {DILATE_RINGS} texels past UV chart borders",
            TsdNodeParams(**base),
            inputs=(DILATE_RINGS, seam_key),
            after=(irradiance, *seam_after),
        )
    )
    if exact:
        out.append(
            PlannedPass(
                f"tsd_exact[{node.name}]",
                "tsd_exact",
                "tsd_level0",
                res,
                f"brute-force convolution with the exact {t.material['sss_model']} profile (image reference; slow "
                "on purpose)",
                TsdExactParams(**base, model=t.material["sss_model"]),
                inputs=(t.material["sss_model"], material_state(t.material)),
                after=(dilated, stretch),
            )
        )
        return out
    previous = dilated
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
                f"weight RGB ({w})" + ("; gutter filled across UV seams" if t.seams is not None else ""),
                TsdBlurParams(**base, step=s),
                inputs=(s.level, s.sigma_mm, s.taps, seam_key),
                after=(previous, stretch, *seam_after),
            )
        )
        previous = name
    return out
