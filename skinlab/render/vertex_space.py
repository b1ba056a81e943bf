"""Vertex-space GPU targets and tables, shared by the passes that work per mesh vertex (the
interreflection, skinlab/render/bounce.py; the light through thin parts, skinlab/render/through_kernel.py):
vertex i of the frame's meshes at texel (i % VERTEX_TEXTURE_WIDTH, i / VERTEX_TEXTURE_WIDTH), row r of
a table at (r % width, r / width), a mesh's vertices as a texture its fullscreen draws read."""

from __future__ import annotations

import math

import moderngl
import numpy as np

VERTEX_TEXTURE_WIDTH = 1024  # vertex-space targets: vertex i at texel (i % width, i / width)
RECORD_TEXTURE_WIDTH = 4096  # tables of records: row r at texel (r % width, r / width)


def vertex_target_size(vertices: int) -> tuple[int, int]:
    return VERTEX_TEXTURE_WIDTH, max(1, math.ceil(vertices / VERTEX_TEXTURE_WIDTH))


def float_target(ctx, size, held=None) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
    """An RGBA float32 target of `size` with its framebuffer, nearest filtering; `held` (such a pair)
    is returned as it is when its size matches, else released and replaced."""
    if held is not None and held[0].size == tuple(size):
        return held
    if held is not None:
        held[1].release()
        held[0].release()
    tex = ctx.texture(size, 4, dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return tex, ctx.framebuffer([tex])


def upload_rows(ctx, rows: np.ndarray, width: int) -> moderngl.Texture:
    """Rows of 1 to 4 floats as a float texture, row r at texel (r % width, r / width)."""
    n, c = rows.shape
    height = max(1, math.ceil(n / width))
    padded = np.zeros((height * width, c), np.float32)
    padded[:n] = rows
    tex = ctx.texture((width, height), c, padded.tobytes(), dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return tex


def vertex_data_texture(ctx, mesh) -> moderngl.Texture:
    """The mesh's positions, normals and UVs as a texture, vertex j at texels (3 (j % 1024) + k,
    j / 1024), k = 0, 1, 2 (passes/bounce_exitance.frag, passes/through_entering.frag u_vertex_data)."""
    n = len(mesh.positions)
    height = max(1, math.ceil(n / VERTEX_TEXTURE_WIDTH))
    padded = np.zeros((height * VERTEX_TEXTURE_WIDTH, 3, 4), np.float32)
    padded[:n, 0, :3] = mesh.positions
    padded[:n, 1, :3] = mesh.normals
    if mesh.uvs is not None:
        padded[:n, 2, :2] = mesh.uvs
    tex = ctx.texture((3 * VERTEX_TEXTURE_WIDTH, height), 4, padded.tobytes(), dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return tex
