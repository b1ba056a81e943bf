"""GPU copies of scene data: vertex buffers per mesh, textures per file. Owned by the renderer."""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_uniforms
from skinlab.scene.mesh import Mesh
from skinlab.scene.textures import load_texture

from .vertex_streams import VertexStream

VERTEX_FORMAT = "3f 3f 2f 4f 4f"
# in_color: the vertex colour (glTF COLOR_0, linear RGBA; 1 where the mesh has none), multiplying the
# base colour and alpha. A technique's extra inputs (pre-integrated skin's in_curvature) are its
# vertex streams (skinlab/render/vertex_streams.py), in buffers of their own
VERTEX_ATTRS = ("in_position", "in_normal", "in_uv", "in_tangent", "in_color")


class GpuMesh:
    def __init__(self, ctx: moderngl.Context, mesh: Mesh):
        self.ctx = ctx
        self.mesh = mesh
        self.version = mesh.version
        n = len(mesh.positions)
        uv = mesh.uvs if mesh.uvs is not None else np.zeros((n, 2), np.float32)
        if mesh.uvs is not None:
            tan = mesh.ensure_tangents()
        else:
            tan = np.tile(np.array([1, 0, 0, 1], np.float32), (n, 1))
        col = mesh.colors if mesh.colors is not None else np.ones((n, 4), np.float32)
        data = np.concatenate([mesh.positions, mesh.normals, uv, tan, col], axis=1).astype(np.float32)
        self.vbo = ctx.buffer(np.ascontiguousarray(data).tobytes())
        self.ibo = ctx.buffer(mesh.indices.astype(np.uint32).tobytes())
        self.count = mesh.indices.size
        self.streams: dict[VertexStream, moderngl.Buffer] = {}  # the extra streams uploaded so far
        self.active: tuple[VertexStream, ...] = ()  # those the current frame's technique asks for
        self._vaos: dict[tuple, moderngl.VertexArray] = {}

    def use_streams(self, streams: tuple[VertexStream, ...]) -> bool:
        """Make `streams` the ones bound (computed and uploaded on first use); True if any was uploaded."""
        uploaded = False
        for s in streams:
            if s not in self.streams:
                n = len(self.mesh.positions)
                data = np.asarray(s.compute(self.mesh), np.float32).reshape(n, -1)
                self.streams[s] = self.ctx.buffer(np.ascontiguousarray(data).tobytes())
                uploaded = True
        self.active = streams
        return uploaded

    def content(self) -> list[tuple]:
        """The vertex array content: the common buffer and the active streams'."""
        extra = [(self.streams[s], s.format, s.attribute) for s in self.active]
        return [(self.vbo, VERTEX_FORMAT, *VERTEX_ATTRS), *extra]

    def vao(self, program: moderngl.Program, indices: moderngl.Buffer | None = None) -> moderngl.VertexArray:
        """The vertex array of `program` over this mesh's vertices, indexed by its own triangles or
        by `indices` (a uint32 index buffer into its vertices, e.g. its triangles reordered)."""
        ibo = self.ibo if indices is None else indices
        key = (id(program), self.active, id(ibo))
        vao = self._vaos.get(key)
        if vao is None or vao.program is not program or vao.index_buffer is not ibo:
            if vao is not None:
                vao.release()
            vao = self.ctx.vertex_array(
                program, self.content(), index_buffer=ibo, index_element_size=4, skip_errors=True
            )
            self._vaos[key] = vao
        return vao

    def release(self) -> None:
        for v in self._vaos.values():
            v.release()
        for b in self.streams.values():
            b.release()
        self.vbo.release()
        self.ibo.release()


def node_uniforms(node) -> dict:
    """A mesh node's transform uniforms (forward.vert; a technique's vertex shaders that read u_model)."""
    model = node.world_matrix
    return {"u_model": model, "u_normal_matrix": np.linalg.inv(model[:3, :3]).T}


HALF_MAX = float(np.finfo(np.float16).max)


class GpuResources:
    """Caches GPU meshes (by Mesh identity and version) and textures (by path and colour space)."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.meshes: dict[int, GpuMesh] = {}
        self.textures: dict[tuple[str, str], moderngl.Texture] = {}
        self.uploads = 0
        # the extra vertex streams of the current frame's technique (Renderer sets them per frame)
        self.vertex_streams: tuple[VertexStream, ...] = ()
        self._isotropic: moderngl.Sampler | None = None
        self._sampled_units: set[int] = set()

    def mesh(self, mesh: Mesh) -> GpuMesh:
        g = self.meshes.get(mesh.uid)
        if g is None or g.version != mesh.version:
            if g is not None:
                g.release()
            g = self.meshes[mesh.uid] = GpuMesh(self.ctx, mesh)
            self.uploads += 1
        if g.active != self.vertex_streams and g.use_streams(self.vertex_streams):
            self.uploads += 1
        return g

    def texture(self, path: Path, colorspace: str) -> moderngl.Texture:
        key = (str(path), colorspace)
        tex = self.textures.get(key)
        if tex is None:
            img = load_texture(path, colorspace)
            h, w, c = img.shape
            if c == 2:
                img = np.concatenate([img, np.zeros((h, w, 1), np.float32)], 2)
                c = 3
            # row 0 of the file is the top; OpenGL's v = 0 is the bottom row. Half floats hold what 8-bit
            # and most float maps need in half the memory; a map beyond their range (65504: an EXR of
            # 1e6) would overflow to Inf, so it stays float32
            dtype = "f2" if float(np.abs(img).max(initial=0.0)) <= HALF_MAX else "f4"
            data = np.ascontiguousarray(img[::-1].astype(np.float16 if dtype == "f2" else np.float32))
            tex = self.ctx.texture((w, h), c, data.tobytes(), dtype=dtype)
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            tex.anisotropy = 8.0
            tex.repeat_x = tex.repeat_y = True
            self.textures[key] = tex
            self.uploads += 1
        return tex

    def bind_material(self, prog: moderngl.Program, material, units, isotropic: bool = False) -> None:
        """The material's plain values as uniforms and its maps on units from `units` (TextureUnits).
        `isotropic`: the maps filtered trilinearly, without the anisotropic filtering the screen-space
        passes want at grazing angles (a sampler object on their units until :meth:`unbind_samplers`).
        For passes that rasterise in UV space, where a texel's footprint on the map is a square: a GPU
        takes one probe there, which is trilinear filtering, while llvmpipe's anisotropic filter (an
        elliptical average) differs from it, changes with the last bit of the derivatives and costs
        a third of the texture-space irradiance pass."""
        set_uniforms(prog, material.uniforms())
        for sampler, (path, cs) in material.textures().items():
            unit = units.bind(prog, sampler, self.texture(path, cs))
            if isotropic:
                self.isotropic_sampler().use(unit)
                self._sampled_units.add(unit)

    def isotropic_sampler(self) -> moderngl.Sampler:
        """The maps' filtering (trilinear, repeat) without anisotropy (bind_material's `isotropic`)."""
        if self._isotropic is None:
            self._isotropic = self.ctx.sampler(filter=(moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR), anisotropy=1.0)
        return self._isotropic

    def unbind_samplers(self) -> None:
        """Back to each texture's own filtering on the units bind_material gave a sampler object."""
        if self._isotropic is not None:  # units are given it only once it is made
            for unit in self._sampled_units:
                self._isotropic.clear(unit)
        self._sampled_units.clear()

    def release(self) -> None:
        if self._isotropic is not None:
            self.unbind_samplers()
            self._isotropic.release()
            self._isotropic = None
        for g in self.meshes.values():
            g.release()
        for t in self.textures.values():
            t.release()
        self.meshes.clear()
        self.textures.clear()
