"""Image metrics that see what a viewer sees, each with its uncertainty from the truth's passes.

Definitions (linear radiance (H, W, 4), alpha = coverage; ``mask``: the pixels compared, by default
the truth's object pixels, alpha > 0.5; a = the frame, b = the truth):

* ``rel_l1`` (per pixel): sum over the masked pixels and R, G, B of |a - b|, divided by the sum of b
  over the same pixels and channels. One normalisation for the whole image (not a mean of per-pixel
  ratios, which dark pixels would dominate): the fraction of the truth's light that is misplaced.
* ``rel_l1_rgb``: the same per channel, sum_px |a_c - b_c| / sum_px b_c.
* ``energy``: per channel, sum_px a_c / sum_px b_c - 1 (the light gained or lost, wherever it is).
* ``flip``: NVIDIA's FLIP (Andersson et al. 2020, PyPI ``flip-evaluator``; docs/references.md#flip) on
  the tone-mapped frames, as a viewer sees them: both images through Skinlab's tone mapping (exposure,
  ACES fit, sRGB encoding: skinlab/scene/optics/color.py) and LDR-FLIP at its default 67 pixels per
  degree. ``flip`` is the map's mean over the mask, ``flip_map`` the (H, W) map in [0, 1].
* ``relative_map``: the signed per-pixel difference of luminance (a - b) / max(b, MAP_DARK x the truth's
  99th percentile), NaN outside the mask: the full-resolution error map.

Uncertainty: the truth is the mean of independent passes (skinlab/truth/passes.py); an error measured
against it inherits its noise. :func:`jackknife` measures the error once against each of the truth's
leave-one-group-out means and returns the delete-a-group jackknife standard error
sqrt((G - 1) / G * sum (e_g - mean e)^2) (G groups of passes of about equal samples; with the two
halves only, |e_a - e_b| / 2). The per-group values are kept so that two settings' difference can be
judged with its own (paired) uncertainty (:func:`paired_sigma`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .compare import MAP_DARK, REC709, _check, object_mask

FLIP_PPD = 67.0  # FLIP's default viewing condition: 0.7 m from a 0.7 m wide 3840-pixel monitor


def _rgb(x: np.ndarray, m: np.ndarray) -> np.ndarray:
    return np.where(m[..., None], x[..., :3].astype(np.float64), 0.0)


def rel_l1(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> float:
    _check(img, ref)
    m = object_mask(ref) if mask is None else mask
    a, b = _rgb(img, m), _rgb(ref, m)
    total = b.sum()
    return float(np.abs(a - b).sum() / total) if total > 0 else math.nan


def rel_l1_rgb(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> list[float]:
    _check(img, ref)
    m = object_mask(ref) if mask is None else mask
    a, b = _rgb(img, m), _rgb(ref, m)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [float(x) for x in np.abs(a - b).sum(axis=(0, 1)) / b.sum(axis=(0, 1))]


def energy(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> list[float]:
    _check(img, ref)
    m = object_mask(ref) if mask is None else mask
    a, b = _rgb(img, m), _rgb(ref, m)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [float(x) for x in a.sum(axis=(0, 1)) / b.sum(axis=(0, 1)) - 1.0]


def tone_mapped(hdr: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """float32 (H, W, 3) in [0, 1]: sRGB-encoded ACES of exposure x radiance (the tone-mapping pass)."""
    from skinlab.scene.optics.color import srgb_encode, tonemap_aces

    rgb = srgb_encode(tonemap_aces(np.maximum(np.asarray(hdr[..., :3], np.float64), 0.0) * exposure))
    return np.ascontiguousarray(np.clip(rgb, 0.0, 1.0), np.float32)


def flip_map(img: np.ndarray, ref: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """(H, W) LDR-FLIP error of the tone-mapped frame against the tone-mapped truth, in [0, 1]."""
    _check(img, ref)
    import flip_evaluator

    err, _, _ = flip_evaluator.evaluate(
        tone_mapped(ref, exposure), tone_mapped(img, exposure), "LDR", inputsRGB=True, applyMagma=False,
        computeMeanError=False, parameters={"ppd": FLIP_PPD},
    )  # fmt: skip
    return np.asarray(err, np.float32).reshape(ref.shape[:2])


def flip_mean(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None, exposure: float = 1.0) -> float:
    m = object_mask(ref) if mask is None else mask
    if not m.any():
        return math.nan
    return float(flip_map(img, ref, exposure)[m].mean())


def relative_map(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """Signed per-pixel (a - b) / max(b, MAP_DARK x 99th percentile) of luminance; NaN outside the mask."""
    _check(img, ref)
    m = object_mask(ref) if mask is None else mask
    la = img[..., :3].astype(np.float64) @ REC709
    lb = ref[..., :3].astype(np.float64) @ REC709
    floor = MAP_DARK * float(np.percentile(lb[m], 99)) if m.any() else 1.0
    return np.where(m, (la - lb) / np.maximum(lb, max(floor, 1e-30)), np.nan)


def jackknife(fn: Callable[[np.ndarray], float], full: np.ndarray, groups: list[np.ndarray]) -> tuple:
    """(value, sigma, per-group values): fn(truth) against the full truth, and the delete-a-group
    jackknife standard error over `groups` (the truth with each group of passes left out)."""
    value = float(fn(full))
    loo = np.array([fn(g) for g in groups], np.float64)
    return value, jackknife_sigma(loo), [float(x) for x in loo]


def jackknife_sigma(loo) -> float:
    loo = np.asarray(loo, np.float64)
    g = len(loo)
    if g < 2 or not np.isfinite(loo).all():
        return math.nan
    return float(math.sqrt((g - 1) / g * ((loo - loo.mean()) ** 2).sum()))


def paired_sigma(loo_a, loo_b) -> float:
    """The jackknife standard error of the difference of two errors measured against the same truth
    groups (the truth's noise they share cancels)."""
    a, b = np.asarray(loo_a, np.float64), np.asarray(loo_b, np.float64)
    if a.shape != b.shape:
        return math.nan
    return jackknife_sigma(a - b)
