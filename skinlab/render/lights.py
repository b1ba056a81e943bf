"""Light uniforms shared by every pass that lights surfaces (skinlab/shaders/lib/lights.glsl)."""

from __future__ import annotations

import numpy as np

from skinlab.gl.uniforms import set_array, set_uniforms

SHADOW_SLOTS = 2  # shadow maps u_shadow0, u_shadow1 (skinlab/shaders/lib/shadow.glsl)
SOFT_KEY = "shadow_soft"  # frame.data: slot -> lib/shadow_soft.glsl `soft` (skinlab/render/passes/shadow.py)


def bind_shadow_maps(renderer, frame, prog, units) -> None:
    """Both shadow samplers on units from `units` (TextureUnits); an empty slot gets a 1x1 map. A soft
    slot (a light with a size, SHADOW_SOFT<slot>) also gets its distance map and its parameters."""
    soft = frame.data.get(SOFT_KEY, {})
    for slot in range(SHADOW_SLOTS):
        tex = frame.targets.get(f"shadow_map{slot}")
        units.bind(prog, f"u_shadow{slot}", tex if tex is not None else renderer.dummy_shadow_map())
        fine = frame.targets.get(f"shadow_fine{slot}")
        if fine is not None and f"u_shadow_fine{slot}" in prog:  # a map fitted to the view (SHADOW_FINE<slot>)
            units.bind(prog, f"u_shadow_fine{slot}", fine)
    if soft and ("u_shadow_distance0" in prog or "u_shadow_distance1" in prog):
        for slot in range(SHADOW_SLOTS):
            dist = frame.targets.get(f"shadow_distance{slot}") if slot in soft else None
            units.bind(prog, f"u_shadow_distance{slot}", dist if dist is not None else renderer.dummy_texture())
        rows = [soft.get(slot, np.zeros(4)) for slot in range(SHADOW_SLOTS)]
        set_array(prog, "u_shadow_soft", np.array(rows), SHADOW_SLOTS)
        set_array(prog, "u_shadow_eye", np.stack([frame.shadow_eyes.get(s, np.zeros(4)) for s in range(2)]), 2)


def soft_shadow(light) -> bool:
    """Whether the light's shadow is soft (it has a size: lib/shadow_soft.glsl)."""
    return getattr(light, "size", 0.0) > 0.0


def light_defines(shadow_lights, nmax: int, frame=None) -> dict:
    """The variant defines of a program that lights surfaces (skinlab/shaders/lib/lights.glsl): MAX_LIGHTS,
    and SHADOW_SLOTS, the shadow-map slots this frame fills (the others' lookups are compiled out);
    SHADOW_SOFT<slot> for a slot whose light has a size (soft shadows, lib/shadow_soft.glsl);
    SHADOW_FINE<slot> for a slot the frame gave a map fitted to the view (skinlab/render/shadow_fit.py);
    SSS_ENTRY_SPREAD where the frame's settings spread the oblique entry's shadow (RenderSettings.entry_spread,
    lib/surface_inputs.glsl sss_entry_ramp)."""
    soft = {f"SHADOW_SOFT{k}": 1 for k, l in enumerate(shadow_lights[:SHADOW_SLOTS]) if soft_shadow(l)}
    fine: dict = {}
    if frame is not None:
        fine = {f"SHADOW_FINE{k}": 1 for k in range(SHADOW_SLOTS) if f"shadow_fine{k}" in frame.targets}
        if frame.settings.entry_spread:
            fine["SSS_ENTRY_SPREAD"] = 1
    return {"MAX_LIGHTS": nmax, "SHADOW_SLOTS": min(len(shadow_lights), SHADOW_SLOTS), **soft, **fine}


def area_defines(lights) -> dict:
    """AREA_LIGHTS when the forward pass's lights include an area light (its specular's representative
    point, passes/forward.frag)."""
    return {"AREA_LIGHTS": 1} if any(getattr(l, "is_area", False) for l in lights) else {}


def near_defines(lights) -> dict:
    """NEAR_LIGHTS: 1 when `lights` (those a pass uploads, set_light_uniforms) hold a point or spot light
    (lib/sss_near_light.glsl sss_light_is_near), else 0: the subsurface factors of a light at a finite
    distance are then compiled out (each is 1 for the other kinds)."""
    return {"NEAR_LIGHTS": int(any(l.kind in NEAR_KINDS for l in lights))}


NEAR_KINDS = ("point", "spot")  # lights at a finite distance (lib/sss_near_light.glsl sss_light_is_near)

LIGHT_KIND_CODE = {"directional": 0.0, "point": 0.0, "spot": 1.0, "rect": 2.0, "sphere": 3.0}


def light_shape(light) -> tuple[np.ndarray, np.ndarray]:
    """(axis, shape) of lib/lights.glsl for one light: axis = (the way it shines, kind code); shape: a
    spot's (outer half-angle in radians, 1 / (outer - inner), 0, 0), a sphere's (radius, 0, 0, 0), a
    rect's (half-width vector, half-height) in world units; zeros for the others."""
    axis = np.append(light.direction, LIGHT_KIND_CODE[light.kind])
    shape = np.zeros(4)
    if light.kind == "spot":
        outer, inner = np.radians(light.outer_deg), np.radians(light.inner_deg)
        shape[:2] = outer, 1.0 / max(outer - inner, 1e-4)
    elif light.kind == "sphere":
        shape[0] = light.radius
    elif light.kind == "rect":
        hx, hy = light.half_extents()
        shape[:3], shape[3] = hx, np.linalg.norm(hy)
    return axis, shape


def set_light_uniforms(prog, frame, lights, shadow_lights, nmax: int) -> None:
    """Upload lights (direction or position, radiance, shape, shadow slot), the light each filled shadow slot
    holds (u_slot_light: every shadow light must be among `lights`) and shadow matrices to `prog`."""
    slots = {id(l): i for i, l in enumerate(shadow_lights)}
    vec = [
        np.append(-l.direction, 0.0) if l.kind == "directional" else np.append(l.world_position, 1.0) for l in lights
    ]
    shapes = [light_shape(l) for l in lights]
    set_array(prog, "u_light_axis", np.array([a for a, _ in shapes]).reshape(-1, 4), nmax)
    set_array(prog, "u_light_shape", np.array([b for _, b in shapes]).reshape(-1, 4), nmax)
    set_uniforms(
        prog,
        {
            "u_num_lights": len(lights),
            "u_mm_per_unit": frame.scene.mm_per_unit,
        },
    )
    set_array(prog, "u_light_vec", np.array(vec).reshape(-1, 4), nmax)
    set_array(prog, "u_light_radiance", np.array([l.radiance for l in lights]).reshape(-1, 3), nmax)
    if "u_light_shadow" in prog:
        ids = np.full(nmax, -1, np.int32)
        ids[: len(lights)] = [slots.get(id(l), -1) for l in lights]
        prog["u_light_shadow"].write(ids[: max(prog["u_light_shadow"].array_length, 1)].tobytes())
    if "u_slot_light" in prog:  # the light each filled slot holds (shaded per slot: lib/lights.glsl)
        slot_light = np.full(SHADOW_SLOTS, -1, np.int32)
        for k, light in enumerate(shadow_lights[:SHADOW_SLOTS]):
            at = [j for j, x in enumerate(lights) if x is light]
            if not at:
                raise ValueError(f"shadow light {light.name!r} is not among the {len(lights)} lights the pass shades")
            slot_light[k] = at[0]
        u = prog["u_slot_light"]
        u.write(slot_light[: max(u.array_length, 1)].tobytes())
    for name, held in (
        ("u_shadow_matrix", frame.shadow_matrices),
        ("u_shadow_fine_matrix", frame.shadow_fine_matrices),
    ):
        if name in prog:
            mats = np.stack([held.get(s, np.eye(4)).T for s in (0, 1)]).astype(np.float32)
            prog[name].write(mats[: max(prog[name].array_length, 1)].tobytes())
