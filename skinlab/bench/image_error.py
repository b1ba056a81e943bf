"""Image error of a frame against the reference frame: relative L1 and per-pixel relative errors on
linear HDR over the lit surface pixels."""

from __future__ import annotations

import math

import numpy as np

LUM_FRACTION = 0.05  # lit pixels: reference luminance above 5 % of its 99th percentile
REC709 = np.array([0.2126, 0.7152, 0.0722])


def percentile(values, q: float) -> float:
    return float(np.percentile(np.asarray(values, np.float64), q)) if len(values) else math.nan


def lit_mask(ref: np.ndarray, lum_fraction: float = LUM_FRACTION) -> np.ndarray:
    """Pixels that count: reference coverage > 0 and luminance above lum_fraction x its 99th percentile."""
    cover = ref[..., 3] > 0
    lum = ref[..., :3].astype(np.float64) @ REC709
    if not cover.any():
        return cover
    thr = lum_fraction * float(np.percentile(lum[cover], 99))
    return cover & (lum > thr)


def image_error(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> dict:
    """Relative L1 and per-pixel relative errors of linear HDR `img` against `ref` over `mask`."""
    if img.shape != ref.shape:
        raise ValueError(f"image error: shapes differ ({img.shape} vs {ref.shape})")
    mask = lit_mask(ref) if mask is None else mask
    n = int(mask.sum())
    if n == 0:
        return {"image_rel_l1": math.nan, "image_max_rel": math.nan, "image_p95_rel": math.nan, "pixels": 0}
    d = np.abs(img[..., :3].astype(np.float64) - ref[..., :3].astype(np.float64)).sum(axis=-1)[mask]
    s = ref[..., :3].astype(np.float64).sum(axis=-1)[mask]
    per = d / s
    return {
        "image_rel_l1": float(d.sum() / s.sum()),
        "image_max_rel": float(per.max()),
        "image_p95_rel": float(np.percentile(per, 95)),
        "pixels": n,
    }
