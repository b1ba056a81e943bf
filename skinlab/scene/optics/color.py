"""NumPy twins of skinlab/shaders/lib/color.glsl: sRGB transfer (IEC 61966-2-1), ACES fit (Narkowicz 2015);
docs/references.md#aces-srgb."""

from __future__ import annotations

import numpy as np

from .constants import SRGB_ENCODED_THRESHOLD, SRGB_LINEAR_THRESHOLD


def srgb_encode(x):
    x = np.clip(np.asarray(x, np.float64), 0.0, 1.0)
    hi = 1.055 * np.power(np.maximum(x, SRGB_LINEAR_THRESHOLD), 1.0 / 2.4) - 0.055
    return np.where(x <= SRGB_LINEAR_THRESHOLD, 12.92 * x, hi)


def srgb_decode(x):
    x = np.clip(np.asarray(x, np.float64), 0.0, 1.0)
    hi = np.power((np.maximum(x, SRGB_ENCODED_THRESHOLD) + 0.055) / 1.055, 2.4)
    return np.where(x <= SRGB_ENCODED_THRESHOLD, x / 12.92, hi)


def tonemap_aces(x):
    x = np.clip(np.asarray(x, np.float64), 0.0, 1e4)  # 1 from x = 7.25 on; x * x stays finite in float32
    return np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
