"""Light through thin parts, the renderer's side (skinlab/shaders/lib/sss_translucency.glsl; NumPy twin
skinlab/scene/optics/translucency.py): whether a frame plans it, and the uniforms and distance maps of a
program that computes it. Texture-space diffusion's irradiance pass and the forward hooks of the
techniques without a texture-space pass (screen-space SSS, disk, pre-integrated skin) share it, so
every technique transmits the same light through the same thickness."""

from __future__ import annotations

import numpy as np

from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.technique import NodeShading

DEFINE = "SSS_TRANSLUCENCY"  # the forward hooks' variant (skinlab/shaders/techniques/<name>/forward.glsl)
REASON = "translucency through thin parts"  # in the frame plan's reasons
OPTION_DOC = "light through thin parts (needs a shadow-casting light)"  # every technique's `translucency`


def plan_translucency(ctx, needed: bool, enabled: bool) -> bool:
    """Whether the frame computes translucency (PlanContext `ctx`): a visible material scatters
    (`needed`), the technique's setting allows it (`enabled`) and a light casts a shadow (its
    distance map gives the thickness). Records why not in the plan's skips."""
    use = needed and enabled and bool(ctx.shadow_lights)
    if use:  # the thickness is a distance through the mesh: across a hole it reads the far side, or nothing
        from skinlab.scene.mesh_topology import open_mesh_warning

        from .scattering import effective_material

        for node in ctx.meshes:
            if effective_material(node, ctx.settings).has_subsurface:
                line = open_mesh_warning(node.mesh, "translucency (light through thin parts)")
                if line is not None and line not in ctx.plan.warnings:
                    ctx.plan.warnings.append(line)
    if needed and not use:
        ctx.plan.skipped.append(
            ("translucency", "disabled in the settings" if not enabled else "no shadow-casting light")
        )
    return use


# The part layers (the first part's exit and the entry into the next, skinlab/shaders/passes/shadow.frag
# SHADOW_LAYER) have this many times fewer texels per side than the shadow map and its first-surface
# distance map: they only tell which part a point lies in and how thick the first part it crossed
# was (a plane's exit is exact at any size; the first surface, which sets a flat part's own thickness,
# keeps the full size), and their two draws were 60 of the pass's 100 ms on the head at 2048.
PART_LAYER_DIVISOR = 2


def part_layer_size(shadow_size: int) -> int:
    """Texels per side of the part layers of a shadow map `shadow_size` texels per side."""
    return max(int(shadow_size) // PART_LAYER_DIVISOR, 1)


def thickness_shrink(frame) -> float:
    """How far (scene units) the thickness lookup moves the point inward along its normal: half a
    texel of the distance maps, which span the scene's bounding sphere (skinlab/render/passes/shadow.py:
    the orthographic map is 2 r wide; a point light's is about as wide at the scene's centre)."""
    cached = frame.data.setdefault("translucency", {})
    if "shrink" not in cached:
        lo, hi = frame.scene.world_bounds()
        radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 1e-6)
        cached["shrink"] = radius / max(int(frame.settings.shadow_size), 1)
    return cached["shrink"]


# A surface farther along the light than the first part's exit by more than this many texels of the
# distance maps (2 x thickness_shrink each; PART_LAYER_DIVISOR times fewer of the part layers')
# belongs to another part: its light crossed the first part, then air (skinlab/shaders/passes/shadow.frag
# SHADOW_LAYER; lib/sss_translucency.glsl). Kept in distance-map texels when the layers were halved:
# against the back-lit ear's truth the gap of four layer texels let 0.3 points more blue through
# (docs/tsd.md "Third round").
PART_GAP_TEXELS = 4.0


def part_gap(frame) -> float:
    """Scene units: how far past the first part's exit a surface must lie to be another part."""
    return PART_GAP_TEXELS * 2.0 * thickness_shrink(frame)


def bind_translucency(prog, frame, units, fallback=None) -> None:
    """The distance maps and their part layers (u_distance0/1, u_exit0/1, u_entry0/1 on units from `units`), the
    lights' eyes, the shrink and the part gap for lib/sss_translucency.glsl. A slot without a
    distance map gets the other slot's (never sampled: no light points at it) or `fallback` (a
    texture) when neither has one."""
    for name in ("distance", "exit", "entry"):
        maps = [frame.targets.get(f"shadow_{name}{slot}") for slot in (0, 1)]
        present = [m for m in maps if m is not None] or [fallback]
        for slot, m in enumerate(maps):
            tex = m if m is not None else present[0]
            if tex is None:
                raise RuntimeError(f"translucency: no shadow {name} map this frame and no fallback texture")
            units.bind(prog, f"u_{name}{slot}", tex)
    eyes = np.stack([frame.shadow_eyes.get(s, np.zeros(4)) for s in (0, 1)])
    set_array(prog, "u_light_eye", eyes, 2)
    set_uniforms(prog, {"u_thickness_shrink": thickness_shrink(frame), "u_part_gap": part_gap(frame)})


def translucent_shading(material, hook: str, frame, through: bool, bind, subsurface: bool = True) -> NodeShading:
    """A forward hook's NodeShading that adds the light through thin parts where `through`: the
    hook's SSS_TRANSLUCENCY variant, and the distance maps bound after the hook's own `bind(prog,
    units)`. Shared by the hooks of screen-space SSS, the disk technique and pre-integrated skin."""

    def bind_all(prog, units):
        bind(prog, units)
        if through:
            bind_translucency(prog, frame, units)

    return NodeShading(material, hook, {DEFINE: 1} if through else {}, bind_all, subsurface=subsurface)
