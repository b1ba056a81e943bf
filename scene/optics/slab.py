"""Light through a thin slab of a scattering medium: the exact diffuse transmittance of an isotropic,
index-matched, plane-parallel slab by the doubling method (NumPy reference; GLSL twin
shaders/lib/sss_boundary.glsl ``sss_slab_through``).

Translucency in the frame (texture-space techniques) needs, for light arriving at cosine mu on one
face of a part d mm thick, the flux that leaves through the far face after scattering (the unscattered
beam goes on towards the viewer only where the part is thinner than a pixel; it is not counted). The
diffusion approximation between extrapolated boundaries this replaces read the back-lit 3 mm skin slab
25-60 % dark in its green and blue channels (single-scattering albedo 0.69, 0.49: a few mean free paths
is no diffusion regime) and up to 80 % bright at 1 mm (docs/ground-truth.md).

Doubling (van de Hulst 1980, "Multiple Light Scattering" ch. 5; Prahl 1995, "The adding-doubling
method", in Optical-Thermal Response of Laser-Irradiated Tissue; docs/references.md#doubling): with
Gauss-Legendre cosines mu_i and weights w_i on (0, 1), the azimuth-averaged flux matrices of a layer of
optical thickness D << mu_min (columns: incident direction j, rows: exit direction i), isotropic phase
function, single-scattering albedo a,

    T_ij = delta_ij e^{-D/mu_j} + a D w_i / (2 mu_j),      R_ij = a D w_i / (2 mu_j)

(a beam crossing the layer at mu_j collides with probability D/mu_j and scatters half of what survives
into each hemisphere, w_i/2 into direction bin i), and two equal layers of a homogeneous slab give

    R_2D = R + T (I - R R)^-1 R T,      T_2D = T (I - R R)^-1 T.

Starting at D = 2^-30 the sequence reaches every tau = 2^(k/2) needed here (two sequences, one from
D sqrt 2). The cosines at which the table is wanted are added as nodes of weight 0: nothing is
scattered into them, and their column is the slab's exact response to a beam at that cosine. Checked
against Chandrasekhar's exact albedo of the semi-infinite medium (1e-6) and energy conservation at
a = 1 (tests/scene/optics/test_slab.py).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .fresnel import clamp_eta, fdr, fresnel_dielectric

SLAB_MU_NODES = 9  # table cosines i / 8 (GLSL SSS_SLAB_MU); 5 were up to 34 % off at cosine 0.1
SLAB_TAU_NODES = 21  # table optical thicknesses 2^(LOG2_TAU_MIN + k / 2) (GLSL SSS_SLAB_TAU)
LOG2_TAU_MIN = -4.0  # 1/16 mean free path
LOG2_TAU_MAX = LOG2_TAU_MIN + (SLAB_TAU_NODES - 1) / 2  # 64 mean free paths
QUAD_NODES = 24  # Gauss-Legendre cosines of the doubling
_LOG2_D0 = -30  # the first layer's optical thickness, 2^-30
_MU_FLOOR = 1e-3  # a beam at cosine 0 is taken at this cosine


def slab_mu_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, SLAB_MU_NODES)


def slab_log2_tau_nodes() -> np.ndarray:
    return LOG2_TAU_MIN + 0.5 * np.arange(SLAB_TAU_NODES)


def doubling_transmittance(a: float, log2_d0: float, steps: int, mu_probe: np.ndarray) -> list[np.ndarray]:
    """Diffuse transmittance (all orders of scattering, unscattered beam excluded) of slabs of
    optical thickness 2^(log2_d0 + k), k = 0..steps, for beams at the cosines mu_probe: (steps+1, P)."""
    x, w = np.polynomial.legendre.leggauss(QUAD_NODES)
    mu = np.concatenate([0.5 * (x + 1.0), np.maximum(mu_probe, _MU_FLOOR)])
    wt = np.concatenate([0.5 * w, np.zeros(len(mu_probe))])
    d = 2.0**log2_d0
    scat = a * d * wt[:, None] / (2.0 * mu[None, :])
    r, t = scat.copy(), np.diag(np.exp(-d / mu)) + scat
    eye = np.eye(len(mu))
    probe = np.arange(QUAD_NODES, len(mu))
    out = []
    for k in range(steps + 1):
        tau = d * 2.0**k
        out.append(t[:, probe].sum(axis=0) - np.exp(-tau / mu[probe]))
        if k < steps:
            m = np.linalg.solve(eye - r @ r, t)  # (I - R R)^-1 T
            r, t = r + t @ np.linalg.solve(eye - r @ r, r @ t), t @ m
    return out


@lru_cache(maxsize=512)
def _transmittance_table(a: float) -> np.ndarray:
    """(SLAB_MU_NODES, SLAB_TAU_NODES) diffuse transmittance at the table's cosines and thicknesses."""
    mu = slab_mu_nodes()
    out = np.zeros((SLAB_MU_NODES, SLAB_TAU_NODES))
    if a <= 0.0:
        return out
    for half in (0, 1):  # the integer and the half octaves
        start = _LOG2_D0 + 0.5 * half
        steps = int(round(LOG2_TAU_MAX - start))
        seq = doubling_transmittance(a, start, steps, mu)
        for k, v in enumerate(seq):
            lt = start + k
            j = (lt - LOG2_TAU_MIN) * 2.0
            if lt >= LOG2_TAU_MIN - 1e-9 and abs(j - round(j)) < 1e-9 and round(j) < SLAB_TAU_NODES:
                out[:, int(round(j))] = np.maximum(v, 0.0)
    return out


def slab_diffuse_transmittance(a: float, log2_tau: float, mu: float) -> float:
    """The exact diffuse transmittance of the slab at one of the table's nodes (for tests and reports):
    a beam at cosine `mu` (a table cosine) through optical thickness 2^log2_tau (a table thickness)."""
    t = _transmittance_table(round(float(np.clip(a, 0.0, 1.0)), 12))
    i = int(round(float(mu) * (SLAB_MU_NODES - 1)))
    j = int(round((float(log2_tau) - LOG2_TAU_MIN) * 2.0))
    if abs(i / (SLAB_MU_NODES - 1) - mu) > 1e-9 or abs(LOG2_TAU_MIN + 0.5 * j - log2_tau) > 1e-9:
        raise ValueError(f"slab_diffuse_transmittance: ({mu}, {log2_tau}) is not a table node")
    return float(t[i, j])


def slab_decay(alpha) -> np.ndarray:
    """Per-channel decay rate per mean free path beyond the table's thickest slab (diffusion's
    sqrt(3 (1 - a))), with an extra 1/tau (the conservative slab's law)."""
    al = np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0)
    return np.sqrt(3.0 * (1.0 - al))


LN_FLOOR = -80.0  # ln of "no light" in the table (e^-80: 0 in float32 products)


def slab_table(alpha, colour) -> np.ndarray:
    """(SLAB_MU_NODES * SLAB_TAU_NODES, 3) natural log of the diffuse transmittance per unit surface
    colour (the frame multiplies by base colour), row i * SLAB_TAU_NODES + j for cosine i/8 and
    thickness node j; LN_FLOOR for a channel whose colour or albedo is 0. Logarithms because the
    lookup interpolates ln T linearly in tau between the half-octave nodes (within 1.5 % of the exact
    doubling for every albedo and cosine; linear T in log2 tau was up to 100 % off where T decays
    exponentially)."""
    al = np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0)
    col = np.clip(np.asarray(colour, np.float64).reshape(3), 0.0, 1.0)
    out = np.full((SLAB_MU_NODES * SLAB_TAU_NODES, 3), LN_FLOOR)
    for c in range(3):
        if col[c] > 0 and al[c] > 0:
            v = _transmittance_table(round(float(al[c]), 12)).reshape(-1) / col[c]
            out[:, c] = np.maximum(np.log(np.maximum(v, 1e-300)), LN_FLOOR)
    return out


def slab_through(back, d_mm, table, mfp_mm, alpha, eta) -> np.ndarray:
    """Light through a part d mm thick per unit irradiance (normal to the light) arriving at cosine
    `back` on its far face, per unit base colour, leaving the near face (3,): the exact table at eta 1
    (`slab_table`: ln T), ln T linear in the optical thickness tau = d / l between its nodes, T linear
    in the cosine; below 1/16 mean free path linear in tau to 0, beyond 64 mean free paths decaying as
    e^{-k (tau - 64)} 64 / tau. At eta > 1: Fresnel
    transmission in at `back`, the table at the refracted cosine, and 1 - F_dr(eta) out (the
    interface's internal reflections between the faces are left out). GLSL twin sss_slab_through."""
    eta = float(clamp_eta(eta))
    b = float(np.clip(back, 0.0, 1.0))
    t_in, t_out = 1.0, 1.0
    if eta > 1.0:
        t_in = 1.0 - float(fresnel_dielectric(b, eta))
        b = float(np.sqrt(max((eta - 1.0) * (eta + 1.0) + b * b, 0.0)) / eta)
        t_out = 1.0 - float(fdr(eta))
    l = np.asarray(mfp_mm, np.float64).reshape(3)
    k = slab_decay(alpha)
    tab = np.asarray(table, np.float64).reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)
    xm = b * (SLAB_MU_NODES - 1)
    i = min(int(np.floor(xm)), SLAB_MU_NODES - 2)
    fm = xm - i
    out = np.zeros(3)
    d = max(float(d_mm), 0.0)
    for c in range(3):
        if l[c] <= 0 or d <= 0:
            continue
        tau = d / l[c]
        tmin, tmax = 2.0**LOG2_TAU_MIN, 2.0**LOG2_TAU_MAX
        tc = min(max(tau, tmin), tmax)
        j = min(int(np.floor((np.log2(tc) - LOG2_TAU_MIN) * 2.0)), SLAB_TAU_NODES - 2)
        t0 = 2.0 ** (LOG2_TAU_MIN + 0.5 * j)
        ft = min(max((tc - t0) / (t0 * (np.sqrt(2.0) - 1.0)), 0.0), 1.0)
        rows = np.exp(tab[i : i + 2, j, c] * (1.0 - ft) + tab[i : i + 2, j + 1, c] * ft)
        v = rows[0] * (1.0 - fm) + rows[1] * fm
        if tau < tmin:
            v *= tau / tmin
        elif tau > tmax:
            v *= np.exp(-k[c] * (tau - tmax)) * tmax / tau
        out[c] = v
    return t_in * t_out * out
