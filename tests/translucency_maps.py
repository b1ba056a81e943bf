"""Distance maps and part layers as textures, and the uniforms of lib/sss_translucency.glsl, for the GLSL
twin tests of the lookups that read them (tests/scene/optics/test_translucency.py, test_single_through.py)."""

import moderngl
import numpy as np

from skinlab.render.boundary import bind_boundary


def distance_texture(ctx, dist: np.ndarray):
    """(H, W) or (H, W, 2) float map as a NEAREST texture."""
    dist = np.asarray(dist)
    h, w = dist.shape[:2]
    comps = 1 if dist.ndim == 2 else dist.shape[2]
    tex = ctx.texture((w, h), comps, np.ascontiguousarray(dist, np.float32).tobytes(), dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return tex


def layer_textures(ctx, layers: np.ndarray):
    """The part layers (H, W, 3: exit, its cosine, next entry) as the shadow pass writes them: the
    exit layer (RG) and the next-entry layer (R)."""
    return distance_texture(ctx, layers[..., :2]), distance_texture(ctx, layers[..., 2])


def no_exit(ctx):
    """Part layers with no surface: one part everywhere (the lookup as without layers)."""
    return layer_textures(ctx, np.array([[[1e30, 0.0, 1e30]]]))


def lookup_setup(maps, matrices, eyes, shrink, mm_per_unit, material=None, exits=(), part_gap=0.0):
    """A GLSLEvaluator setup binding lib/sss_translucency.glsl's uniforms, distance maps and their
    part layers (`exits`, per slot the (exit, entry) textures of layer_textures; no_exit's for one part)."""
    from skinlab.gl.uniforms import set_array, set_uniforms

    def setup(prog):
        for slot, tex in enumerate(maps):
            tex.use(10 + slot)
            if f"u_distance{slot}" in prog:
                prog[f"u_distance{slot}"].value = 10 + slot
        for slot, (tex, entry) in enumerate(exits):
            tex.use(12 + slot)
            entry.use(14 + slot)
            if f"u_exit{slot}" in prog:
                prog[f"u_exit{slot}"].value = 12 + slot
            if f"u_entry{slot}" in prog:
                prog[f"u_entry{slot}"].value = 14 + slot
        if "u_shadow_matrix" in prog:
            mats = np.stack([m.T for m in matrices]).astype(np.float32)
            prog["u_shadow_matrix"].write(mats[: max(prog["u_shadow_matrix"].array_length, 1)].tobytes())
        set_array(prog, "u_light_eye", np.asarray(eyes, np.float64), 2)
        set_uniforms(prog, {"u_thickness_shrink": shrink, "u_mm_per_unit": mm_per_unit, "u_part_gap": part_gap})
        if "u_light_shadow" in prog:
            ids = np.array([0, 1, -1, -1], np.int32)
            prog["u_light_shadow"].write(ids[: max(prog["u_light_shadow"].array_length, 1)].tobytes())
        if material is not None:
            bind_boundary(prog, material)

    return setup
