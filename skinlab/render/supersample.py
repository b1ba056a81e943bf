"""Antialiasing by supersampling (``RenderSettings.supersample``): NumPy twins of the tone-mapping
pass's box filter (skinlab/shaders/passes/tonemap_supersample.frag) and the depth read-back's reduction.

An output pixel's value is the mean of its N x N samples, the box pixel filter the path-traced truth
uses (each pixel averaged over its area; skinlab/truth/, docs/ground-truth.md)."""

from __future__ import annotations

import numpy as np


def box_filter(img: np.ndarray, n: int) -> np.ndarray:
    """The mean of each n x n block of `img` (H*n, W*n, ...) -> (H, W, ...), in float32 as the GPU."""
    if n == 1:
        return img
    h, w = img.shape[0] // n, img.shape[1] // n
    if img.shape[0] != h * n or img.shape[1] != w * n:
        raise ValueError(f"box filter: image {img.shape[1]}x{img.shape[0]} is not a multiple of {n}")
    blocks = img.astype(np.float64).reshape(h, n, w, n, *img.shape[2:])
    return blocks.mean(axis=(1, 3)).astype(np.float32)


def composite_filtered(img: np.ndarray, n: int, background) -> np.ndarray:
    """What the tone-mapping pass tone-maps (before exposure): the mean over each n x n block of the
    samples composited over `background` (linear RGB), ``mix(background, rgb, clamp(alpha, 0, 1))``."""
    a = np.clip(img[..., 3:4].astype(np.float64), 0.0, 1.0)
    shown = np.asarray(background, np.float64) * (1.0 - a) + img[..., :3].astype(np.float64) * a
    return box_filter(shown, n)


def nearest_depth(depth: np.ndarray, n: int) -> np.ndarray:
    """Each output pixel's nearest sample (the minimum over its n x n block; inf where all are background)."""
    if n == 1:
        return depth
    h, w = depth.shape[0] // n, depth.shape[1] // n
    return depth.reshape(h, n, w, n).min(axis=(1, 3))
