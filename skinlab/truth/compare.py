"""Image error against the path-traced truth, the truth's own noise floor, and error maps.

All on linear HDR radiance (H, W, 4), alpha = coverage, over the object: the pixels the reference
covers (alpha > 0.5), the same pixels in both images.

* ``rel_l1``: sum |img - ref| / sum ref over those pixels, R, G and B summed (per pixel);
* ``rel_l1_block``: the same on ``block`` x ``block`` pixel sums (default 4 x 4): each block sums
  the covered pixels of both images, so path-tracing noise averages out while shading errors
  larger than a block remain;
* ``energy``: per channel, sum img / sum ref - 1 over the object;
* ``judged_blocks``: issue 12's block target, the number of ``JUDGE_BLOCK`` x ``JUDGE_BLOCK``
  (8 x 8) luminance blocks more than ``JUDGE_TOL`` (15 %) off the truth among those the truth's
  noise allows to judge: blocks whose half-to-half noise (``block_noise``) is below ``JUDGE_NOISE``
  (5 %; the full reference is then within about 2.5 %, one standard deviation, so 15 % is six of
  them) and that are not darker than ``MAP_DARK`` of the brightest (as in the error maps).

The noise floor of a reference is the same measure between the means of two halves of its
independent passes; the full reference (both halves) is about half as noisy again.
"""

from __future__ import annotations

import numpy as np

BLOCK = 4
COVERAGE = 0.5
MAP_SCALE = 0.5  # error maps: full colour at +-50 % relative difference
MAP_DARK = 0.01  # blocks darker than this fraction of the brightest (99th percentile) block are not judged
REC709 = np.array([0.2126, 0.7152, 0.0722])
JUDGE_BLOCK = 8  # issue 12: "no 8x8-pixel block more than 15 % off where the truth's noise allows it to be judged"
JUDGE_TOL = 0.15
JUDGE_NOISE = 0.05  # a block is judged where its half-to-half noise is below this


def object_mask(ref: np.ndarray) -> np.ndarray:
    return ref[..., 3] > COVERAGE


def block_sums(x: np.ndarray, block: int) -> np.ndarray:
    """Sums over block x block tiles (the image cropped to whole tiles)."""
    h, w = x.shape[:2]
    h2, w2 = h - h % block, w - w % block
    x = x[:h2, :w2]
    return x.reshape(h2 // block, block, w2 // block, block, *x.shape[2:]).sum(axis=(1, 3))


def _check(img: np.ndarray, ref: np.ndarray) -> None:
    if img.shape[:2] != ref.shape[:2]:
        raise ValueError(f"image {img.shape[1]}x{img.shape[0]} and reference {ref.shape[1]}x{ref.shape[0]} differ")


def image_error(img: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None, block: int = BLOCK) -> dict:
    """Relative L1 per pixel and per block, and the energy ratio per channel, over the mask."""
    _check(img, ref)
    m = object_mask(ref) if mask is None else mask
    a = np.where(m[..., None], img[..., :3], 0.0).astype(np.float64)
    b = np.where(m[..., None], ref[..., :3], 0.0).astype(np.float64)
    total = b.sum()
    if not m.any() or total <= 0:
        return {"rel_l1": float("nan"), "rel_l1_block": float("nan"), "energy": [float("nan")] * 3, "pixels": 0}
    ba, bb = block_sums(a, block), block_sums(b, block)
    with np.errstate(invalid="ignore", divide="ignore"):
        energy = a.sum(axis=(0, 1)) / b.sum(axis=(0, 1)) - 1.0
    return {
        "rel_l1": float(np.abs(a - b).sum() / total),
        "rel_l1_block": float(np.abs(ba - bb).sum() / max(bb.sum(), 1e-30)),
        "energy": [float(x) for x in energy],
        "pixels": int(m.sum()),
    }


def _luminance(x: np.ndarray, m: np.ndarray) -> np.ndarray:
    return np.where(m, x[..., :3].astype(np.float64) @ REC709, 0.0)


def _lit_blocks(br: np.ndarray, bm: np.ndarray) -> np.ndarray:
    """Blocks with coverage whose truth is not darker than MAP_DARK of the 99th-percentile block."""
    return (bm > 0) & (br > 0) & (br > MAP_DARK * (np.percentile(br[bm > 0], 99) if (bm > 0).any() else 0.0))


def block_noise(half_a: np.ndarray, half_b: np.ndarray, ref: np.ndarray, block: int = JUDGE_BLOCK) -> np.ndarray:
    """Per block x block tile: the relative standard deviation of the difference between the two
    halves' luminance sums, sqrt(sum over the block's pixels of (a - b)^2) / (block sum of the
    truth), NaN where the block has no coverage or no light. The estimate from the 64 pixel
    differences of an 8x8 block is much steadier than the block's one difference; it assumes
    independent pixels, which the references' box reconstruction filter gives
    (skinlab/truth/export.py). Same convention as the ledger's noise floor (between the halves): the
    full reference's own noise is about half of it."""
    _check(half_a, ref)
    _check(half_b, ref)
    m = object_mask(ref)
    d2 = (_luminance(half_a, m) - _luminance(half_b, m)) ** 2
    br, bm = block_sums(_luminance(ref, m), block), block_sums(m.astype(np.float64), block)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where((bm > 0) & (br > 0), np.sqrt(block_sums(d2, block)) / br, np.nan)


def judged_blocks(
    img: np.ndarray,
    ref: np.ndarray,
    half_a: np.ndarray,
    half_b: np.ndarray,
    block: int = JUDGE_BLOCK,
    tol: float = JUDGE_TOL,
    noise_max: float = JUDGE_NOISE,
) -> dict:
    """Issue 12's block target: of the lit blocks whose noise (block_noise) is below noise_max,
    how many are more than tol off the truth in luminance. {"judged", "over", "over_fraction"
    (NaN when none is judged), "worst" (largest |relative difference| among judged, NaN if none),
    "over_mask" (bool per block)}."""
    _check(img, ref)
    m = object_mask(ref)
    bi, br = block_sums(_luminance(img, m), block), block_sums(_luminance(ref, m), block)
    bm = block_sums(m.astype(np.float64), block)
    noise = block_noise(half_a, half_b, ref, block)
    judged = _lit_blocks(br, bm) & (np.nan_to_num(noise, nan=np.inf) < noise_max)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(judged, np.abs(bi - br) / br, 0.0)
    over = judged & (d > tol)
    n = int(judged.sum())
    return {
        "judged": n,
        "over": int(over.sum()),
        "over_fraction": float(over.sum() / n) if n else float("nan"),
        "worst": float(d[judged].max()) if n else float("nan"),
        "over_mask": over,
    }


def relative_difference(img: np.ndarray, ref: np.ndarray, block: int = BLOCK) -> np.ndarray:
    """Signed (img - ref) / ref of luminance per block x block tile, expanded back to pixels (NaN
    outside the object and where the truth's block is darker than MAP_DARK of its 99th percentile
    block: a relative difference of almost nothing says nothing)."""
    _check(img, ref)
    m = object_mask(ref)
    li, lr = _luminance(img, m), _luminance(ref, m)
    bi, br, bm = block_sums(li, block), block_sums(lr, block), block_sums(m.astype(np.float64), block)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(_lit_blocks(br, bm), (bi - br) / br, np.nan)
    out = np.full(m.shape, np.nan)
    h2, w2 = d.shape[0] * block, d.shape[1] * block
    out[:h2, :w2] = np.repeat(np.repeat(d, block, axis=0), block, axis=1)
    return np.where(m, out, np.nan)


def error_map_rgb(diff: np.ndarray, scale: float = MAP_SCALE) -> np.ndarray:
    """uint8 RGB: red where the image is brighter than the truth, blue where darker (full colour at
    +-scale), white where equal, dark grey outside the object or where the truth is too dark."""
    import matplotlib

    cmap = matplotlib.colormaps["RdBu_r"]
    t = np.clip(np.nan_to_num(diff, nan=0.0) / scale, -1.0, 1.0) * 0.5 + 0.5
    rgb = (cmap(t)[..., :3] * 255).astype(np.uint8)
    rgb[np.isnan(diff)] = (40, 40, 40)
    return rgb


def magma_rgb(fmap: np.ndarray) -> np.ndarray:
    """uint8 RGB of values in [0, 1] (magma): FLIP maps (skinlab/truth/metrics.py), noise maps."""
    import matplotlib

    return (matplotlib.colormaps["magma"](np.clip(np.nan_to_num(fmap), 0, 1))[..., :3] * 255).astype(np.uint8)
