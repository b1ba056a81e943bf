import numpy as np
import pytest

from skinlab.scene.mesh import Mesh
from skinlab.scene.scenefile import DEFAULT_SCENE, load_scene
from skinlab.scene.uv_checks import analyse_uvs

QUAD_UV = [[0, 0], [1, 0], [1, 1], [0, 1]]
QUAD_IDX = [[0, 1, 2], [0, 2, 3]]


def quad(sx=10.0, sy=10.0, name="quad"):
    pos = [[0, 0, 0], [sx, 0, 0], [sx, sy, 0], [0, sy, 0]]
    return Mesh(name, np.array(pos, float), np.array(QUAD_IDX), uvs=np.array(QUAD_UV, float))


def test_unit_quad_is_clean():
    r = analyse_uvs(quad(), mm_per_unit=2.0, texels=100, grid=64)
    assert r.has_uvs and r.triangles == 2
    assert r.mm_per_texel.shape == (2, 2)
    assert np.allclose(r.mm_per_texel, 0.2, rtol=1e-12, atol=0)  # 10 units * 2 mm / 100 texels
    for key in ("p10", "p50", "p90"):
        assert r.mm_per_texel_percentiles[key] == pytest.approx((0.2, 0.2), rel=1e-12)
    # texel centres lie exactly on the diagonal: the half-open rule gives each to one triangle
    assert r.uv_coverage == 1.0 and r.overlap_fraction == 0.0
    assert (r.zero_area_world, r.zero_area_uv, r.out_of_range) == (0, 0, 0)
    assert r.warnings() == []


@pytest.mark.parametrize("grid", [7, 8, 51])
def test_fan_through_texel_centres_covers_each_texel_once(grid):
    # four triangles around the centre (a texel centre when grid is odd), diagonals through centres
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0]], float)
    uv = pos[:, :2].copy()
    idx = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    r = analyse_uvs(Mesh("fan", pos, idx, uvs=uv), mm_per_unit=1.0, grid=grid)
    assert r.uv_coverage == 1.0 and r.overlap_fraction == 0.0


def test_anisotropic_quad_stretches_u_only():
    r = analyse_uvs(quad(sx=20.0), mm_per_unit=2.0, texels=100)
    assert np.allclose(r.mm_per_texel[:, 0], 0.4, rtol=1e-12, atol=0)
    assert np.allclose(r.mm_per_texel[:, 1], 0.2, rtol=1e-12, atol=0)
    assert r.mm_per_texel_percentiles["p50"] == pytest.approx((0.4, 0.2), rel=1e-12)
    # model_scale multiplies like mm_per_unit
    r2 = analyse_uvs(quad(sx=20.0), mm_per_unit=1.0, texels=100, model_scale=2.0)
    assert np.allclose(r2.mm_per_texel, r.mm_per_texel, rtol=1e-12, atol=0)


def test_percentiles_are_area_weighted():
    # left half of the UV square: a 10x20 patch; right half: a 1x2 patch (1% of the area)
    pos = np.array(
        [[0, 0, 0], [10, 0, 0], [10, 20, 0], [0, 20, 0], [50, 0, 0], [51, 0, 0], [51, 2, 0], [50, 2, 0]], float
    )
    uv = np.array([[0, 0], [0.5, 0], [0.5, 1], [0, 1], [0.5, 0], [1, 0], [1, 1], [0.5, 1]], float)
    idx = np.array(QUAD_IDX + [[4, 5, 6], [4, 6, 7]])
    r = analyse_uvs(Mesh("two", pos, idx, uvs=uv), mm_per_unit=1.0, texels=10)
    assert np.allclose(r.mm_per_texel[:2], 2.0) and np.allclose(r.mm_per_texel[2:], 0.2)
    for key in ("p10", "p50", "p90"):  # unweighted, p10 would be the small patch's 0.2
        assert r.mm_per_texel_percentiles[key] == pytest.approx((2.0, 2.0))
    assert r.uv_coverage == 1.0 and r.overlap_fraction == 0.0


def test_overlapping_triangles_are_reported():
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], float)
    uv = np.array([[0, 0], [1, 0], [0, 1]] * 2, float)
    r = analyse_uvs(Mesh("twice", pos, np.array([[0, 1, 2], [3, 4, 5]]), uvs=uv), mm_per_unit=1.0)
    assert r.overlap_fraction == pytest.approx(1.0)
    assert r.uv_coverage == pytest.approx(0.5, abs=0.01)
    (w,) = r.warnings()
    assert "'twice'" in w and "overlap" in w.lower()


def test_mirrored_copy_overlaps_too():
    # the same UV triangle with opposite winding (a mirrored island laid on top) still overlaps
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], float)
    uv = np.array([[0, 0], [1, 0], [0, 1]] * 2, float)
    r = analyse_uvs(Mesh("mirror", pos, np.array([[0, 1, 2], [3, 5, 4]]), uvs=uv), mm_per_unit=1.0)
    assert r.overlap_fraction == pytest.approx(1.0)


def test_zero_world_area_triangle():
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [3, 0, 0], [4, 0, 0]], float)
    uv = np.array([[0, 0], [0.5, 0], [0.5, 1], [0, 1], [0.5, 0], [1, 0], [1, 1]], float)
    idx = np.array(QUAD_IDX + [[4, 5, 6]])  # collinear positions, non-zero UV area
    r = analyse_uvs(Mesh("sliver", pos, idx, uvs=uv), mm_per_unit=10.0)
    assert r.zero_area_world == 1 and r.zero_area_uv == 0
    assert np.all(r.mm_per_texel[2] == 0.0)
    assert np.isfinite(r.mm_per_texel).all()
    assert all(np.isfinite(v).all() for v in r.mm_per_texel_percentiles.values())
    (w,) = r.warnings()
    assert "'sliver'" in w and "1 of 3" in w and "zero world area" in w


def test_zero_uv_area_and_out_of_range_triangles():
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [3, 0, 0], [2, 1, 0]], float)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.2, 0.2], [0.4, 0.4], [0.6, 0.6]], float)
    idx = np.array(QUAD_IDX + [[4, 5, 6]])  # collinear UVs, non-zero world area
    r = analyse_uvs(Mesh("flat", pos, idx, uvs=uv), mm_per_unit=1.0)
    assert r.zero_area_uv == 1 and r.zero_area_world == 0 and r.out_of_range == 0
    assert np.isnan(r.mm_per_texel[2]).all() and np.isfinite(r.mm_per_texel[:2]).all()
    assert r.uv_coverage == 1.0 and r.overlap_fraction == 0.0
    (w,) = r.warnings()
    assert "'flat'" in w and "zero UV area" in w and "no irradiance" in w

    # the same sliver on a surface 1e5 times larger is a note (no warning on every render)
    big = pos.copy()
    big[:4] *= 1000.0
    r3 = analyse_uvs(Mesh("big", big, idx, uvs=uv), mm_per_unit=1.0)
    assert r3.zero_area_uv == 1 and r3.zero_area_uv_surface < 1e-4 and r3.warnings() == []
    (note,) = r3.notes()
    assert "1 of 3 triangles" in note and "no irradiance" in note
    assert r.notes() == [] and r.zero_area_uv_surface == pytest.approx(0.5 / 1.5)

    uv2 = uv.copy()
    uv2[4:] = [[1.5, 0.5], [2.0, 0.5], [1.5, 1.0]]  # a proper triangle entirely outside the square
    r2 = analyse_uvs(Mesh("outside", pos, idx, uvs=uv2), mm_per_unit=1.0)
    assert r2.out_of_range == 1 and r2.zero_area_uv == 0
    assert r2.uv_coverage == 1.0 and r2.overlap_fraction == 0.0  # clipped away, not wrapped
    assert any("outside [0, 1]" in w for w in r2.warnings())


def test_missing_uvs():
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    r = analyse_uvs(Mesh("bare", pos, np.array(QUAD_IDX)), mm_per_unit=1.0)
    assert not r.has_uvs and r.triangles == 2 and r.zero_area_world == 0
    assert r.mm_per_texel.shape == (2, 2) and np.isnan(r.mm_per_texel).all()
    (w,) = r.warnings()
    assert "'bare'" in w and "texture-space diffusion" in w and "ensure_uvs" in w


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="mm_per_unit"):
        analyse_uvs(quad(), mm_per_unit=0.0)
    with pytest.raises(ValueError, match="grid"):
        analyse_uvs(quad(), mm_per_unit=1.0, grid=0)


def test_head_uv_layout():
    scene = load_scene(DEFAULT_SCENE)
    (node,) = scene.mesh_nodes()
    r = analyse_uvs(node.mesh, scene.mm_per_unit, texels=1024, grid=512)
    assert r.has_uvs and r.triangles == len(node.mesh.indices) > 10000
    assert r.overlap_fraction < 0.002  # measured 1.9e-4: stray texels along a few seams
    assert 0.85 < r.uv_coverage < 0.98  # measured 0.916
    assert r.out_of_range == 0 and r.zero_area_world == 0
    pct = r.mm_per_texel_percentiles
    assert all(np.isfinite(pct[k]).all() for k in ("p10", "p50", "p90"))
    for c in range(2):
        assert 0.1 < pct["p10"][c] <= pct["p50"][c] <= pct["p90"][c] < 5.0  # p50 ~ 0.7 mm per texel
    # the eye corners hold a dozen triangles collapsed in UV; they are all that is warned about
    assert 0 < r.zero_area_uv < 50
    assert [w for w in r.warnings() if "zero UV area" not in w] == []
