"""Which material a mesh is shaded with this frame and whether it scatters below the surface (the
questions every technique's planning asks first)."""

from __future__ import annotations

_OVERRIDES: dict = {}


def effective_material(node, settings):
    """The node's material, with sss_model replaced when the settings override it for every material."""
    mat = node.material
    if settings.sss_model is not None and mat["sss_model"] != settings.sss_model:
        mat = _override(mat, settings.sss_model)
    return mat


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
