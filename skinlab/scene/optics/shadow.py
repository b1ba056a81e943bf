"""NumPy twin of skinlab/shaders/lib/shadow.glsl for a depth-compare sampler with NEAREST filtering,
clamp-to-edge addressing and compare function '<=' (the result of each tap is exactly 0 or 1,
so the twin is exact). The renderer samples with LINEAR compare filtering, whose bilinear weights
are implementation precision (llvmpipe uses 8-bit weights); those are not part of the twin."""

from __future__ import annotations

import numpy as np

from .constants import SHADOW_BIAS


def shadow_bias(NoL):
    cosl = np.clip(np.asarray(NoL, np.float64), 0.05, 1.0)
    return SHADOW_BIAS * (1.0 + 3.0 * np.sqrt(1.0 - cosl * cosl) / cosl)


def shadow_pcf(depth_map: np.ndarray, shadow_matrix: np.ndarray, world: np.ndarray, NoL) -> np.ndarray:
    """depth_map: (H, W) with row 0 at texture v = 0 (GL order). world: (N, 3)."""
    world = np.asarray(world, np.float64)
    p = np.concatenate([world, np.ones((len(world), 1))], 1) @ np.asarray(shadow_matrix, np.float64).T
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    h, w = depth_map.shape
    ref = c[:, 2] - shadow_bias(NoL)
    total = np.zeros(len(world))
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            u = c[:, 0] + dx / w
            v = c[:, 1] + dy / h
            i = np.clip(np.floor(u * w).astype(np.int64), 0, w - 1)
            j = np.clip(np.floor(v * h).astype(np.int64), 0, h - 1)
            total += (ref <= depth_map[j, i]).astype(np.float64)
    return np.where(outside, 1.0, total / 9.0)
