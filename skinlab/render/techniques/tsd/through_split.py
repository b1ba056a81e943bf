"""Which of a mesh's triangles can read light through thin parts from the irradiance pass's record
(skinlab/render/techniques/tsd/passes.py TsdNodeTargets.through_record), per shadow slot, so that the
forward pass draws each triangle with the gather's exit factor of that light for the slots it can read
only (skinlab/shaders/techniques/tsd/forward.glsl, TSD_THROUGH_READ: a mask of the slots; 0 none).

The gather reads the record at the fragment's interpolated uv with nearest filtering and clamp to edge:
the texel floor(uv x size), clamped to the texture. A fragment inside a triangle has its uv inside the
triangle's UV bounding box, so it reads a texel of the box's texels; `MARGIN_TEXELS` more on every
side keep a fragment whose uv the interpolation put a rounding past the box's edge. A triangle none
of whose box's texels holds a slot's light reads only records of zero light from it, for which the
exit factor's difference adds exactly 0 (its factor is finite: skinlab/shaders/lib/sss_boundary.glsl
sss_slab_exit divides by at least 1e-30), so drawing it without that slot's exit factor gives the same
image. On llvmpipe a branch's arithmetic runs even where no fragment of a group takes it (docs/tsd.md,
"Fifth round"): only a variant without the code saves it. A triangle with a UV that is not finite
reads every slot."""

from __future__ import annotations

import numpy as np

MARGIN_TEXELS = 1
BLOCK_TEXELS = 4  # the record's texels are looked up in square blocks of this side (any lit texel lights its block)


def through_triangles(uvs: np.ndarray, indices: np.ndarray, lit: np.ndarray, block: int = BLOCK_TEXELS) -> np.ndarray:
    """Per triangle (indices (M, 3) into uvs (N, 2), OpenGL convention) whether a fragment inside it can
    read a texel where `lit` (H, W bool, row 0 at v = 0) is true. The texels are taken in `block` x
    `block` blocks (a block is lit if any of its texels is; a triangle reads the blocks its texels lie
    in): more triangles may be marked than read a lit texel, never fewer."""
    h, w = lit.shape
    hb, wb = -(-h // block), -(-w // block)
    padded = np.zeros((hb * block, wb * block), bool)
    padded[:h, :w] = lit
    blocks = padded.reshape(hb, block, wb, block).any(axis=(1, 3))
    tri = np.asarray(uvs, np.float64)[np.asarray(indices).reshape(-1, 3)]  # (M, 3, 2)
    finite = np.isfinite(tri).all(axis=(1, 2))
    tri = np.where(finite[:, None, None], tri, 0.0)
    size = np.array([w, h], np.float64)
    top = np.array([w - 1, h - 1])
    lo = np.clip(np.floor(tri.min(axis=1) * size).astype(np.int64) - MARGIN_TEXELS, 0, top) // block
    hi = np.clip(np.floor(tri.max(axis=1) * size).astype(np.int64) + MARGIN_TEXELS, 0, top) // block
    # a summed-area table of the lit blocks: those in [lo, hi] (inclusive) per triangle
    sat = np.zeros((hb + 1, wb + 1), np.int32)
    sat[1:, 1:] = np.cumsum(np.cumsum(blocks, axis=0, dtype=np.int32), axis=1)
    x0, y0 = lo[:, 0], lo[:, 1]
    x1, y1 = hi[:, 0] + 1, hi[:, 1] + 1
    count = sat[y1, x1] - sat[y0, x1] - sat[y1, x0] + sat[y0, x0]
    return (count > 0) | ~finite


def lit_texels(record: bytes, size: int) -> np.ndarray:
    """(size, size) bool: the texels of an RGBA float32 record (bytes as read back) whose light (rgb) is not
    all +0 (a -0 or a NaN counts as light: the test is on the bits)."""
    bits = np.frombuffer(record, np.uint32).reshape(size, size, 4)
    return (bits[..., 0] | bits[..., 1] | bits[..., 2]) != 0


def slot_masks(uvs: np.ndarray, indices: np.ndarray, lits: list[np.ndarray]) -> np.ndarray:
    """Per triangle the mask of the slots (bit k: lits[k], each (H, W) bool) whose lit texels it can read."""
    mask = np.zeros(len(np.asarray(indices).reshape(-1, 3)), np.int64)
    for k, lit in enumerate(lits):
        mask |= through_triangles(uvs, indices, lit).astype(np.int64) << k
    return mask


def split_indices(indices: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The triangles grouped by `mask` (per triangle: an int, e.g. slot_masks'), each group in its
    order: (flat uint32 indices, [(mask value, first index, index count), ...] in increasing value)."""
    tris = np.asarray(indices, np.uint32).reshape(-1, 3)
    mask = np.asarray(mask)
    order = np.argsort(mask, kind="stable")
    values, counts = np.unique(mask, return_counts=True)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    groups = [(int(v), int(a) * 3, int(c) * 3) for v, a, c in zip(values, starts, counts)]
    return np.ascontiguousarray(tris[order].reshape(-1)), groups
