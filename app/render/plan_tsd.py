"""Planning texture-space diffusion for a frame: which meshes need it, with which Gaussian chain.

A mesh node gets TSD passes only when its (effective) material scatters below the surface: a
subsurface weight above 0, a model other than "none" and a radius above 0, and a kernel wider than a
texel. Everything decided here is recorded in the plan (pass reasons, skipped items, warnings).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scene.mesh import with_atlas
from scene.optics.tsd import design_kernel, material_medium, profile_fit
from scene.uv_checks import analyse_uvs

DILATE_RINGS = 4  # texels of dilation past chart borders (irradiance and stretch)


def effective_material(node, settings):
    mat = node.material
    if settings.sss_model is not None and mat["sss_model"] != settings.sss_model:
        mat = _override(mat, settings.sss_model)
    return mat


_OVERRIDES: dict = {}


def _override(mat, model):
    """The material with sss_model replaced (cached per material object and value set, so shader
    programs and fits are not redone every frame)."""
    key = (mat.name, model, tuple(sorted((k, str(v)) for k, v in mat.values.items())))
    m = _OVERRIDES.get(key)
    if m is None:
        if len(_OVERRIDES) > 256:
            _OVERRIDES.clear()
        m = _OVERRIDES[key] = mat.with_overrides({"sss_model": model})
    return m


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
    kernel: object
    size: int


def scattering_material(node, settings, plan, label: str):
    """The node's effective material if it scatters below the surface, else None (skip recorded)."""
    mat = effective_material(node, settings)
    if not mat.has_subsurface:
        why = (
            "sss_model is none"
            if mat["sss_model"] == "none"
            else "subsurface weight is 0"
            if mat["subsurface"] <= 0
            else "subsurface_radius is 0"
        )
        plan.skipped.append((label, f"material '{mat.name}': {why}; plain diffuse"))
        return None
    return mat


def plan_tsd_node(node, settings, scene, plan) -> TsdNodePlan | None:
    """Decide TSD for one visible mesh node; record skips and warnings in `plan`."""
    label = f"tsd[{node.name}]"
    mat = scattering_material(node, settings, plan, label)
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
    size = settings.tsd_size
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
    fit = profile_fit(mat["sss_model"], material_medium(mat.values), settings.tsd_gaussians)
    kernel = design_kernel(fit, max(p10, 1e-9), p50, taps=settings.tsd_taps)
    for what, why in kernel.skipped:
        plan.skipped.append((f"{label} {what}", why))
    if kernel.levels == 0:
        plan.skipped.append(
            (label, "every Gaussian of the profile is narrower than a texel or negligible; plain diffuse")
        )
        return None
    return TsdNodePlan(node, mat, kernel, size)
