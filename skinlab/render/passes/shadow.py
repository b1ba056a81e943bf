"""Shadow maps: depth from a light. A directional light's orthographic map is fitted to the scene's
bounding box as the light sees it (the box's corners in light space), so that its texels are as
small as the box allows; a point light's perspective map is fitted to the bounding sphere."""

from __future__ import annotations

import math
from typing import NamedTuple

import moderngl
import numpy as np

from skinlab.gl.state import gl_state
from skinlab.gl.uniforms import set_uniforms
from skinlab.render.alpha import bind_mask, blended, mask_defines
from skinlab.render.frame_plan import ShadowParams
from skinlab.render.gpu_resources import node_uniforms
from skinlab.render.lights import SOFT_KEY, soft_shadow
from skinlab.render.shadow_facing import AWAY, TOWARD, layer_triangles
from skinlab.render.shadow_fit import ShadowWindow
from skinlab.render.technique import RenderPass
from skinlab.render.texture_units import TextureUnits
from skinlab.render.translucency import part_gap, part_layer_size
from skinlab.scene import transform as tf
from skinlab.scene.graph import LightNode


class ShadowMap(NamedTuple):
    """A slot's depth map: the depth texture (compared), its framebuffer and, for lights whose
    translucency reads it, the first surface's distance from the light (R32F)."""

    depth: moderngl.Texture
    fbo: moderngl.Framebuffer
    distance: moderngl.Texture | None

    def release(self) -> None:
        for x in (self.fbo, self.depth, self.distance):
            if x is not None:
                x.release()


class PartLayers(NamedTuple):
    """A slot's part layers for light through thin parts (skinlab/render/translucency.py
    part_layer_size texels per side): the exit from the first part (RG32F) and the entry into the
    next (R32F), each with its framebuffer, and the depth buffer the two share."""

    exit: moderngl.Texture
    exit_fbo: moderngl.Framebuffer
    entry: moderngl.Texture
    entry_fbo: moderngl.Framebuffer
    depth: moderngl.Renderbuffer

    def release(self) -> None:
        for x in (self.exit_fbo, self.entry_fbo, self.exit, self.entry, self.depth):
            x.release()


# maps clip space [-1, 1] to texture space [0, 1]
CLIP_TO_TEXTURE = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1.0]])


FIT_MARGIN = 0.01  # the fitted box grows by this fraction of its size each side (no geometry on the clip planes)


def box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 8 corners of an axis-aligned box, (8, 3)."""
    return np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)], np.float64)


def light_view_proj(light: LightNode, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-6)
    if light.kind == "directional":
        d = light.direction
        eye = centre - d * 2 * radius
        view = np.linalg.inv(tf.compose(eye, tf.look_at_rotation(eye, centre), np.ones(3)))
        # the box's extent across and along the light: the map covers exactly that (plus a margin),
        # not the bounding sphere's square (up to 1.7x smaller texels on a flat scene)
        c = box_corners(lo, hi) @ view[:3, :3].T + view[:3, 3]
        pad = FIT_MARGIN * (c.max(0) - c.min(0)) + 1e-6 * radius
        x0, y0, z0 = c.min(0) - pad
        x1, y1, z1 = c.max(0) + pad
        shift = np.eye(4)
        shift[:2, 3] = -(x0 + x1) / 2, -(y0 + y1) / 2
        return tf.orthographic((x1 - x0) / 2, (y1 - y0) / 2, -z1, -z0) @ shift @ view
    pos = light.world_position
    dist = float(np.linalg.norm(centre - pos))
    if dist <= radius * 1.01:
        raise ValueError(
            f"light {light.name!r}: a shadow-casting point light must be outside the scene's "
            f"bounding sphere (distance {dist:.3g} <= radius {radius:.3g})"
        )
    fov = 2 * np.arcsin(radius / dist)
    view = np.linalg.inv(tf.compose(pos, tf.look_at_rotation(pos, centre), np.ones(3)))
    return tf.perspective(fov, 1.0, max(dist - radius, 1e-4), dist + radius) @ view


def light_eye(light: LightNode) -> np.ndarray:
    """The light's position (w = 1) or the direction its light travels (w = 0)."""
    return np.append(light.direction, 0.0) if light.kind == "directional" else np.append(light.world_position, 1.0)


def soft_parameters(light: LightNode, m: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """lib/shadow_soft.glsl's `soft` for a light with a size and its texture-space shadow matrix `m`:
    (size: tan of a directional light's angular radius or a local light's radius, 0 directional / 1
    local, uv per scene unit across the light's view (at unit distance for a local light), the
    scene's diameter)."""
    centre = (lo + hi) / 2
    diameter = max(float(np.linalg.norm(hi - lo)), 1e-6)
    local = light.kind != "directional"
    d = light.direction if not local else centre - light.world_position
    d = d / np.linalg.norm(d)
    side = np.cross(d, [0.0, 1.0, 0.0] if abs(d[1]) < 0.9 else [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    eps = 1e-3 * diameter

    def uv(x):
        q = m @ np.append(x, 1.0)
        return q[:2] / q[3]

    k = float(np.linalg.norm(uv(centre + side * eps) - uv(centre)) / eps)
    if local:
        k *= float(np.linalg.norm(centre - light.world_position))
    size = math.tan(light.size) if not local else light.size
    return np.array([size, float(local), k, diameter])


class LayerSubset:
    """The triangles of one node a distance-map layer draws: `partial` False when it draws them all
    (the mesh's own vertex array), else `vao` over their index buffer (None: no triangle at all);
    `key` what they were chosen from."""

    def __init__(self, key: tuple, partial: bool):
        self.key, self.partial = key, partial
        self.ibo: moderngl.Buffer | None = None
        self.vao: moderngl.VertexArray | None = None

    def release(self) -> None:
        for x in (self.vao, self.ibo):
            if x is not None:
                x.release()


class ShadowPass(RenderPass):
    def __init__(self, renderer):
        super().__init__(renderer)
        self.maps: dict[int, ShadowMap] = {}  # per slot
        self.layers: dict[int, PartLayers] = {}  # per slot whose light has part layers
        # (node uid, facing) -> the triangles a layer draws (skinlab/render/shadow_facing.py), kept
        # while the light and the node hold still
        self._layer_draws: dict[tuple, LayerSubset] = {}

    def target(self, slot: int, size: int, distance: bool = False, layers: bool = False) -> ShadowMap:
        """A slot's ShadowMap, made or remade at `size`. With `distance`, the
        distance texture holds the first surface's distance from the light; with `layers` the slot
        also has the part layers (self.layers[slot], skinlab/shaders/passes/shadow.frag)."""
        t = self.maps.get(slot)
        if t is None or t.depth.size != (size, size) or (t.distance is not None) != distance:
            if t is not None:
                t.release()
            ctx = self.r.ctx
            tex = ctx.depth_texture((size, size))
            tex.compare_func = "<="
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            dist = _float_texture(ctx, size, 1) if distance else None
            fbo = ctx.framebuffer([dist] if dist is not None else [], depth_attachment=tex)
            t = self.maps[slot] = ShadowMap(tex, fbo, dist)
        held = self.layers.get(slot)
        n = part_layer_size(size)
        if held is not None and (not layers or held.exit.size != (n, n)):
            self._release_layers(slot)
            held = None
        if layers and held is None:
            ctx = self.r.ctx
            exit_tex, entry_tex = _float_texture(ctx, n, 2), _float_texture(ctx, n, 1)
            depth = ctx.depth_renderbuffer((n, n))
            self.layers[slot] = PartLayers(
                exit_tex,
                ctx.framebuffer([exit_tex], depth_attachment=depth),
                entry_tex,
                ctx.framebuffer([entry_tex], depth_attachment=depth),
                depth,
            )
        return t

    def _release_layers(self, slot: int) -> None:
        layers = self.layers.pop(slot, None)
        if layers is not None:
            layers.release()

    def release(self) -> None:
        for m in self.maps.values():
            m.release()
        self.maps.clear()
        for slot in list(self.layers):
            self._release_layers(slot)
        for subset in self._layer_draws.values():
            subset.release()
        self._layer_draws.clear()

    def _target(self, p) -> ShadowMap:
        prm: ShadowParams = p.params
        return self.target(prm.slot, p.resolution[0], prm.distance, prm.layers)

    def outputs(self, frame, p) -> tuple:
        """The textures holding the pass's result (reuse across frames, skinlab/render/reuse.py)."""
        tex, _, dist = self._target(p)
        held = self.layers[p.params.slot] if p.params.layers else None
        layers = () if held is None else (held.exit, held.entry)
        return (tex, *(() if dist is None else (dist,)), *layers)

    def publish(self, frame, p) -> None:
        """Hand the slot's maps and matrices to the frame (after run, or when reused)."""
        prm: ShadowParams = p.params
        light, slot = prm.light, prm.slot
        tex, _, dist = self._target(p)
        frame.targets[f"shadow_map{slot}"] = tex
        frame.shadow_eyes[slot] = light_eye(light)
        if dist is not None:
            frame.targets[f"shadow_distance{slot}"] = dist
        if prm.layers:
            held = self.layers[slot]
            frame.targets[f"shadow_exit{slot}"] = held.exit
            frame.targets[f"shadow_entry{slot}"] = held.entry
        lo, hi = frame.scene.world_bounds()
        m = CLIP_TO_TEXTURE @ light_view_proj(light, lo, hi)
        frame.shadow_matrices[slot] = m
        if soft_shadow(light):
            frame.data.setdefault(SOFT_KEY, {})[slot] = soft_parameters(light, m, lo, hi)

    def run(self, frame, p) -> None:
        ctx = self.r.ctx
        prm: ShadowParams = p.params
        light, slot, distance = prm.light, prm.slot, prm.distance
        tex, fbo, dist = self._target(p)
        lo, hi = frame.scene.world_bounds()
        vp = light_view_proj(light, lo, hi)
        if dist is None:
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        else:  # "no surface": as far as it gets
            fbo.clear(1e30, 1e30, 1e30, 1e30, depth=1.0)
        fbo.use()
        # no polygon offset: its slope term (factor x the polygon's depth slope) grows without bound
        # toward an occluder's silhouette in the light's view; the lookup's bias is sized to the
        # texel instead (skinlab/shaders/lib/shadow.glsl)
        with gl_state(ctx, moderngl.DEPTH_TEST):
            self.draw_casters(frame, {"SHADOW_DISTANCE": 1} if distance else {}, {"u_light_eye": light_eye(light)}, vp)
            if prm.layers:
                self._draw_layers(frame, slot, light, vp)
        self.publish(frame, p)

    def draw_casters(
        self, frame, defines: dict, uniforms: dict, vp, textures: dict | None = None, facing: str | None = None
    ) -> None:
        """Every mesh that casts a shadow, each with its program (a masked material's cut-away pixels
        cast no shadow, skinlab/render/alpha.py; a see-through surface, alpha_mode "blend", none).
        `facing` (a layer, under a directional light): only the triangles it can use
        (skinlab/render/shadow_facing.py; the same texels)."""
        for node in frame.scene.mesh_nodes():
            if blended(node.material):
                continue
            prog = self.r.programs.get(
                "passes/shadow.vert", "passes/shadow.frag", {**defines, **mask_defines(node.material)}
            )
            set_uniforms(prog, {**uniforms, **node_uniforms(node), "u_light_view_proj": vp})
            units = TextureUnits(self.r.ctx)
            for sampler, tex in (textures or {}).items():
                units.bind(prog, sampler, tex)
            bind_mask(self.r.resources, prog, node.material, units)
            if facing is not None and uniforms["u_light_eye"][3] == 0.0:
                subset = self._layer_subset(node, prog, facing, uniforms["u_light_eye"][:3])
                if subset is not None:  # else every triangle: the mesh's own vertex array
                    if subset.vao is not None:  # else none of them
                        subset.vao.render(moderngl.TRIANGLES)
                    continue
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)

    def _layer_subset(self, node, prog, facing: str, travel: np.ndarray) -> LayerSubset | None:
        """The triangles of `node` a layer facing `facing` can use, as a vertex array (None in it:
        none of them); None when it needs them all."""
        gm = self.r.resources.mesh(node.mesh)
        key = (id(prog), id(gm.vbo), gm.active, node.mesh.version, node.world_matrix.tobytes(), travel.tobytes())
        held = self._layer_draws.get((node.uid, facing))
        if held is not None and held.key == key:
            return held if held.partial else None
        if held is not None:
            held.release()
        tris = layer_triangles(node, travel, facing)
        subset = LayerSubset(key, tris is not None and len(tris) < node.mesh.indices.size)
        if tris is not None and subset.partial and len(tris):
            subset.ibo = self.r.ctx.buffer(np.ascontiguousarray(tris).tobytes())
            subset.vao = self.r.ctx.vertex_array(
                prog, gm.content(), index_buffer=subset.ibo, index_element_size=4, skip_errors=True
            )
        self._layer_draws[(node.uid, facing)] = subset
        return subset if subset.partial else None

    def _draw_layers(self, frame, slot: int, light: LightNode, vp) -> None:
        """The part layers for light through thin parts (skinlab/shaders/passes/shadow.frag
        SHADOW_LAYER; skinlab/render/translucency.py part_layer_size texels per side): the exit from
        the first part, then the entry into the next."""
        held = self.layers[slot]
        exit_tex, exit_fbo, entry_fbo = held.exit, held.exit_fbo, held.entry_fbo
        eye = light_eye(light)
        exit_fbo.clear(1e30, 0.0, 0.0, 0.0, depth=1.0)
        exit_fbo.use()
        self.draw_casters(frame, {"SHADOW_DISTANCE": 1, "SHADOW_LAYER": 1}, {"u_light_eye": eye}, vp, facing=AWAY)
        entry_fbo.clear(1e30, 1e30, 1e30, 1e30, depth=1.0)
        entry_fbo.use()
        self.draw_casters(
            frame, {"SHADOW_DISTANCE": 1, "SHADOW_LAYER": 2}, {"u_light_eye": eye, "u_part_gap": part_gap(frame)},
            vp, {"u_exit": exit_tex}, facing=TOWARD,
        )  # fmt: skip


class FittedShadowPass(RenderPass):
    """A light's second depth map, fitted to what the camera sees (skinlab/render/shadow_fit.py): the
    same casters as its full map (ShadowPass), drawn through the window's crop. Its own pass, so
    that what reads only the full map (the interreflection) is kept while the camera moves."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self.fine: dict[int, ShadowMap] = {}  # per slot

    def target(self, slot: int, window: ShadowWindow | None) -> ShadowMap | None:
        """A slot's fitted map (depth only) at the window's size, made or remade; None (and any held
        one released) without a window."""
        t = self.fine.get(slot)
        if t is not None and (window is None or t.depth.size != (window.nx, window.ny)):
            t.release()
            del self.fine[slot]
            t = None
        if window is None or t is not None:
            return t
        tex = self.r.ctx.depth_texture((window.nx, window.ny))
        tex.compare_func = "<="
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        t = self.fine[slot] = ShadowMap(tex, self.r.ctx.framebuffer([], depth_attachment=tex), None)
        return t

    def release(self) -> None:
        for m in self.fine.values():
            m.release()
        self.fine.clear()

    def outputs(self, frame, p) -> tuple:
        t = self.target(p.params.slot, p.params.fine)
        return () if t is None else (t.depth,)

    def publish(self, frame, p) -> None:
        prm: ShadowParams = p.params
        t = self.target(prm.slot, prm.fine)
        if t is None or prm.fine is None:
            return
        lo, hi = frame.scene.world_bounds()
        frame.targets[f"shadow_fine{prm.slot}"] = t.depth
        frame.shadow_fine_matrices[prm.slot] = CLIP_TO_TEXTURE @ prm.fine.crop() @ light_view_proj(prm.light, lo, hi)

    def run(self, frame, p) -> None:
        prm: ShadowParams = p.params
        t = self.target(prm.slot, prm.fine)
        if t is not None and prm.fine is not None:
            lo, hi = frame.scene.world_bounds()
            vp = prm.fine.crop() @ light_view_proj(prm.light, lo, hi)
            t.fbo.clear(depth=1.0)
            t.fbo.use()
            with gl_state(self.r.ctx, moderngl.DEPTH_TEST):
                full = self.r.passes["shadow"]  # type: ignore[attr-defined]  # the renderer's (PassHost does not name it)
                assert isinstance(full, ShadowPass)
                full.draw_casters(frame, {}, {"u_light_eye": light_eye(prm.light)}, vp)  # the full map's casters
        self.publish(frame, p)


def _float_texture(ctx, size: int, components: int) -> moderngl.Texture:
    """A size x size float32 texture read texel by texel (the distance maps and part layers)."""
    t = ctx.texture((size, size), components, dtype="f4")
    t.filter = (moderngl.NEAREST, moderngl.NEAREST)
    t.repeat_x = t.repeat_y = False
    return t
