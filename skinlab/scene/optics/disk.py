"""Importance-sampled Burley disk SSS in screen space (Golubev, "Efficient Screen-Space Subsurface
Scattering Using Burley's Normalized Diffusion in Real-Time", SIGGRAPH 2018 course; what Unity HDRP
and Blender EEVEE Next ship; docs/references.md#golubev-2018). NumPy reference of the kernel
skinlab/shaders/techniques/disk/gather.frag applies and of its helpers in skinlab/shaders/lib/disk.glsl.

Per pixel, n samples on a disc around it: sample i at radius r_i = CDF^{-1}(xi_i) of the normalised
Burley profile of shape d_s (Golubev's closed-form inverse, skinlab/scene/optics/burley.py), xi_i = (i + 1/2)/n
(stratified), at angle i * golden angle + phi, phi a per-pixel rotation (interleaved gradient noise,
Jimenez 2014) that trades banding for noise. The pdf over the plane is p(r) = p_r(r) / (2 pi r),
p_r(r) = (e^{-r/d_s} + e^{-r/(3 d_s)}) / (4 d_s); sample i's weight per channel is the material's own
radial profile (any sss_model) over it, R_c(r_i) / p(r_i), normalised so each channel's weights sum
to 1. The shader sums weight x the neighbour's subsurface diffuse over the samples it accepts (a
neighbour that is scattering material within the profile's reach in depth) and divides by the
accepted weight, so a flat lit surface keeps exactly its light (energy conservation) and a rejected
sample takes nothing across a silhouette.

d_s, the sampling shape, is chosen so the Burley CDF reaches SAMPLE_ENERGY at the radius holding that
fraction of the widest channel's energy of the material's exact profile (as HDRP samples with the
widest channel); radii are in millimetres on the surface, turned into pixels with each pixel's depth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skinlab.cache import table

from .burley import burley_sample_golubev
from .constants import PI
from .media import Medium

GOLDEN_ANGLE = PI * (3.0 - math.sqrt(5.0))  # radians, 2.39996...
SAMPLE_ENERGY = 0.99  # fraction of the widest channel's energy inside the sampled disc's outer samples
MAX_DISK_SAMPLES = 64  # skinlab/shaders/techniques/disk/gather.frag


@dataclass(frozen=True)
class DiskKernel:
    """One profile's disk samples: radii (n,) mm, weights (n, 3) normalised per channel (all 0 for a
    channel that does not scatter: the shader keeps the centre), reach_mm the depth difference past
    which a neighbour is rejected, d_mm the Burley shape the radii were drawn with."""

    radii_mm: np.ndarray
    weights: np.ndarray
    reach_mm: float
    d_mm: float


def burley_radial_pdf(r, d):
    """Radial pdf (2 pi r included) of the untruncated normalised Burley profile, 1/mm."""
    r, d = np.asarray(r, np.float64), float(d)
    return (np.exp(-r / d) + np.exp(-r / (3.0 * d))) / (4.0 * d)


@table(disk=True, maxsize=256)
def disk_kernel(model: str, medium: Medium, samples: int) -> DiskKernel:
    """The disk samples for a material's sss_model and medium (cached per medium and count)."""
    from .gaussians import NoEnergy, _energy_radius
    from .profile_fit import MODEL_PROFILES
    from .profiles import get_profile

    if model not in MODEL_PROFILES:
        raise ValueError(
            f"sss_model: the disk technique has no profile for {model!r}; expected one of {', '.join(MODEL_PROFILES)}"
        )
    if not (isinstance(samples, int) and 1 <= samples <= MAX_DISK_SAMPLES):
        raise ValueError(f"disk_samples: expected an integer in [1, {MAX_DISK_SAMPLES}], got {samples!r}")
    scatter = medium.scattering
    if not scatter.any():
        return DiskKernel(np.zeros(samples), np.zeros((samples, 3)), 0.0, 0.0)
    prof = get_profile(MODEL_PROFILES[model])
    fn = lambda r: np.asarray(prof.evaluate(np.asarray(r, np.float64), medium), np.float64) * scatter[None, :]
    try:
        reach = _energy_radius(fn, SAMPLE_ENERGY)
    except NoEnergy:  # the light spreads less than 1e-5 mm in every scattering channel: none scatters
        return DiskKernel(np.zeros(samples), np.zeros((samples, 3)), 0.0, 0.0)
    x_e = float(burley_sample_golubev(SAMPLE_ENERGY, 1.0))  # r/d where the Burley CDF reaches it
    d = reach / x_e
    xi = (np.arange(samples) + 0.5) / samples
    r = burley_sample_golubev(xi, d)
    pdf_area = burley_radial_pdf(r, d) / (2.0 * PI * r)
    w = np.maximum(fn(r), 0.0) / pdf_area[:, None]
    tot = w.sum(axis=0)
    w = np.where(tot > 0, w / np.where(tot > 0, tot, 1.0), 0.0)
    return DiskKernel(r, w, float(reach), float(d))


def disk_angle(i, n, phi):
    """Sample i's angle (radians): the golden-angle spiral rotated by the pixel's phi. Twin of
    disk_angle in skinlab/shaders/lib/disk.glsl (n is unused there too: kept for the signature)."""
    return np.asarray(i, np.float64) * GOLDEN_ANGLE + np.asarray(phi, np.float64)


def disk_offset(i, r_mm, phi):
    """(.., 2) offset in mm of sample i at radius r_mm for rotation phi (radians)."""
    a = disk_angle(i, 0, phi)
    r = np.asarray(r_mm, np.float64)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=-1)


def interleaved_gradient_noise(px, py):
    """Jimenez 2014 interleaved gradient noise in [0, 1) at pixel centres (px, py) in pixels."""
    px, py = np.asarray(px, np.float64), np.asarray(py, np.float64)
    f = np.mod(0.06711056 * px + 0.00583715 * py, 1.0)
    return np.mod(52.9829189 * f, 1.0)


def disk_edge_response(x_mm, kernel: DiskKernel) -> np.ndarray:
    """The kernel's response across a straight edge (lit for x < 0), averaged over the per-pixel
    rotation: sample i lands on the lit side with probability acos(clamp(x / r_i)) / pi. (N, 3); a
    channel that does not scatter is a step."""
    x = np.atleast_1d(np.asarray(x_mm, np.float64))
    r = np.maximum(kernel.radii_mm, 1e-12)
    lit = np.arccos(np.clip(x[:, None] / r[None, :], -1.0, 1.0)) / PI  # (N, n)
    out = lit @ kernel.weights
    step = np.where(x < 0, 1.0, np.where(x == 0, 0.5, 0.0))
    none = kernel.weights.sum(axis=0) <= 0
    return np.where(none[None, :], step[:, None], out)


def disk_filter_reference(img, alpha, view_z, kernels, reach_mm, mm_per_unit, pixels_per_unit, phi) -> np.ndarray:
    """NumPy model of the disk pass (skinlab/shaders/techniques/disk/gather.frag) on the forward pass's targets, in
    GL row order (row 0 at the bottom): img (H, W, 3) subsurface diffuse, alpha (H, W) profile index
    + 1 + radius scale / 2 (0: not scattering), view_z (H, W) view depth in scene units, kernels
    (profiles, n, 4) rgb weight and radius mm, reach_mm (profiles,), phi (H, W) rotations (radians).
    Nearest-texel fetches; a sample off the image, on another profile's pixel or beyond the reach
    in depth is rejected; each channel divided by its accepted weight (none: the centre)."""
    img = np.asarray(img, np.float64)
    h, w, _ = img.shape
    out = img.copy()
    kernels = np.asarray(kernels, np.float64)
    n = kernels.shape[1]
    idx = np.arange(n)
    for y, x in zip(*np.nonzero(np.asarray(alpha) >= 1.0)):
        a = float(alpha[y, x])
        prof_id = math.floor(a)
        prof, scale = prof_id - 1, 2.0 * (a - prof_id)
        z = float(view_z[y, x])
        px_per_mm = pixels_per_unit / (z * mm_per_unit)
        k = kernels[prof]
        off = disk_offset(idx, k[:, 3] * scale, phi[y, x]) * px_per_mm  # pixels
        u = (x + 0.5 + off[:, 0]) / w
        v = (y + 0.5 + off[:, 1]) / h
        ok = (u >= 0) & (v >= 0) & (u < 1) & (v < 1)
        tx = np.clip(np.floor(u * w).astype(int), 0, w - 1)
        ty = np.clip(np.floor(v * h).astype(int), 0, h - 1)
        ok &= np.floor(np.asarray(alpha)[ty, tx]) == prof_id
        ok &= np.abs(np.asarray(view_z)[ty, tx] - z) * mm_per_unit <= reach_mm[prof] * scale
        wts = k[:, :3] * ok[:, None]
        ws = wts.sum(axis=0)
        acc = (wts * img[ty, tx]).sum(axis=0)
        out[y, x] = np.where(ws > 0, acc / np.where(ws > 0, ws, 1.0), img[y, x])
    return out
