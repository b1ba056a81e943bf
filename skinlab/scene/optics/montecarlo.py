"""Monte Carlo reference: vectorised random walk in a semi-infinite homogeneous medium.

Units: mean free paths (sigma_t = 1); scale with :meth:`MCResult.scaled`. The medium fills z > 0,
light arrives from z < 0 at the origin. Per photon:

* entry: ``incidence="normal"`` (along +z) or ``"diffuse"`` (cosine-distributed, refracted by
  Snell's law into the medium). ``entry_fresnel=False`` (default) normalises to the light that
  *enters* (as the analytic profiles do); True weights each photon by 1 - F(cos_i) so that the
  result is relative to the incident light with the specular reflection excluded.
* free flights s = -ln(xi); at a collision the weight is multiplied by the single-scattering albedo
  (implicit capture) and a new direction is drawn from Henyey-Greenstein(g) (isotropic for g = 0).
* a flight that crosses z = 0 stops at the surface; the photon leaves with probability
  1 - F(cos) (exact dielectric Fresnel, eta = n_medium/n_outside; total internal reflection gives
  F = 1) and is tallied at r = sqrt(x^2 + y^2) with its weight, otherwise it is specularly reflected
  back in and the (memoryless) flight restarts from the surface.
* Russian roulette below weight ``roulette_below``: survive with probability ``roulette_p`` and
  weight / roulette_p (unbiased). Walks still alive after ``max_steps`` collisions are dropped and
  their weight reported as ``capped`` (a bias bound: the exact total lies in [total, total + capped]).

Exits after exactly one collision are also tallied apart (``single``): the single-scattering part
(Jensen 2001's term), counted from first-bounce photons.

Each photon exits at most once, so its contribution x_i to a bin (or to the total) is its weight or
0; the standard errors are sqrt((mean(x^2) - mean(x)^2)/(N - 1)) from the per-photon sums.
Deterministic for a seed: photons are generated in fixed-size batches, batch k from
SeedSequence(seed).spawn(...)[k], independent of the number of worker processes.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from skinlab.declare import Field

from .fresnel import fresnel_dielectric

BATCH = 1 << 16
MAX_PHOTONS = 10**10  # about a day on one core; more is a typo (1e30) rather than a plan

# a walk's parameters, declared once: simulate() checks them, `skinlab mc` takes them as options
WALK_FIELDS = {
    f.name: f
    for f in (
        Field("albedo", "float", None, (0.0, 1.0), doc="single-scattering albedo sigma_s/sigma_t"),
        Field("eta", "float", 1.3, (0.0, math.inf), lo_open=True, doc="relative index of refraction, medium/outside"),
        Field("g", "float", 0.0, (-1.0, 1.0), lo_open=True, hi_open=True, doc="Henyey-Greenstein mean cosine"),
        Field("incidence", "choice", "normal", choices=("normal", "diffuse"), doc="how light enters"),
        Field("photons", "int", 100_000, (2, MAX_PHOTONS), doc="photons to trace"),
        Field("seed", "int", 0, (0, math.inf), doc="random seed; the same seed gives the same result"),
        Field(
            "max_steps",
            "int",
            100_000,
            (1, math.inf),
            doc="collisions per walk before it is dropped and counted as capped",
        ),  # fmt: skip
        Field("workers", "int", 1, (1, math.inf), doc="processes"),
    )
}
DEFAULT_EDGES = np.concatenate([[0.0], np.geomspace(1e-2, 1e2, 81)])


@dataclass
class MCResult:
    """Radial reflectance profile in mean-free-path units (per unit area, per entering photon)."""

    r_edges: np.ndarray
    R: np.ndarray  # (B,) per unit area (1/mfp^2)
    R_se: np.ndarray  # (B,) standard error of R
    total: float  # total diffuse reflectance (all exits, also beyond the last edge)
    total_se: float
    photons: int
    capped: float  # weight per photon dropped at max_steps (upper bias bound of total)
    params: dict = field(default_factory=dict)
    single: float = 0.0  # reflectance of photons that left after exactly one collision
    single_se: float = 0.0

    @property
    def r_mid(self) -> np.ndarray:
        """Area-weighted bin centre: sqrt((r0^2 + r1^2)/2)."""
        e = self.r_edges
        return np.sqrt(0.5 * (e[:-1] ** 2 + e[1:] ** 2))

    def scaled(self, mfp_mm: float):
        """(r_edges_mm, R_per_mm2, R_se_per_mm2) for a medium with mean free path mfp_mm."""
        return self.r_edges * mfp_mm, self.R / mfp_mm**2, self.R_se / mfp_mm**2


def _check(albedo, eta, g, incidence, photons):
    for name, value in (("albedo", albedo), ("eta", eta), ("g", g), ("incidence", incidence)):
        WALK_FIELDS[name].check(value)
    if isinstance(photons, float) and np.isfinite(photons) and photons == int(photons):
        photons = int(photons)  # 1e5
    WALK_FIELDS["photons"].check(photons)


def _sample_hg(rng, n, g):
    xi = rng.random(n)
    if abs(g) < 1e-6:
        return 1.0 - 2.0 * xi
    t = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi)
    return np.clip((1.0 + g * g - t * t) / (2.0 * g), -1.0, 1.0)


def _scatter(rng, ux, uy, uz, g):
    """New direction: HG polar angle about the old direction, uniform azimuth (MCML rotation)."""
    n = len(ux)
    ct = _sample_hg(rng, n, g)
    st = np.sqrt(np.maximum((1.0 - ct) * (1.0 + ct), 0.0))
    phi = 2.0 * np.pi * rng.random(n)
    cp, sp = np.cos(phi), np.sin(phi)
    tmp = np.sqrt(np.maximum((1.0 - uz) * (1.0 + uz), 0.0))
    pole = tmp < 1e-6
    tmp = np.where(pole, 1.0, tmp)
    nx = st * (ux * uz * cp - uy * sp) / tmp + ux * ct
    ny = st * (uy * uz * cp + ux * sp) / tmp + uy * ct
    nz = -st * cp * tmp + uz * ct
    nx = np.where(pole, st * cp, nx)
    ny = np.where(pole, st * sp, ny)
    nz = np.where(pole, np.sign(uz) * ct, nz)
    inv = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
    return nx * inv, ny * inv, nz * inv


def _run_batch(args):
    (seed_seq, n, albedo, eta, g, incidence, entry_fresnel, edges, max_steps, roulette_below, roulette_p) = args
    rng = np.random.default_rng(seed_seq)
    nb = len(edges) - 1
    s1 = np.zeros(nb)
    s2 = np.zeros(nb)
    # entry
    if incidence == "normal":
        cos_i = np.ones(n)
    else:
        cos_i = np.sqrt(rng.random(n))
    sin_t = np.sqrt((1.0 - cos_i) * (1.0 + cos_i)) / eta
    uz = np.sqrt(np.maximum((1.0 - sin_t) * (1.0 + sin_t), 0.0))
    phi = 2.0 * np.pi * rng.random(n)
    ux, uy = sin_t * np.cos(phi), sin_t * np.sin(phi)
    w = np.ones(n)
    if entry_fresnel:
        w *= 1.0 - fresnel_dielectric(cos_i, eta)
    x = np.zeros(n)
    y = np.zeros(n)
    z = np.zeros(n)
    steps = np.zeros(n, dtype=np.int64)
    t1 = t2 = 0.0
    u1 = u2 = 0.0
    capped = 0.0
    while len(w):
        s = rng.standard_exponential(len(w))
        zn = z + s * uz
        out = zn < 0.0
        if out.any():
            io = np.nonzero(out)[0]
            t = z[io] / -uz[io]
            xe, ye = x[io] + t * ux[io], y[io] + t * uy[io]
            F = fresnel_dielectric(uz[io], eta)  # uz < 0: inside -> outside
            leave = rng.random(len(io)) >= F
            il = io[leave]
            wl = w[il]
            r = np.hypot(xe[leave], ye[leave])
            b = np.searchsorted(edges, r, side="right") - 1
            inb = (b >= 0) & (b < nb)
            s1 += np.bincount(b[inb], wl[inb], nb)
            s2 += np.bincount(b[inb], wl[inb] ** 2, nb)
            t1 += wl.sum()
            t2 += (wl**2).sum()
            w1 = wl[steps[il] == 1]
            u1 += w1.sum()
            u2 += (w1**2).sum()
            ir = io[~leave]
            x[ir], y[ir], z[ir] = xe[~leave], ye[~leave], 0.0
            uz[ir] = -uz[ir]
        col = ~out
        ic = np.nonzero(col)[0]
        x[ic] += s[ic] * ux[ic]
        y[ic] += s[ic] * uy[ic]
        z[ic] = zn[ic]
        w[ic] *= albedo
        ux[ic], uy[ic], uz[ic] = _scatter(rng, ux[ic], uy[ic], uz[ic], g)
        steps[ic] += 1
        # Russian roulette (unbiased): survive with p, weight / p
        low = col & (w < roulette_below) & (w > 0)
        if low.any():
            il = np.nonzero(low)[0]
            live = rng.random(len(il)) < roulette_p
            w[il] = np.where(live, w[il] / roulette_p, 0.0)
        over = col & (steps >= max_steps)
        if over.any():
            capped += w[over].sum()
        keep = (w > 0) & ~over
        if out.any():
            keep[io[leave]] = False
        if not keep.all():
            x, y, z, ux, uy, uz, w, steps = (a[keep] for a in (x, y, z, ux, uy, uz, w, steps))
    return s1, s2, t1, t2, capped, u1, u2


def simulate(
    albedo: float,
    eta: float = 1.0,
    g: float = 0.0,
    incidence: str = "normal",
    photons: int = 100_000,
    seed: int = 0,
    r_edges=None,
    max_steps: int = 100_000,
    entry_fresnel: bool = False,
    roulette_below: float = 1e-3,
    roulette_p: float = 0.1,
    progress: bool = True,
    workers: int = 1,
) -> MCResult:
    """Run the random walk; see the module docstring. ``workers`` > 1 uses processes (same result)."""
    albedo, eta, g = float(albedo), float(eta), float(g)
    _check(albedo, eta, g, incidence, photons)
    photons = int(photons)
    WALK_FIELDS["max_steps"].check(max_steps)
    WALK_FIELDS["seed"].check(seed)
    WALK_FIELDS["workers"].check(workers)
    edges = DEFAULT_EDGES if r_edges is None else np.asarray(r_edges, dtype=np.float64)
    if edges.ndim != 1 or len(edges) < 2 or np.any(np.diff(edges) <= 0) or edges[0] < 0:
        raise ValueError("r_edges: need an increasing sequence of at least 2 radii >= 0")
    sizes = [BATCH] * (photons // BATCH) + ([photons % BATCH] if photons % BATCH else [])
    seqs = np.random.SeedSequence(int(seed)).spawn(len(sizes))
    jobs = [
        (sq, n, albedo, eta, g, incidence, entry_fresnel, edges, int(max_steps), roulette_below, roulette_p)
        for sq, n in zip(seqs, sizes)
    ]
    from tqdm import tqdm

    bar = tqdm(
        total=photons,
        unit="photon",
        unit_scale=True,
        file=sys.stderr,
        disable=not progress,
        desc=f"MC albedo={albedo:g}",
    )
    s1 = np.zeros(len(edges) - 1)
    s2 = np.zeros_like(s1)
    t1 = t2 = capped = u1 = u2 = 0.0
    results: Iterable[tuple]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(workers) as ex:
            results = list(ex.map(_run_batch, jobs))
    else:
        results = (_run_batch(job) for job in jobs)
    for (b1, b2, b_t1, b_t2, b_cap, b_u1, b_u2), n in zip(results, sizes):
        s1 += b1
        s2 += b2
        t1 += b_t1
        t2 += b_t2
        capped += b_cap
        u1 += b_u1
        u2 += b_u2
        bar.update(n)
    bar.close()
    N = photons
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    mean = s1 / N
    var = np.maximum(s2 / N - mean**2, 0.0) / (N - 1)
    tmean = t1 / N
    tvar = max(t2 / N - tmean**2, 0.0) / (N - 1)
    umean = u1 / N
    uvar = max(u2 / N - umean**2, 0.0) / (N - 1)
    return MCResult(
        edges,
        mean / area,
        np.sqrt(var) / area,
        tmean,
        float(np.sqrt(tvar)),
        N,
        capped / N,
        dict(
            albedo=albedo,
            eta=eta,
            g=g,
            incidence=incidence,
            seed=int(seed),
            max_steps=int(max_steps),
            entry_fresnel=bool(entry_fresnel),
        ),
        umean,
        float(np.sqrt(uvar)),
    )


def chandrasekhar_h(albedo: float, mu, n: int = 200) -> np.ndarray:
    """Chandrasekhar's H-function for isotropic scattering (single-scattering albedo), by iterating
    1/H(mu) = sqrt(1 - a) + (a/2) int_0^1 mu' H(mu') / (mu + mu') dmu' on Gauss-Legendre nodes.
    Used for the exact eta = 1 reflectance of a semi-infinite medium: A(mu0) = 1 - H(mu0) sqrt(1 - a)
    (Chandrasekhar 1960, Radiative Transfer, ch. V)."""
    x, wq = np.polynomial.legendre.leggauss(n)
    m = 0.5 * (x + 1.0)
    wq = 0.5 * wq
    a = float(albedo)
    H = np.ones(n)
    for _ in range(2000):
        Hn = 1.0 / (np.sqrt(1.0 - a) + 0.5 * a * ((wq * m * H)[None, :] / (m[:, None] + m[None, :])).sum(1))
        if np.max(np.abs(Hn - H)) < 1e-14:
            H = Hn
            break
        H = Hn
    mu = np.atleast_1d(np.asarray(mu, dtype=np.float64))
    return 1.0 / (np.sqrt(1.0 - a) + 0.5 * a * ((wq * m * H)[None, :] / (mu[:, None] + m[None, :])).sum(1))


def exact_albedo_isotropic(albedo: float, mu0: float = 1.0) -> float:
    """Exact total reflectance of a semi-infinite isotropic medium, eta = 1, incidence cosine mu0."""
    return float(1.0 - chandrasekhar_h(albedo, mu0)[0] * np.sqrt(1.0 - albedo))
