"""Light uniforms shared by every pass that lights surfaces (skinlab/shaders/lib/lights.glsl)."""

from __future__ import annotations

import numpy as np

from skinlab.gl.uniforms import set_array, set_uniforms

SHADOW_SLOTS = 2  # shadow maps u_shadow0, u_shadow1 (skinlab/shaders/lib/shadow.glsl)


def bind_shadow_maps(renderer, frame, prog, units) -> None:
    """Both shadow samplers on units from `units` (TextureUnits); an empty slot gets a 1x1 map."""
    for slot in range(SHADOW_SLOTS):
        tex = frame.targets.get(f"shadow_map{slot}")
        units.bind(prog, f"u_shadow{slot}", tex if tex is not None else renderer.dummy_shadow_map())


def light_defines(shadow_lights, nmax: int) -> dict:
    """The variant defines of a program that lights surfaces (skinlab/shaders/lib/lights.glsl): MAX_LIGHTS,
    and SHADOW_SLOTS, the shadow-map slots this frame fills (the others' lookups are compiled out)."""
    return {"MAX_LIGHTS": nmax, "SHADOW_SLOTS": min(len(shadow_lights), SHADOW_SLOTS)}


def set_light_uniforms(prog, frame, lights, shadow_lights, nmax: int) -> None:
    """Upload lights (direction or position, radiance, shadow slot) and shadow matrices to `prog`."""
    slots = {id(l): i for i, l in enumerate(shadow_lights)}
    vec = [
        np.append(-l.direction, 0.0) if l.kind == "directional" else np.append(l.world_position, 1.0) for l in lights
    ]
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
    if "u_shadow_matrix" in prog:
        mats = np.stack([frame.shadow_matrices.get(s, np.eye(4)).T for s in (0, 1)]).astype(np.float32)
        prog["u_shadow_matrix"].write(mats[: max(prog["u_shadow_matrix"].array_length, 1)].tobytes())
