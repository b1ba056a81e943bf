"""Issue 12's block target (skinlab/truth/compare.py): the noise of a reference's 8x8 blocks estimated
from its two halves, and the blocks more than 15 % off among those that noise allows to judge."""

import numpy as np
import pytest

from skinlab.truth.compare import JUDGE_NOISE, JUDGE_TOL, block_noise, judged_blocks


def _image(lum: np.ndarray) -> np.ndarray:
    """An (H, W, 4) grey image of luminance lum, fully covered."""
    img = np.ones((*lum.shape, 4), np.float64)
    img[..., :3] = lum[..., None]
    return img


def test_block_noise_matches_the_noise_put_in():
    rng = np.random.default_rng(1)
    h = w = 64
    ref = _image(np.ones((h, w)))
    sigma = np.where(np.arange(w) < 32, 0.05, 0.5)[None, :].repeat(h, 0)  # quiet left, noisy right
    a = _image(1.0 + sigma * rng.standard_normal((h, w)))
    b = _image(1.0 + sigma * rng.standard_normal((h, w)))
    n = block_noise(a, b, ref)
    assert n.shape == (8, 8)
    # the halves' block sums differ by sqrt(64 * 2 sigma^2) / 64 (relative, reference 1 per pixel)
    expect = np.sqrt(2.0) * sigma[0, ::8] / 8.0
    assert np.allclose(n.mean(0), expect, rtol=0.15)
    # and the estimate is steady: every block within 30 % of it (one difference per block is not)
    assert np.all(np.abs(n / expect[None, :] - 1.0) < 0.3)


def test_block_noise_is_nan_outside_the_object():
    ref = _image(np.ones((16, 16)))
    ref[8:, :, 3] = 0.0  # bottom half uncovered
    n = block_noise(ref, ref, ref)
    assert np.isnan(n[1]).all() and (n[0] == 0.0).all()


def test_judged_blocks_counts_only_quiet_lit_blocks_over_the_tolerance():
    rng = np.random.default_rng(2)
    h, w = 32, 64
    lum = np.ones((h, w))
    lum[24:, :] = 1e-4  # a dark bottom row of blocks: not judged however far off
    ref = _image(lum)
    sigma = np.zeros((h, w))
    sigma[:, 48:] = 2.0  # the right two columns of blocks are too noisy to judge
    a = _image(lum * (1.0 + sigma * rng.standard_normal((h, w))))
    b = _image(lum * (1.0 + sigma * rng.standard_normal((h, w))))
    off = np.ones((h, w))
    off[:, :8] = 1.0 + JUDGE_TOL + 0.05  # first block column: 20 % brighter
    off[:, 8:16] = 1.0 - (JUDGE_TOL - 0.05)  # second: 10 % darker, within the tolerance
    off[:, 48:] = 1.5  # 50 % off where the truth cannot tell
    off[24:, :] = 3.0
    res = judged_blocks(_image(lum * off), ref, a, b)
    assert res["judged"] == 3 * 6  # three lit block rows x six quiet block columns
    assert res["over"] == 3 and res["over_mask"][:3, 0].all() and res["over_mask"].sum() == 3
    assert res["over_fraction"] == pytest.approx(3 / 18)
    assert res["worst"] == pytest.approx(JUDGE_TOL + 0.05)


def test_judged_blocks_with_nothing_to_judge_is_nan_not_zero():
    rng = np.random.default_rng(3)
    lum = np.ones((16, 16))
    ref = _image(lum)
    a = _image(lum + rng.standard_normal(lum.shape))  # 100 % per-pixel noise: 8x8 noise ~18 % > 5 %
    b = _image(lum + rng.standard_normal(lum.shape))
    res = judged_blocks(_image(lum * 2.0), ref, a, b)
    assert JUDGE_NOISE < 0.1 and res["judged"] == 0 and res["over"] == 0
    assert np.isnan(res["over_fraction"]) and np.isnan(res["worst"])


def test_judged_blocks_rejects_images_of_other_sizes():
    ref = _image(np.ones((16, 16)))
    with pytest.raises(ValueError, match="differ"):
        judged_blocks(_image(np.ones((8, 8))), ref, ref, ref)
