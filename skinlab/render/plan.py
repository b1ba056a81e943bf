"""The frame is planned from the scene: a pass runs only when something visible needs it."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .bounce import plan_bounce, prefetch_bounce
from .boundary import prefetch_boundaries
from .compute import Device, choose_path
from .environment import plan_environment, plan_sky, prefetch_sky
from .frame_plan import FramePlan, PlannedPass, ShadowParams, TonemapParams, shadow_fit_pass_name, shadow_pass_name
from .lights import soft_shadow
from .registry import get_technique
from .reuse import light_placement, scene_geometry
from .technique import ForwardParams, PlanContext
from .through_kernel import plan_through
from .translucency import part_layer_size

if TYPE_CHECKING:
    from skinlab.scene.graph import LightNode, Scene

    from .settings import RenderSettings

# the path `compute = auto` takes for tone mapping on software GL (measured: docs/architecture.md)
TONEMAP_ON_SOFTWARE = "fragment"

__all__ = ["FramePlan", "PlannedPass", "ShadowParams", "ForwardParams", "plan_frame"]


def soft_size(light: LightNode) -> str:
    """A light's size as the plan says it."""
    if light.kind == "directional":
        return f"angular radius {math.degrees(light.angular_radius):.2g} deg"
    return f"radius {light.size:.3g} scene units"


def fitted_window(scene: Scene, settings: RenderSettings, light: LightNode, geometry: tuple):
    """The light's second shadow map fitted to what the camera sees (skinlab/render/shadow_fit.py), or None."""
    from .passes.shadow import light_view_proj
    from .shadow_fit import FIT_MAX_TEXELS, shadow_window

    lo, hi = scene.world_bounds()
    try:
        clip = light_view_proj(light, lo, hi)
    except ValueError:  # a point light inside the scene: the shadow pass says so
        return None
    size = settings.shadow_size
    samples = settings.render_size
    return shadow_window(scene, clip, samples, size, min(FIT_MAX_TEXELS, 8 * size), geometry)


def plan_frame(scene: Scene, settings: RenderSettings, state=None, device: Device | None = None) -> FramePlan:
    """Passes for this frame: shadow maps, interreflection (skinlab/render/bounce.py), the technique's
    passes (registry), the forward pass with
    the technique's shading hook, tone mapping. ``state``: the technique's renderer-side state (its
    caches, e.g. texture-space diffusion's stretch maps); None plans as if nothing were cached.
    ``device``: what the GL context can do (skinlab/render/compute.py: compute shaders); None plans the
    fragment path everywhere."""
    meshes = scene.mesh_nodes()
    n = settings.supersample
    plan = FramePlan([], warnings=list(getattr(scene, "warnings", ())))  # the scene's own first (loading)
    # the environment map's passes and its bright sources as lights, after the scene's own
    environment, env_lights = plan_environment(scene, settings, meshes, plan)
    lights = scene.lights() + env_lights
    if len(lights) > settings.max_lights:
        plan.skipped.append(
            (
                f"{len(lights) - settings.max_lights} light(s)",
                f"more than {settings.max_lights} lights; the first {settings.max_lights} are used",
            )
        )
        lights = lights[: settings.max_lights]
    shadow_lights: list[LightNode] = [l for l in lights if l.cast_shadow]
    for l in lights:
        if not l.cast_shadow:
            plan.skipped.append((f"shadow[{l.name}]", "light does not cast shadows"))
    if not meshes:
        plan.skipped.append(("shadows", "no visible mesh"))
        shadow_lights = []
    technique = get_technique(settings.technique_name)
    prefetch_bounce(scene, settings, meshes, lights)  # rays are cast while the technique plans
    prefetch_sky(scene, settings, meshes)  # (the same records, for what the scene hides of the map)
    prefetch_boundaries(meshes, settings)  # the materials' boundary tables, for the frame's binds
    tp = technique.plan(PlanContext(scene, settings, meshes, lights, shadow_lights[:2], plan, state, device))
    plan.vertex_streams = tuple(technique.vertex_streams) if meshes else ()
    sky = plan_sky(scene, settings, meshes, plan, environment)
    if sky is not None:
        environment.append(sky)
    distance = tp.shadow_distance and bool(shadow_lights)
    layer_size = part_layer_size(settings.shadow_size)
    geometry = scene_geometry(scene) if shadow_lights else ()
    plan.passes += environment
    fitted: list[str] = []
    for slot, l in enumerate(shadow_lights[:2]):
        soft = soft_shadow(l)  # a light with a size: soft shadows from the distance map too
        dist = distance or soft
        why = [w for w, on in (("translucency", distance), ("soft shadows", soft)) if on]
        fine = fitted_window(scene, settings, l, geometry) if settings.shadow_fit and not soft else None
        plan.passes.append(
            PlannedPass(
                shadow_pass_name(l),
                "shadow",
                f"shadow_map{slot}" + (f"+shadow_distance{slot}" if dist else ""),
                (settings.shadow_size, settings.shadow_size),
                f"{l.kind} light '{l.name}' casts shadows on {len(meshes)} visible mesh(es)"
                + (f"; distance map for {' and '.join(why)}" if dist else "")
                + (f" (the parts' exit and next entry at {layer_size}x{layer_size})" if distance else "")
                + (f" ({soft_size(l)})" if soft else ""),
                ShadowParams(l, slot, dist, distance),
                inputs=(slot, dist, distance, light_placement(l), geometry),
            )
        )
        if fine is not None:
            plan.passes.append(
                PlannedPass(
                    shadow_fit_pass_name(l),
                    "shadow_fit",
                    f"shadow_fine{slot}",
                    (fine.nx, fine.ny),
                    f"the camera sees {100 * (fine.x1 - fine.x0) * (fine.y1 - fine.y0) / 4:.2g} % of light "
                    f"'{l.name}''s map: a second map over that window, {fine.gain:.1f}x finer texels",
                    ShadowParams(l, slot, False, False, fine),
                    inputs=(slot, light_placement(l), geometry, fine),
                )
            )
            fitted.append(shadow_fit_pass_name(l))
    # what lights surfaces from the shadow maps kept across frames reads the fitted ones too (the
    # interreflection does not: its senders are mostly out of view, and it is kept while the camera moves)
    for p in tp.before_forward:
        if fitted and p.reads_light and any(a.startswith("shadow[") for a in p.after):
            p.after = (*p.after, *fitted)
    for l in shadow_lights[2:]:
        plan.skipped.append((f"shadow[{l.name}]", "at most 2 shadow-casting lights"))
    bounce = plan_bounce(scene, settings, meshes, lights, shadow_lights[:2], plan)
    for p in bounce:  # the environment's light bounces too
        p.after = (*p.after, *(e.name for e in environment))
    plan.passes += bounce
    through = plan_through(scene, settings, meshes, lights, shadow_lights[:2], plan, distance)
    plan.passes += through
    # bounce and environment light are ambient light: every pass of the technique that is kept
    # across frames reads them (its inputs hold the environment's rotation and intensity); the light
    # through thin parts is carried as bounce light
    ambient = [e.name for e in environment] + ([bounce[-1].name] if bounce else []) + [t.name for t in through]
    for p in tp.before_forward:
        if p.inputs is not None and ambient and p.reads_light:
            p.after = (*p.after, *ambient)
    plan.passes += tp.before_forward
    hook = tp.forward
    plan.passes.append(
        PlannedPass(
            "forward",
            "forward",
            "+".join(["hdr_color", "depth", *hook.outputs]),
            settings.render_size,
            (f"{n} x {n} samples per output pixel (supersample); " if n > 1 else "")
            + ("depth pre-pass, then " if settings.depth_prepass else "")
            + f"shade {len(meshes)} visible mesh(es) with {len(lights)} light(s)"
            + hook.reason
            + (
                "; single scattering along the light's path inside from the distance maps (single_through)"
                if distance and settings.single_through
                else ""
            ),
            ForwardParams(lights, shadow_lights[:2], hook),
        )
    )
    plan.passes += tp.after_forward
    path = choose_path(settings, device, TONEMAP_ON_SOFTWARE)
    plan.passes.append(
        PlannedPass(
            "tonemap",
            "tonemap",
            "ldr_color" + ("+hdr_filtered" if n > 1 else ""),
            settings.size,
            (f"box filter of each pixel's {n} x {n} samples (linear radiance), then " if n > 1 else "")
            + "ACES tone mapping and sRGB encoding for display/PNG"
            + path.note,
            TonemapParams(path.compute),
        )
    )
    return plan
