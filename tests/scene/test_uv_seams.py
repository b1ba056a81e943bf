"""Seam extensions (skinlab/scene/uv_seams.py): seam edges found, the surface across a seam unfolded into the
owner chart's frame exactly where the layout is rigid, never over the owner's own chart."""

import numpy as np
import pytest

from skinlab.scene.uv_seams import charts, clip_triangles, seam_edges, seam_extension, seam_transform
from tests.seam_scenes import TEXELS, UV_SCALE, plane_mesh


def _chart_map(cut, right):
    """The plane's UV layout as a function of (x, y) for one half (tests/seam_scenes.py)."""
    t = 1.0 / TEXELS
    if not right:
        return lambda x, y: np.stack([26 * t + UV_SCALE * (x + 1), 128 * t + UV_SCALE * (y + 1)], -1)
    if cut == "rotate":
        return lambda x, y: np.stack([230 * t + UV_SCALE * (y + 1), 154 * t - UV_SCALE * x], -1)
    return lambda x, y: np.stack([230 * t + UV_SCALE * (y + 1), 26 * t + UV_SCALE * x], -1)


def test_one_chart_has_no_seam():
    m = plane_mesh(None, n=8)
    pairs, *_ = seam_edges(m)
    assert len(pairs) == 0 and charts(m).max() == 0
    assert seam_extension(m, 0.05).triangles == 0


@pytest.mark.parametrize("cut", ["rotate", "mirror"])
def test_the_cut_plane_unfolds_exactly(cut):
    """Both sides of the cut x = 0 are found (n seam edges, two charts); every extension triangle's
    UVs are where the owner chart's own layout puts its 3D corners (the layout is rigid, so the
    continuation is exact), its source UVs where the source chart has them, its depth >= 0, within
    the band, and it never covers the owner's chart."""
    n, band = 16, 20.0 / TEXELS
    m = plane_mesh(cut, n=n)
    pairs, _, pids, pid = seam_edges(m)
    ch = charts(m, pid)
    assert len(pairs) == n and ch.max() == 1
    assert all(ch[a] != ch[b] for a, b in pairs)
    ext = seam_extension(m, band)
    assert ext.triangles > 2 * n
    f = m.indices.astype(int)
    right_tri = m.positions[f].mean(1)[:, 0] > 0
    owner_right = right_tri[ext.owner]
    assert owner_right.any() and (~owner_right).any()  # both sides are extended
    assert (right_tri[ext.source] != owner_right).all()  # from the other side of the cut
    p = ext.positions.astype(np.float64)
    for side in (False, True):
        sel = owner_right == side
        own = _chart_map(cut, side)(p[sel, :, 0], p[sel, :, 1])
        np.testing.assert_allclose(ext.uv[sel], own, atol=2e-6)
        src = _chart_map(cut, not side)(p[sel, :, 0], p[sel, :, 1])
        np.testing.assert_allclose(ext.src_uv[sel], src, atol=2e-6)
        # past the cut: x >= 0 for the left chart's extension, x <= 0 for the right one's
        assert (p[sel, :, 0] * (1 if not side else -1) >= -1e-6).all()
    assert (ext.depth >= 0).all() and ext.depth.max() <= band + 2.0 * UV_SCALE * 2.0 / n
    # never over the owner's chart: no extension triangle's centroid lies inside an owner-chart triangle
    cen = ext.uv.mean(1).astype(np.float64)
    uv = m.uvs.astype(np.float64)[f]
    for k in range(ext.triangles):
        tris = uv[ch == ch[ext.owner[k]]]
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]

        def cross(o, q, r):
            return (q[:, 0] - o[:, 0]) * (r[1] - o[:, 1]) - (q[:, 1] - o[:, 1]) * (r[0] - o[:, 0])

        d1, d2, d3 = cross(a, b, cen[k]), cross(b, c, cen[k]), cross(c, a, cen[k])
        inside = ((d1 > 1e-12) & (d2 > 1e-12) & (d3 > 1e-12)) | ((d1 < -1e-12) & (d2 < -1e-12) & (d3 < -1e-12))
        assert not inside.any(), k


@pytest.mark.parametrize("cut", ["rotate", "mirror"])
def test_directed_seams_map_the_source_edge_onto_the_owners(cut):
    """Each seam edge of the cut plane is continued from both sides (the layout is rigid: no scale jump);
    each side's transform puts the source's edge corners on the owner's, its normal points away from
    the owner triangle, and its UV length is the owner's edge's."""
    from skinlab.scene.uv_seams import directed_seams

    n = 8
    m = plane_mesh(cut, n=n)
    seams = directed_seams(m, 4.0 / TEXELS)
    assert len(seams) == 2 * n
    assert {(s.owner, s.source) for s in seams} == {p for a, b in seam_edges(m)[0] for p in ((a, b), (b, a))}
    f, uv = m.indices.astype(int), m.uvs.astype(np.float64)
    for s in seams:
        centre_owner = uv[f[s.owner]].mean(0)
        assert (centre_owner - s.a0) @ s.n_hat < 0  # positive depth: away from the owner
        # the source edge's midpoint lands on the owner's edge midpoint
        np.testing.assert_allclose(s.m @ s.centre + s.c, s.a0 + 0.5 * s.length * s.t_hat, atol=1e-12)
        assert s.length == pytest.approx(UV_SCALE * 2.0 / n) and abs(np.linalg.det(s.m)) == pytest.approx(1.0)


def test_seam_transform_rotates_or_mirrors_across_the_edge():
    a0, a1, a2 = np.array([0.0, 0.0]), np.array([1.0, 0.0]), np.array([0.5, -1.0])  # A below the edge
    rot = np.array([[0.0, -2.0], [2.0, 0.0]])  # B's chart: A's frame rotated by 90 degrees, x 2
    for m_true in (rot, rot @ np.diag([1.0, -1.0])):
        inv = np.linalg.inv(m_true)
        b0, b1 = inv @ a0 + 3.0, inv @ a1 + 3.0
        b2 = inv @ np.array([0.3, 0.8]) + 3.0  # B's third corner above the edge in A's frame
        m, c = seam_transform(a0, a1, a2, b0, b1, b2)
        np.testing.assert_allclose(m @ b0 + c, a0, atol=1e-12)
        np.testing.assert_allclose(m @ b1 + c, a1, atol=1e-12)
        np.testing.assert_allclose(m @ b2 + c, [0.3, 0.8], atol=1e-12)
        np.testing.assert_allclose(m, m_true, atol=1e-12)
    assert seam_transform(a0, a0, a2, a0, a1, a2) is None  # degenerate edge
    assert seam_transform(a0, a1, np.array([0.5, 0.0]), a0, a1, a2) is None  # a sliver in UV


def test_clip_triangles_keeps_exactly_the_far_side():
    """Triangles clipped to d >= 0 (d affine): the kept area is the part of each triangle with d >= 0
    (against a dense sample of the triangle), every corner has d >= 0, attributes stay affine."""
    rng = np.random.default_rng(7)
    tri = rng.uniform(-1, 1, (200, 3, 2))
    normal, offset = np.array([0.6, 0.8]), 0.1
    d = tri @ normal - offset
    attrs = np.concatenate([tri, (tri @ np.array([2.0, -1.0]))[..., None], d[..., None]], 2)
    out = clip_triangles(attrs, d)
    assert (out[..., -1] >= -1e-12).all()
    np.testing.assert_allclose(out[..., 2], out[..., :2] @ np.array([2.0, -1.0]), atol=1e-12)  # affine attribute
    np.testing.assert_allclose(out[..., -1], out[..., :2] @ normal - offset, atol=1e-12)

    def area(t):
        e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        return 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])

    # the kept fraction of the total area, against barycentric samples of every input triangle
    s = np.linspace(0.0, 1.0, 61)
    u, v = np.meshgrid(s, s)
    ok = u + v <= 1.0
    u, v = u[ok], v[ok]
    pts = (
        tri[:, 0, None]
        + u[None, :, None] * (tri[:, 1] - tri[:, 0])[:, None]
        + v[None, :, None] * (tri[:, 2] - tri[:, 0])[:, None]
    )
    frac = ((pts @ normal - offset) >= 0).mean(1)
    assert abs(area(out[..., :2]).sum() - (area(tri) * frac).sum()) < 0.01 * area(tri).sum()
    assert len(clip_triangles(attrs[d.min(1) >= 0], d[d.min(1) >= 0])) == (d.min(1) >= 0).sum()  # kept whole
    assert len(clip_triangles(attrs[d.max(1) < 0], d[d.max(1) < 0])) == 0  # dropped


def test_seam_band_from_the_kernel():
    from types import SimpleNamespace

    from skinlab.render.techniques.tsd.seams import SEAM_BAND_MAX_TEXELS, seam_band_texels

    k = SimpleNamespace(steps=(SimpleNamespace(variance_mm2=0.25), SimpleNamespace(variance_mm2=4.0)))
    assert seam_band_texels(k, 1.0) == 8  # 3 x 2 mm / 1 mm + 2 = 8 texels
    assert seam_band_texels(k, 0.5) == 16  # 14 -> 16
    assert seam_band_texels(k, 1e-3) == SEAM_BAND_MAX_TEXELS


def test_border_bands_lie_outside_their_charts():
    """Every chart border edge (the plane's outline, and both sides of the cut) gets a strip of gutter
    `band` wide outside it: depth 0 on the edge, `band` at the far side, never over a chart."""
    from skinlab.scene.uv_seams import border_bands, border_edges

    n, band = 8, 4.0 / TEXELS
    assert len(border_edges(plane_mesh(None, n=n))[0]) == 4 * n
    m = plane_mesh("rotate", n=n)
    assert len(border_edges(m)[0]) == 6 * n
    quads, depth = border_bands(m, band)
    assert quads.shape == (12 * n, 3, 2) and set(np.unique(depth)) == {0.0, band}
    f = m.indices.astype(int)
    uv = m.uvs.astype(np.float64)[f]
    lo, hi = uv.min((0, 1)), uv.max((0, 1))
    for c in quads.mean(1):
        a, b, cc = uv[:, 0], uv[:, 1], uv[:, 2]
        w1 = (b[:, 0] - a[:, 0]) * (c[1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[0] - a[:, 0])
        w2 = (cc[:, 0] - b[:, 0]) * (c[1] - b[:, 1]) - (cc[:, 1] - b[:, 1]) * (c[0] - b[:, 0])
        w3 = (a[:, 0] - cc[:, 0]) * (c[1] - cc[:, 1]) - (a[:, 1] - cc[:, 1]) * (c[0] - cc[:, 0])
        inside = ((w1 > 0) & (w2 > 0) & (w3 > 0)) | ((w1 < 0) & (w2 < 0) & (w3 < 0))
        assert not inside.any()
    assert (quads.min((0, 1)) >= lo - band - 1e-7).all() and (quads.max((0, 1)) <= hi + band + 1e-7).all()


def _in_triangles(tri: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(P,) whether each point p (P, 2) lies in some triangle tri (T, 3, 2) (edges included)."""
    a, b, c = (tri[None, :, k] for k in range(3))
    q = p[:, None, :]

    def side(u, v):
        return (v[..., 0] - u[..., 0]) * (q[..., 1] - u[..., 1]) - (v[..., 1] - u[..., 1]) * (q[..., 0] - u[..., 0])

    d = np.stack([side(a, b), side(b, c), side(c, a)])
    return ((d >= -1e-12).all(0) | (d <= 1e-12).all(0)).any(1)


def test_border_strips_hold_every_point_near_a_chart_outside_it():
    """border_strips (the light-through record's fill, skinlab/render/techniques/tsd/passes.py) covers
    every point outside the charts within `out` of one - beside an edge and past a convex corner - and
    nothing farther than out (plus its inner margin: it reaches `inside` into the chart)."""
    from skinlab.scene.uv_seams import border_edges, border_strips

    m = plane_mesh("rotate", n=4)
    out, inside = 3.0 / TEXELS, 1.0 / TEXELS
    strips = border_strips(m, out, inside)
    assert strips.shape == (2 * len(border_edges(m)[0]), 3, 2)
    charts_uv = m.uvs.astype(np.float64)[m.indices.astype(int)]
    f = m.indices.astype(int)
    t, k = border_edges(m)
    e0, e1 = m.uvs[f[t, k]].astype(np.float64), m.uvs[f[t, (k + 1) % 3]].astype(np.float64)
    rng = np.random.default_rng(2)
    lo, hi = charts_uv.min((0, 1)) - 2 * out, charts_uv.max((0, 1)) + 2 * out
    p = rng.uniform(lo, hi, (20000, 2))
    # distance from each point to the nearest border edge (segment)
    d = e1 - e0
    s = np.clip(np.einsum("pij,ij->pi", p[:, None] - e0[None], d) / np.einsum("ij,ij->i", d, d), 0, 1)
    dist = np.linalg.norm(p[:, None] - (e0[None] + s[..., None] * d[None]), axis=2).min(1)
    outside = ~_in_triangles(charts_uv, p)
    held = _in_triangles(strips, p)
    near = outside & (dist < out * 0.999)
    assert near.sum() > 500 and held[near].all()
    assert not held[outside & (dist > out * 1.001 * np.sqrt(2))].any()  # (a corner's square reaches sqrt 2 out)
    assert not held[~outside & (dist > inside * 1.001 * np.sqrt(2))].any()
