"""Light through a thin slab of a scattering medium: the exact diffuse transmittance of an isotropic,
index-matched, plane-parallel slab by the doubling method (NumPy reference; GLSL twin
skinlab/shaders/lib/sss_boundary.glsl ``sss_slab_through``).

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

import numpy as np

from skinlab.cache import table

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


def _doubling_steps(a: float, log2_d0: float, steps: int, mu_probe: np.ndarray):
    """Yield (tau, mu, w, t) for slabs of optical thickness 2^(log2_d0 + k), k = 0..steps: the
    cosines (Gauss-Legendre, then the probes with weight 0), their weights and the flux matrix T
    (columns: incident direction, rows: exit direction; the unscattered beam on the diagonal)."""
    x, w = np.polynomial.legendre.leggauss(QUAD_NODES)
    mu = np.concatenate([0.5 * (x + 1.0), np.maximum(mu_probe, _MU_FLOOR)])
    wt = np.concatenate([0.5 * w, np.zeros(len(mu_probe))])
    d = 2.0**log2_d0
    scat = a * d * wt[:, None] / (2.0 * mu[None, :])
    r, t = scat.copy(), np.diag(np.exp(-d / mu)) + scat
    eye = np.eye(len(mu))
    for k in range(steps + 1):
        yield d * 2.0**k, mu, wt, t
        if k < steps:
            m = np.linalg.solve(eye - r @ r, t)  # (I - R R)^-1 T
            r, t = r + t @ np.linalg.solve(eye - r @ r, r @ t), t @ m


def doubling_transmittance(a: float, log2_d0: float, steps: int, mu_probe: np.ndarray) -> list[np.ndarray]:
    """Diffuse transmittance (all orders of scattering, unscattered beam excluded) of slabs of
    optical thickness 2^(log2_d0 + k), k = 0..steps, for beams at the cosines mu_probe: (steps+1, P)."""
    probe = np.arange(QUAD_NODES, QUAD_NODES + len(mu_probe))
    return [
        t[:, probe].sum(axis=0) - np.exp(-tau / mu[probe])
        for tau, mu, _, t in _doubling_steps(a, log2_d0, steps, np.asarray(mu_probe, np.float64))
    ]


def doubling_exit(a: float, tau: float, mu0: float) -> tuple[np.ndarray, np.ndarray]:
    """The exact angular distribution of the diffuse light transmitted by the index-matched slab of
    optical thickness tau (a power of two times 2^-30 is not needed: the first layer is tau / 2^n), lit
    by a beam at cosine mu0: (mu, exit) at the doubling's Gauss-Legendre cosines, exit normalised to
    cosine-weighted hemispherical mean 1 (the transmitted radiance over its mean). For tests and
    reports (the frame's slab_exit is checked against it)."""
    x, w = np.polynomial.legendre.leggauss(QUAD_NODES)
    mu = np.concatenate([0.5 * (x + 1.0), [max(float(mu0), _MU_FLOOR)]])
    wt = np.concatenate([0.5 * w, [0.0]])
    n = max(int(np.ceil(np.log2(max(tau, 1e-9)))) - _LOG2_D0, 0)
    d = tau / 2.0**n
    scat = a * d * wt[:, None] / (2.0 * mu[None, :])
    r, t = scat.copy(), np.diag(np.exp(-d / mu)) + scat
    eye = np.eye(len(mu))
    for _ in range(n):
        m = np.linalg.solve(eye - r @ r, t)
        r, t = r + t @ np.linalg.solve(eye - r @ r, r @ t), t @ m
    col = t[:QUAD_NODES, QUAD_NODES]  # the beam's flux into each quadrature direction (none unscattered)
    return mu[:QUAD_NODES], col / (2.0 * wt[:QUAD_NODES] * mu[:QUAD_NODES] * col.sum())


@table(maxsize=512)
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


def _knee(tau):
    """ln(tau / (1 + tau)): the part of ln T that the lookup interpolates apart. A slab transmits in
    proportion to tau below a mean free path and decays exponentially beyond a few (linear in tau in
    ln T); ln T linear in tau between nodes a half octave apart bends across the knee between the two,
    up to 1.5 % dark at 1-4 mean free paths for every albedo (3 mm of skin1: 2.3 / 3.2 / 4.5 mean free
    paths). With this taken out and added back at tau, within 0.5 % at the 90th percentile and 1.3 %
    at most (cosines 1/4-1, albedos 0.3-0.99, where T > 1e-4; tests/scene/optics/test_slab.py)."""
    return np.log(tau / (1.0 + tau))


def slab_through(back, d_mm, table, mfp_mm, alpha, eta) -> np.ndarray:
    """Light through a part d mm thick per unit irradiance (normal to the light) arriving at cosine
    `back` on its far face, per unit base colour, leaving the near face (3,): the exact table at eta 1
    (`slab_table`: ln T), ln T - ln(tau / (1 + tau)) linear in the optical thickness tau = d / l between
    its nodes (`_knee`) and linear in the cosine; below 1/16 mean free path linear in tau to 0, beyond
    64 mean free paths decaying as e^{-k (tau - 64)} 64 / tau. At eta > 1: Fresnel transmission in at
    `back`, the table at the refracted cosine, and 1 - F_dr(eta) out (the interface's internal
    reflections between the faces are left out). GLSL twin sss_slab_through. `back` and `d_mm` may be
    arrays (broadcast together): the result is then (..., 3), each entry what the scalar call gives."""
    eta = float(clamp_eta(eta))
    b, d = np.broadcast_arrays(np.clip(np.asarray(back, np.float64), 0.0, 1.0), np.asarray(d_mm, np.float64))
    d = np.maximum(d, 0.0)
    t_in = np.ones_like(b)
    t_out = 1.0
    if eta > 1.0:
        t_in = 1.0 - np.asarray(fresnel_dielectric(b, eta), np.float64)
        b = np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + b * b, 0.0)) / eta
        t_out = 1.0 - float(fdr(eta))
    l = np.asarray(mfp_mm, np.float64).reshape(3)
    k = slab_decay(alpha)
    tab = np.asarray(table, np.float64).reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)
    xm = b * (SLAB_MU_NODES - 1)
    i = np.minimum(np.floor(xm).astype(np.int64), SLAB_MU_NODES - 2)[..., None]
    fm = (xm - i[..., 0])[..., None]
    crosses = (l > 0) & (d[..., None] > 0)  # (..., 3): light to carry (no medium or no thickness: none)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(crosses, d[..., None] / np.where(l > 0, l, 1.0), 1.0)
    tmin, tmax = 2.0**LOG2_TAU_MIN, 2.0**LOG2_TAU_MAX
    tc = np.minimum(np.maximum(tau, tmin), tmax)
    j = np.minimum(np.floor((np.log2(tc) - LOG2_TAU_MIN) * 2.0).astype(np.int64), SLAB_TAU_NODES - 2)
    t0 = 2.0 ** (LOG2_TAU_MIN + 0.5 * j)
    ft = np.minimum(np.maximum((tc - t0) / (t0 * (np.sqrt(2.0) - 1.0)), 0.0), 1.0)
    c = np.arange(3)
    # ln T - ln(tau / (1 + tau)) linear in tau between the nodes (the shape's knee taken out)
    k0, k1, kc = _knee(t0), _knee(t0 * np.sqrt(2.0)), _knee(tc)
    rows0 = (tab[i, j, c] - k0) * (1.0 - ft) + (tab[i, j + 1, c] - k1) * ft + kc
    rows1 = (tab[i + 1, j, c] - k0) * (1.0 - ft) + (tab[i + 1, j + 1, c] - k1) * ft + kc
    v = np.exp(rows0 * (1.0 - fm) + rows1 * fm)  # ln T linear in the cosine too
    v = np.where(tau < tmin, v * tau / tmin, v)
    v = np.where(tau > tmax, v * np.exp(-k * (tau - tmax)) * tmax / tau, v)
    return t_in[..., None] * t_out * np.where(crosses, v, 0.0)


# -- the angular distribution of the light that comes through -------------------------------------------
#
# Light that crossed a few mean free paths leaves the far face more along the normal than light
# reflected by a thick medium (3 mm of skin1 lit at 30 degrees, exit cosine 0.95: 1.15 / 1.37 / 1.65
# times the reflected light's exit factor, R G B); thinner than a mean free path it leaves more at
# grazing cosines. The transmitted radiance per unit incident flux, S(mu, mu0), is symmetric
# (reciprocity). Its separable part built from the slab's own directional transmittance T (the table
# above), T(mu) T(mu0) / (pi T_d) with T_d = 2 int T(mu) mu dmu, carries exactly the transmitted flux
# and is exact for thick slabs (one diffusion mode), but misses how the exit distribution follows the
# incident cosine (up to 40 % at 2-8 mean free paths for albedo 0.5). The remainder R = S - T T/(pi T_d)
# has zero cosine-weighted mean in each argument; its leading eigenfunction (cosine-weighted inner
# product; the eigenvalue is negative for every albedo and thickness) takes most of it:
#
#     S(mu, mu0) ~= (T_d / pi) [u(mu) u(mu0) - h(mu) h(mu0)],   u = T / T_d,   h = sqrt(-lambda pi / T_d) psi
#
# within 2 % of the exact doubling for albedos >= 0.5 up to 8 mean free paths and exit and incident
# cosines >= 0.3 (tests/scene/optics/test_slab.py; separable alone: 40 %). The exit factor of the light
# that came through (cosine-weighted hemispherical mean 1, like boundary.py's exit(mu)) for light that
# arrived at cosine mu0, through an interface of index eta (mu_t the cosines inside, F Fresnel):
#
#     exit_T(mu; mu0) = (1 - F(mu)) [u(mu_t) - h(mu_t) q] / (A - B q),   q = h(mu0_t) / u(mu0_t)
#
# A = 2 int (1 - F) u(mu_t) mu dmu, B = 2 int (1 - F) h(mu_t) mu dmu per thickness (1 and about 0 at
# eta 1). u and h do not depend on the colour (T and lambda scale alike).

_NORM_QUAD = 128  # Gauss-Legendre cosines of the exit normalisations
# |q| = |h / u| at the incident cosine: at most 1.4 for cosines >= 1/8, every albedo and thickness of the
# table; larger only where u is tiny (grazing light through tens of mean free paths of a dark medium,
# where the rank-2 form fails and almost nothing comes through), so q is clamped there, and the
# normalisation A - B q kept above A / 2 (|B q| < 0.1 wherever the form holds).
EXIT_Q_MAX = 2.0


@table(maxsize=512)
def _eigen_table(a: float) -> np.ndarray:
    """(SLAB_MU_NODES, SLAB_TAU_NODES): h = sqrt(-lambda pi / T_d) psi at the table's cosines and
    thicknesses (psi the remainder's leading eigenfunction, unit cosine-weighted norm, psi(1) > 0;
    0 where the eigenvalue is not negative or nothing comes through)."""
    mu_nodes = slab_mu_nodes()
    out = np.zeros((SLAB_MU_NODES, SLAB_TAU_NODES))
    if a <= 0.0:
        return out
    q = np.arange(QUAD_NODES)
    p = np.arange(QUAD_NODES, QUAD_NODES + SLAB_MU_NODES)
    for half in (0, 1):
        start = _LOG2_D0 + 0.5 * half
        steps = int(round(LOG2_TAU_MAX - start))
        for k, (tau, mu, wt, t) in enumerate(_doubling_steps(a, start, steps, mu_nodes)):
            lt = start + k
            j = (lt - LOG2_TAU_MIN) * 2.0
            if lt < LOG2_TAU_MIN - 1e-9 or abs(j - round(j)) > 1e-9 or round(j) >= SLAB_TAU_NODES:
                continue
            mq, wq = mu[q], wt[q]
            weight = 2.0 * np.pi * mq * wq  # the cosine-weighted measure (flux of unit radiance)
            tq = t[np.ix_(q, q)] - np.diag(np.exp(-tau / mq))
            s_qq = tq / weight[:, None]  # S(mu_i, mu_j): radiance at mu_i per unit flux arriving at mu_j
            s_pq = t[np.ix_(q, p)].T / weight[None, :]  # S(mu_probe, mu_j) = S(mu_j, mu_probe) (reciprocity)
            t_q = tq.sum(axis=0)  # directional transmittance at the quadrature cosines
            t_p = t[np.ix_(q, p)].sum(axis=0)
            t_d = float(2.0 * np.sum(wq * mq * t_q))
            if t_d <= 1e-300:
                continue
            r_qq = s_qq - np.outer(t_q, t_q) / (np.pi * t_d)
            r_pq = s_pq - np.outer(t_p, t_q) / (np.pi * t_d)
            sw = np.sqrt(weight)
            m = sw[:, None] * r_qq * sw[None, :]
            lam, vec = np.linalg.eigh(0.5 * (m + m.T))
            i = int(np.argmax(np.abs(lam)))
            if lam[i] >= 0.0:
                continue
            psi_q = vec[:, i] / sw
            psi_p = (r_pq @ (weight * psi_q)) / lam[i]  # the eigen equation at the table's cosines
            if psi_p[-1] < 0.0:
                psi_p = -psi_p
            out[:, int(round(j))] = np.sqrt(-lam[i] * np.pi / t_d) * psi_p
    return out


def slab_exit_tables(alpha, table, eta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exit factor's tables for a material: (norm, h, ab). norm (SLAB_TAU_NODES, 3): ln T_d, the
    cosine-weighted mean of T from `table` (slab_table: ln T per unit colour; T linear in the cosine as
    the lookup reads it), so u = exp(ln T - ln T_d); h (SLAB_MU_NODES * SLAB_TAU_NODES, 3): the
    eigenfunction term, rows as the table's; ab (2 * SLAB_TAU_NODES, 3): A per thickness node, then B
    (the normalisations through the interface of index eta). GLSL u_sss_slab_norm, u_sss_slab_h,
    u_sss_slab_ab."""
    eta = float(clamp_eta(eta))
    al = np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0)
    x, w = np.polynomial.legendre.leggauss(_NORM_QUAD)
    mu, w = 0.5 * (x + 1.0), 0.5 * w
    t_rows = _table_rows(mu, np.exp(np.asarray(table, np.float64).reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)))
    t_d = 2.0 * np.einsum("q,qjc->jc", w * mu, t_rows)
    norm = np.maximum(np.log(np.maximum(t_d, 1e-300)), 2.0 * LN_FLOOR)
    h = np.stack([_eigen_table(round(float(al[c]), 12)) for c in range(3)], axis=-1)  # (MU, TAU, 3)
    t_out, mu_t = np.ones_like(mu), mu
    if eta > 1.0:
        t_out = 1.0 - np.asarray(fresnel_dielectric(mu, eta), np.float64)
        mu_t = np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + mu * mu, 0.0)) / eta
    t_in = _table_rows(mu_t, np.exp(np.asarray(table, np.float64).reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)))
    u_t = np.exp(np.log(np.maximum(t_in, 1e-300)) - norm[None])
    a_ = 2.0 * np.einsum("q,qjc->jc", w * mu * t_out, u_t)
    b_ = 2.0 * np.einsum("q,qjc->jc", w * mu * t_out, _table_rows(mu_t, h))
    return norm, h.reshape(-1, 3), np.concatenate([a_, b_])


def _table_rows(mu: np.ndarray, tab: np.ndarray) -> np.ndarray:
    """(len(mu), SLAB_TAU_NODES, ...): `tab` (SLAB_MU_NODES, SLAB_TAU_NODES, ...) linear in the cosine."""
    xm = np.clip(mu, 0.0, 1.0) * (SLAB_MU_NODES - 1)
    i = np.minimum(np.floor(xm).astype(np.int64), SLAB_MU_NODES - 2)
    fm = (xm - i).reshape((-1,) + (1,) * (tab.ndim - 1))
    return tab[i] * (1.0 - fm) + tab[i + 1] * fm


def _exit_uh(tab, h, x, j, ft, lnn, c) -> tuple[float, float]:
    """u and h of channel c at cosine x between thickness nodes j, j + 1 (fraction ft; ln T_d lnn)."""
    xm = x * (SLAB_MU_NODES - 1)
    i = min(int(np.floor(xm)), SLAB_MU_NODES - 2)
    fm = xm - i
    rows = np.exp(tab[i : i + 2, j, c] * (1.0 - ft) + tab[i : i + 2, j + 1, c] * ft - lnn)
    hs = h[i : i + 2, j, c] * (1.0 - ft) + h[i : i + 2, j + 1, c] * ft
    return rows[0] * (1.0 - fm) + rows[1] * fm, hs[0] * (1.0 - fm) + hs[1] * fm


def slab_exit(mu, mu0, d_mm, table, exit_tables, mfp_mm, eta) -> np.ndarray:
    """(3,) the exit factor of light that came through a part d mm thick, arriving on its far face
    at cosine mu0 and leaving at cosine mu (cosine-weighted hemispherical mean 1 over mu, like
    boundary.py's exit): (1 - F(mu)) [u(mu_t) - h(mu_t) q] / (A - B q), q = h(mu0_t) / u(mu0_t), from
    `table` (slab_table) and `exit_tables` (slab_exit_tables): ln T linear in tau between the nodes
    (the knee slab_through takes out would cancel in u = T / T_d), u and h linear in the cosine, h, A
    and B linear in tau, with tau = d / l clamped to the table (beyond it the frame's extrapolations of
    T cancel in u); q clamped to +-EXIT_Q_MAX, A - B q at least A / 2, the result at least 0; 1 for a
    channel without scattering (l = 0). GLSL sss_slab_exit."""
    eta = float(clamp_eta(eta))
    norm, h, ab = (np.asarray(x, np.float64) for x in exit_tables)
    tab = np.asarray(table, np.float64).reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)
    h = h.reshape(SLAB_MU_NODES, SLAB_TAU_NODES, 3)
    m, m0 = float(np.clip(mu, 0.0, 1.0)), float(np.clip(mu0, 0.0, 1.0))
    t_out = 1.0
    if eta > 1.0:
        t_out = 1.0 - float(fresnel_dielectric(m, eta))
        m = float(np.sqrt(max((eta - 1.0) * (eta + 1.0) + m * m, 0.0)) / eta)
        m0 = float(np.sqrt(max((eta - 1.0) * (eta + 1.0) + m0 * m0, 0.0)) / eta)
    l = np.asarray(mfp_mm, np.float64).reshape(3)
    d = max(float(d_mm), 0.0)
    tmin, tmax = 2.0**LOG2_TAU_MIN, 2.0**LOG2_TAU_MAX
    out = np.ones(3)
    for c in range(3):
        if l[c] <= 0:
            continue
        tc = min(max(d / l[c], tmin), tmax)
        j = min(int(np.floor((np.log2(tc) - LOG2_TAU_MIN) * 2.0)), SLAB_TAU_NODES - 2)
        t0 = 2.0 ** (LOG2_TAU_MIN + 0.5 * j)
        ft = min(max((tc - t0) / (t0 * (np.sqrt(2.0) - 1.0)), 0.0), 1.0)
        lnn = norm[j, c] * (1.0 - ft) + norm[j + 1, c] * ft
        a_ = ab[j, c] * (1.0 - ft) + ab[j + 1, c] * ft
        b_ = ab[SLAB_TAU_NODES + j, c] * (1.0 - ft) + ab[SLAB_TAU_NODES + j + 1, c] * ft
        u, hv = _exit_uh(tab, h, m, j, ft, lnn, c)
        u0, h0 = _exit_uh(tab, h, m0, j, ft, lnn, c)
        q = min(max(h0 / max(u0, 1e-30), -EXIT_Q_MAX), EXIT_Q_MAX)
        out[c] = t_out * max(u - hv * q, 0.0) / max(a_ - b_ * q, 0.5 * a_, 1e-30)
    return out
