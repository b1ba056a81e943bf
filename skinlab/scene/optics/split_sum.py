"""Image-based specular light by the split sum (Karis 2013, "Real Shading in Unreal Engine 4",
docs/references.md#environment-lighting): the integral of the environment's radiance times the GGX
BRDF is split into the radiance prefiltered with the GGX lobe about the mirror direction (one level
per roughness, ``prefilter``) and the BRDF's directional albedo as F0 A + B (``brdf_table``).

NumPy twins of skinlab/shaders/lib/environment.glsl: ``equirect_uv`` (a direction in the map's frame
to texture coordinates), ``sample_levels`` (what ``textureLod`` returns from the prefiltered levels:
bilinear in each level, repeat across u, clamp in v, linear between levels), ``table_lookup`` (the
BRDF table as the GPU's bilinear filter reads it) and ``specular_occlusion``.

The map is latitude-longitude with Mitsuba's axes (skinlab/scene/envmap.py): u = atan2(x, -z) / 2 pi,
v = acos(y) / pi, row 0 at the top (+Y); texel (i, j) of a W x H level is centred on
u = (i + 1/2) / W, v = (j + 1/2) / H.
"""

from __future__ import annotations

import numpy as np

from .brdf import ggx_alpha, ggx_d, smith_g2
from .constants import MIN_COS, PI

LEVELS = 6  # prefiltered levels: level k holds roughness k / (LEVELS - 1)
BASE_WIDTH = 512  # level 0's width (height half of it); level k is BASE_WIDTH >> k wide
PREFILTER_SAMPLES = 128  # GGX samples per texel of a level (filtered importance sampling)
IRRADIANCE_WIDTH = 64  # the diffuse irradiance map: 64 x 32 texels (irradiance varies slowly)
TABLE_SIZE = 32  # the BRDF table: TABLE_SIZE cosines x TABLE_SIZE roughnesses
TABLE_SAMPLES = 512


def hammersley(n: int) -> np.ndarray:
    """(n, 2) the Hammersley set: (i / n, radical inverse of i in base 2)."""
    i = np.arange(n, dtype=np.uint64)
    bits = i.copy()
    bits = ((bits << np.uint64(16)) | (bits >> np.uint64(16))) & np.uint64(0xFFFFFFFF)
    for shift, mask in ((1, 0x55555555), (2, 0x33333333), (4, 0x0F0F0F0F), (8, 0x00FF00FF)):
        m = np.uint64(mask)
        bits = ((bits & m) << np.uint64(shift)) | ((bits >> np.uint64(shift)) & m)
    return np.stack([(i.astype(np.float64) + 0.5) / n, bits.astype(np.float64) / 2.0**32], 1)


def equirect_uv(d) -> tuple[np.ndarray, np.ndarray]:
    """Texture coordinates (u in [0, 1), v in [0, 1]) of directions d (..., 3) in the map's frame:
    u = atan2(x, -z) / 2 pi, v = atan2(|(x, z)|, y) / pi; u = 0 along the poles' axis."""
    d = np.asarray(d, np.float64)
    side = np.abs(d[..., 0]) + np.abs(d[..., 2]) > 1e-12
    u = np.where(side, np.mod(np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * PI), 1.0), 0.0)
    v = np.arctan2(np.hypot(d[..., 0], d[..., 2]), d[..., 1]) / PI
    return u, v


def texel_directions(width: int, height: int) -> np.ndarray:
    """(H, W, 3) the unit direction at each texel centre (row 0 at the top)."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, theta = np.meshgrid(2.0 * PI * u, PI * v)
    s = np.sin(theta)
    return np.stack([np.sin(phi) * s, np.cos(theta), -np.cos(phi) * s], -1)


def texel_solid_angles(width: int, height: int) -> np.ndarray:
    """(H, W) each texel's solid angle (exact for the band of rows: 2 pi / W (cos t0 - cos t1))."""
    t = PI * np.arange(height + 1) / height
    band = (np.cos(t[:-1]) - np.cos(t[1:])) * (2.0 * PI / width)
    return np.repeat(band[:, None], width, 1)


def bilinear(img: np.ndarray, u, v) -> np.ndarray:
    """(..., C) bilinear lookup of img (H, W, C) as the GPU filters it: repeat across u, clamp to the
    edge in v, texel centres at (i + 1/2) / W."""
    h, w = img.shape[:2]
    x = np.asarray(u, np.float64) * w - 0.5
    y = np.asarray(v, np.float64) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    i0 = np.mod(x0.astype(np.int64), w)
    i1 = np.mod(i0 + 1, w)
    j0 = np.clip(y0.astype(np.int64), 0, h - 1)
    j1 = np.clip(y0.astype(np.int64) + 1, 0, h - 1)
    top = img[j0, i0] * (1 - fx) + img[j0, i1] * fx
    bottom = img[j1, i0] * (1 - fx) + img[j1, i1] * fx
    return top * (1 - fy) + bottom * fy


def sample_levels(levels: list[np.ndarray], d, lod) -> np.ndarray:
    """What ``textureLod`` returns from the level chain at directions d (map frame) and level of
    detail lod (clamped to the chain): bilinear in the two nearest levels, linear between them."""
    u, v = equirect_uv(d)
    lod = np.clip(np.asarray(lod, np.float64), 0.0, len(levels) - 1)
    lod = np.broadcast_to(lod, u.shape)
    lo = np.floor(lod).astype(np.int64)
    hi = np.minimum(lo + 1, len(levels) - 1)
    f = (lod - lo)[..., None]
    out = np.zeros(u.shape + (levels[0].shape[2],))
    for k in np.unique(np.concatenate([lo.ravel(), hi.ravel()])):
        s = bilinear(levels[k], u, v)
        out += s * (np.where(lo == k, 1.0, 0.0)[..., None] * (1 - f) + np.where(hi == k, 1.0, 0.0)[..., None] * f)
    return out


def downsample(img: np.ndarray) -> np.ndarray:
    """Each 2 x 2 block's mean weighted by the texels' solid angles (H and W even): the mean radiance
    over the block's solid angle, so the sphere's total is kept."""
    h, w = img.shape[:2]
    omega = texel_solid_angles(w, h)[:, 0].reshape(h // 2, 2)
    blocks = img.reshape(h // 2, 2, w // 2, 2, -1)
    return (blocks * omega[:, :, None, None, None]).sum((1, 3)) / (2.0 * omega.sum(1))[:, None, None]


def resample(img: np.ndarray, width: int) -> np.ndarray:
    """img at width x width / 2: box-averaged down by powers of two, then bilinear to the exact size."""
    while img.shape[1] >= 2 * width and img.shape[1] % 2 == 0 and img.shape[0] % 2 == 0:
        img = downsample(img)
    if img.shape[1] == width and img.shape[0] == width // 2:
        return img
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(width // 2) + 0.5) / (width // 2)
    uu, vv = np.meshgrid(u, v)
    return bilinear(img, uu, vv)


def irradiance_map(image: np.ndarray, width: int = IRRADIANCE_WIDTH, source_width: int = 128) -> np.ndarray:
    """(width / 2, width, 3) the irradiance E(n) = sum L(w) max(n.w, 0) dw on a surface of normal n at
    each texel's direction, from the image box-averaged to source_width (the cosine lobe is smooth: at
    128 x 64 source texels the sum is within 0.1 % of the full map's)."""
    src = resample(np.asarray(image, np.float64), source_width)
    d = texel_directions(source_width, source_width // 2).reshape(-1, 3)
    weighted = src.reshape(-1, 3) * texel_solid_angles(source_width, source_width // 2).reshape(-1, 1)
    n = texel_directions(width, width // 2).reshape(-1, 3)
    out = np.zeros((len(n), 3))
    for start in range(0, len(n), 512):
        out[start : start + 512] = np.maximum(n[start : start + 512] @ d.T, 0.0) @ weighted
    return out.reshape(width // 2, width, 3).astype(np.float32)


KERNEL_NODES = 17  # single-scattering layers: view cosines mu_j = j / 16 (boundary.ANGULAR_NODES)
KERNEL_POWERS = (2, 3)  # the entering light's layers after them: int L max(n.w, 0)^k dw
KERNEL_LAYERS = KERNEL_NODES + len(KERNEL_POWERS)


def kernel_weights(cosines: np.ndarray) -> np.ndarray:
    """(KERNEL_LAYERS, ...) the zonal kernels of :func:`kernel_maps` at cosines t = n.w (0 for t <= 0):
    t / (4 pi (mu_j + t)) for the single-scattering layers, then t^k."""
    t = np.maximum(np.asarray(cosines, np.float64), 0.0)
    mu = np.linspace(0.0, 1.0, KERNEL_NODES).reshape((-1,) + (1,) * t.ndim)
    single = np.where(t > 0.0, t / (4.0 * np.pi * np.maximum(mu + t, 1e-30)), 0.0)
    return np.concatenate([single, np.stack([t**k for k in KERNEL_POWERS])])


def kernel_maps(image: np.ndarray, width: int = IRRADIANCE_WIDTH, source_width: int = 128) -> np.ndarray:
    """(KERNEL_LAYERS, width / 2, width, 3): the map convolved with the zonal kernels of the light a
    medium takes from it at each texel's normal n (exact sums over the image box-averaged to
    source_width, as :func:`irradiance_map`). Layer j < KERNEL_NODES: S_j(n) = int L(w) t / (4 pi
    (mu_j + t)) dw, t = max(n.w, 0): Jensen's single scattering of an index-matched medium of albedo a
    toward a view at cosine mu_j is a S_j(n) (isotropic phase; Chandrasekhar's first order,
    skinlab/scene/optics/boundary.py), exact for any map, where nine SH bands are not: its kernel is
    nearly a step toward grazing views. Then int L t^k dw for k in KERNEL_POWERS: with the irradiance
    (k = 1) they give the light entering the multiple scattering, int L A_ms(t) t dw, for A_ms fitted
    by c_0 + c_1 t + c_2 t^2 (boundary.entry_kernel_coefficients)."""
    src = resample(np.asarray(image, np.float64), source_width)
    d = texel_directions(source_width, source_width // 2).reshape(-1, 3)
    weighted = src.reshape(-1, 3) * texel_solid_angles(source_width, source_width // 2).reshape(-1, 1)
    n = texel_directions(width, width // 2).reshape(-1, 3)
    weighted32 = weighted.astype(np.float32)
    mus = np.linspace(0.0, 1.0, KERNEL_NODES, dtype=np.float32)
    out = np.zeros((KERNEL_LAYERS, len(n), 3))
    for start in range(0, len(n), 512):
        t = np.maximum(n[start : start + 512] @ d.T, 0.0).astype(np.float32)  # (512, texels)
        for j, mu in enumerate(mus):  # t / (mu + t): float32 is plenty for a sum of positive terms
            out[j, start : start + 512] = (t / (mu + t + np.float32(1e-30))) @ weighted32
        for i, k in enumerate(KERNEL_POWERS):
            out[KERNEL_NODES + i, start : start + 512] = (t**k) @ weighted32
    out[:KERNEL_NODES] /= 4.0 * np.pi
    return out.reshape(KERNEL_LAYERS, width // 2, width, 3).astype(np.float32)


def uniform_kernel_maps(radiance) -> np.ndarray:
    """(KERNEL_LAYERS, 1, 2, 3) :func:`kernel_maps` of a uniform sky of this radiance (closed forms):
    S_j = L (1 - mu_j ln(1 + 1/mu_j)) / 2, int L t^k dw = 2 pi L / (k + 1)."""
    c = np.asarray(radiance, np.float64).reshape(3)
    mu = np.linspace(0.0, 1.0, KERNEL_NODES)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(mu > 0, mu * np.log1p(1.0 / np.where(mu > 0, mu, 1.0)), 0.0)
    f = np.concatenate([0.5 * (1.0 - log_term), [2.0 * np.pi / (k + 1) for k in KERNEL_POWERS]])
    return np.broadcast_to((f[:, None] * c)[:, None, None, :], (KERNEL_LAYERS, 1, 2, 3)).astype(np.float32)


def kernel_lookup(kernels: np.ndarray, d, layer: int) -> np.ndarray:
    """Layer `layer` of :func:`kernel_maps` read bilinearly at map-frame directions d (the shader's
    env_kernel)."""
    u, v = equirect_uv(d)
    return bilinear(kernels[layer], u, v)


def _frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent and bitangent of unit normals (N, 3) (Duff et al. 2017)."""
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], 1)
    s = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], 1)
    return t, s


def prefilter(image: np.ndarray, levels: int = LEVELS, width: int = BASE_WIDTH, samples: int = PREFILTER_SAMPLES):
    """The chain of prefiltered radiance levels of an equirectangular image (H, W, 3): level 0 the image
    at width x width/2, level k (width >> k wide) the radiance convolved with the GGX lobe of roughness
    k / (levels - 1) about each texel's direction, with n = v = r (Karis 2013), weighted by n.l.
    Filtered importance sampling (Krivanek & Colbert 2008): each sample reads the source's box
    pyramid at the level whose texel matches the sample's solid angle, so a few samples per texel
    give a smooth result."""
    base = resample(np.asarray(image, np.float64), width)
    pyramid = [base]
    while pyramid[-1].shape[1] > 2 and pyramid[-1].shape[0] % 2 == 0:
        pyramid.append(downsample(pyramid[-1]))
    texel_omega = 4.0 * PI / (base.shape[0] * base.shape[1])
    xi = hammersley(samples)
    out = [base.astype(np.float32)]
    for k in range(1, levels):
        w = max(width >> k, 2)
        rough = k / (levels - 1)
        a = float(ggx_alpha(rough))
        cos_h = np.sqrt((1.0 - xi[:, 0]) / (1.0 + (a * a - 1.0) * xi[:, 0]))
        sin_h = np.sqrt(np.maximum(1.0 - cos_h**2, 0.0))
        phi = 2.0 * PI * xi[:, 1]
        h_local = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], 1)
        nol = 2.0 * cos_h**2 - 1.0
        keep = nol > 0.0
        h_local, nol, cos_h = h_local[keep], nol[keep], cos_h[keep]
        pdf = ggx_d(cos_h, a) / 4.0  # pdf of l: D NoH / (4 VoH), VoH = NoH for n = v
        lod = np.maximum(0.5 * np.log2((1.0 / (samples * pdf)) / texel_omega) + 1.0, 0.0)
        n = texel_directions(w, w // 2).reshape(-1, 3)
        t, s = _frame(n)
        result = np.zeros((len(n), 3))
        for hl, weight, level in zip(h_local, nol, lod):  # one sample of every texel at a time
            hv = hl[0] * t + hl[1] * s + hl[2] * n
            lv = 2.0 * hl[2] * hv - n
            lv /= np.linalg.norm(lv, axis=-1, keepdims=True)
            result += weight * sample_levels(pyramid, lv, level)
        result /= nol.sum()
        out.append(result.reshape(w // 2, w, 3).astype(np.float32))
    return out


def brdf_table(size: int = TABLE_SIZE, samples: int = TABLE_SAMPLES) -> np.ndarray:
    """(size, size, 2): rows roughness j / (size - 1), columns n.v = i / (size - 1) (at least
    MIN_COS); (A, B) with the GGX specular's directional albedo = F0 A + B for Schlick's Fresnel
    (Skinlab's specular_ggx: GGX D, height-correlated Smith G2), by importance sampling the GGX
    normal distribution."""
    xi = hammersley(samples)
    out = np.zeros((size, size, 2))
    for j in range(size):
        a = float(ggx_alpha(j / (size - 1)))
        cos_h = np.sqrt((1.0 - xi[:, 0]) / (1.0 + (a * a - 1.0) * xi[:, 0]))
        sin_h = np.sqrt(np.maximum(1.0 - cos_h**2, 0.0))
        phi = 2.0 * PI * xi[:, 1]
        h = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], 1)
        for i in range(size):
            nov = max(i / (size - 1), MIN_COS)
            v = np.array([np.sqrt(1.0 - nov * nov), 0.0, nov])
            voh = h @ v
            l = 2.0 * voh[:, None] * h - v
            nol = l[:, 2]
            ok = (nol > 0.0) & (voh > 0.0)
            g = smith_g2(nol[ok], nov, a)
            g_vis = g * voh[ok] / (np.maximum(cos_h[ok], MIN_COS) * nov)
            fc = (1.0 - voh[ok]) ** 5
            out[j, i] = [((1.0 - fc) * g_vis).sum() / samples, (fc * g_vis).sum() / samples]
    return out


def table_lookup(table: np.ndarray, nov, roughness) -> np.ndarray:
    """(..., 2) the BRDF table at (n.v, roughness) as the GPU's bilinear filter reads it (node i at
    texel centre i: coordinates (x (size - 1) + 1/2) / size)."""
    size = table.shape[0]
    x = np.clip(np.asarray(nov, np.float64), 0.0, 1.0) * (size - 1)
    y = np.clip(np.asarray(roughness, np.float64), 0.0, 1.0) * (size - 1)
    i0 = np.minimum(np.floor(x).astype(np.int64), size - 2)
    j0 = np.minimum(np.floor(y).astype(np.int64), size - 2)
    fx, fy = (x - i0)[..., None], (y - j0)[..., None]
    top = table[j0, i0] * (1 - fx) + table[j0, i0 + 1] * fx
    bottom = table[j0 + 1, i0] * (1 - fx) + table[j0 + 1, i0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def specular_occlusion(nov, visibility, roughness) -> np.ndarray:
    """The share of the prefiltered specular light a surface that sees a fraction `visibility` of the
    sky receives (Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", sec. 4.10.2): 1 for an
    unoccluded surface, `visibility` at normal incidence, less at grazing views of rough surfaces."""
    nov = np.clip(np.asarray(nov, np.float64), 0.0, 1.0)
    ao = np.clip(np.asarray(visibility, np.float64), 0.0, 1.0)
    return np.clip((nov + ao) ** np.exp2(-16.0 * np.asarray(roughness, np.float64) - 1.0) - 1.0 + ao, 0.0, 1.0)
