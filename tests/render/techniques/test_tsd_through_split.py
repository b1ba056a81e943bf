"""The orbiting frame's forward-pass cuts give the same images (issue 27): the mesh drawn in two parts,
the triangles that can read light through thin parts from the irradiance pass's record with its exit
factor and the others without it (skinlab/render/techniques/tsd/through_split.py, NodeShading.parts);
the near-light factors compiled out where no point or spot light is lit (NEAR_LIGHTS); the boundary's
non-separable rest compiled in only for a material that has one (SSS_MS_REST)."""

from __future__ import annotations

import numpy as np
import pytest

import skinlab.render.passes.forward as forward
from skinlab.render.boundary import boundary_defines
from skinlab.render.lights import near_defines
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import passes as tsd_passes
from skinlab.render.techniques.tsd.passes import frame_nodes
from skinlab.render.techniques.tsd.through_split import (
    BLOCK_TEXELS,
    MARGIN_TEXELS,
    lit_texels,
    slot_masks,
    split_indices,
    through_triangles,
)
from skinlab.resources import assets_root
from skinlab.scene.scenefile import load_scene

REFERENCE = assets_root() / "scenes" / "reference"
FWD = "passes/forward.frag"


def _reads_brute(uvs, tri, lit, samples=64, seed=0):
    """Whether points inside triangle `tri` (vertices and random barycentric points) read a lit texel
    (nearest, clamp to edge: the texel floor(uv x size), clamped)."""
    rng = np.random.default_rng(seed)
    b = rng.dirichlet(np.ones(3), samples)
    pts = np.concatenate([uvs[tri], b @ uvs[tri]])
    n = lit.shape[0]
    ij = np.clip(np.floor(pts * n).astype(int), 0, n - 1)
    return bool(lit[ij[:, 1], ij[:, 0]].any())


def test_the_triangles_that_can_read_a_lit_texel_are_marked():
    n = 64
    lit = np.zeros((n, n), bool)
    lit[10, 40] = True  # row 10 (v), column 40 (u)
    c = (np.array([40.5, 10.5]) / n).astype(np.float32)  # that texel's centre
    far = c + 20.0 / n
    edge = c + (BLOCK_TEXELS + MARGIN_TEXELS + 1.0) / n  # past the block and the margin
    d = 0.2 / n
    uvs = np.array([c, c + [d, 0], c + [0, d], far, far + [d, 0], far + [0, d], edge, edge + [d, 0], edge + [0, d]])
    uvs = np.concatenate([uvs, [[np.nan, 0.5], [0.5, 0.5], [0.6, 0.5]], [[-0.5, -0.5], [-0.4, -0.5], [-0.5, -0.4]]])
    idx = np.arange(len(uvs), dtype=np.uint32).reshape(-1, 3)
    marked = through_triangles(uvs.astype(np.float32), idx, lit)
    assert marked.tolist() == [True, False, False, True, False]  # on it; far; past the margin; a NaN uv; off the map
    lit[0, 0] = True  # off the map is read at the edge texel (clamp to edge)
    assert through_triangles(uvs.astype(np.float32), idx, lit)[4]


def test_marking_is_conservative_against_sampled_reads():
    rng = np.random.default_rng(3)
    n = 96
    lit = rng.random((n, n)) < 0.004
    uvs = rng.random((600, 2)).astype(np.float32) * 1.1 - 0.05  # some off the map
    idx = rng.integers(0, len(uvs), (400, 3)).astype(np.uint32)
    # small triangles: a vertex and one near it (and the first again: degenerate, a line)
    small = np.concatenate([uvs[idx[:, 0]], uvs[idx[:, 0]] + rng.normal(0, 2.0 / n, (400, 2))]).astype(np.float32)
    small_idx = np.stack([np.arange(400), 400 + np.arange(400), np.arange(400)], 1).astype(np.uint32)
    for u, ix, some in ((uvs, idx, False), (small, small_idx, True)):
        marked = through_triangles(u, ix, lit)
        brute = np.array([_reads_brute(u, t, lit, seed=k) for k, t in enumerate(ix)])
        assert (marked | ~brute).all()  # every triangle seen reading light is marked
        assert brute.any()
        if some:  # the small ones: not simply all of them
            assert 0 < marked.sum() < len(marked) // 2
    assert not through_triangles(uvs, idx, np.zeros((n, n), bool)).any()


def test_split_indices_groups_every_triangle_once_by_its_slots():
    n = 32
    lits = [np.zeros((n, n), bool), np.zeros((n, n), bool)]
    lits[0][:, : n // 4] = True  # slot 0 lights the left quarter, slot 1 the right one
    lits[1][:, -n // 4 :] = True
    centres = np.array([[0.1, 0.5], [0.9, 0.5], [0.5, 0.5], [0.1, 0.2], [0.5, 0.9]], np.float32)
    uvs = np.concatenate([centres, centres + [0.01, 0], centres + [0, 0.01]]).astype(np.float32)
    uvs = np.concatenate([uvs, [[0.05, 0.5], [0.95, 0.5], [0.5, 0.52]]]).astype(np.float32)  # one across both
    idx = np.concatenate([np.stack([np.arange(5), 5 + np.arange(5), 10 + np.arange(5)], 1), [[15, 16, 17]]])
    mask = slot_masks(uvs, idx.astype(np.uint32), lits)
    assert mask.tolist() == [1, 2, 0, 1, 0, 3]
    flat, groups = split_indices(idx, mask)
    assert groups == [(0, 0, 6), (1, 6, 6), (2, 12, 3), (3, 15, 3)]
    for m, first, count in groups:
        assert flat[first : first + count].reshape(-1, 3).tolist() == idx[mask == m].tolist()


def test_lit_texels_tests_the_bits():
    rec = np.zeros((2, 2, 4), np.float32)
    rec[0, 0, 3] = 50.0  # a thickness without light: not lit
    rec[0, 1, 1] = -0.0
    rec[1, 0, 2] = np.float32(1e-45)  # the smallest subnormal
    rec[1, 1, 0] = np.nan
    assert lit_texels(rec.tobytes(), 2).tolist() == [[False, True], [True, True]]


@pytest.fixture(scope="module")
def head():
    return load_scene("head")


def _forward_variants(renderer) -> list:
    """The forward programs' TSD_THROUGH_READ (None: every slot's record read)."""
    return [dict(d).get("TSD_THROUGH_READ") for (_, fs, d, _) in renderer.programs.entries if fs == FWD]


@pytest.mark.parametrize("scene_name", ["head", "bunny-skimmilk"])
def test_the_mesh_drawn_in_groups_is_the_same_image(ctx, scene_name, monkeypatch):
    """The head (one shadow slot: those that read its light through and the others) and the skim-milk
    bunny (two slots: every combination), against the mesh drawn whole with every slot's exit factor."""
    scene = load_scene(scene_name)
    st = RenderSettings.for_technique("tsd", 64, 64, shadow_size=512, size=128)
    r = Renderer(ctx)
    r.reuse = True
    try:
        split = r.render(scene, st).hdr
        t = next(iter(frame_nodes(r.last_frame).values()))
        ibo, groups = t.targets.through_faces
        total = scene.mesh_nodes()[0].mesh.indices.size
        assert sum(c for _, _, c in groups) == total and len(groups) > 1
        every = (1 << t.through_slots) - 1
        assert t.through_slots == (2 if "bunny" in scene_name else 1)
        assert {m for m, _, _ in groups} <= set(range(every + 1))
        assert sorted(_forward_variants(r), key=str) == sorted(
            [None if m == every else str(m) for m, _, _ in groups], key=str
        )
        res = r.render(scene, st)  # orbiting: the irradiance pass reused, its groups kept
        assert next(p for p in res.plan.passes if p.kind == "tsd_irradiance").reused_since is not None
        orbit = res.hdr
        # every triangle drawn as reading no slot's light through: another image (a wrong split shows)
        t.targets.through_faces = (ibo, [(0, 0, total)])
        none = r.render(scene, st).hdr
        monkeypatch.setattr(tsd_passes, "MIN_SPLIT_SHARE", 2.0)  # never grouped: the whole mesh, every slot
        whole = Renderer(ctx)
        full = whole.render(scene, st).hdr
        assert not next(iter(frame_nodes(whole.last_frame).values())).targets.through_faces
        assert _forward_variants(whole) == [None]
        whole.release()
    finally:
        r.release()
    assert np.isfinite(split).all() and (split[..., 3] > 0).sum() > 500
    np.testing.assert_array_equal(split, full)
    np.testing.assert_array_equal(orbit, full)
    assert np.abs(none - full).max() > 1e-4 * np.abs(full).max()


def test_near_defines_name_the_lights_at_a_finite_distance():
    class L:
        def __init__(self, kind):
            self.kind = kind

    assert near_defines([L("directional"), L("rect"), L("sphere")]) == {"NEAR_LIGHTS": 0}
    assert near_defines([L("directional"), L("point")]) == {"NEAR_LIGHTS": 1}
    assert near_defines([L("spot")]) == {"NEAR_LIGHTS": 1}
    assert near_defines([]) == {"NEAR_LIGHTS": 0}


def _both(ctx, scene, st, monkeypatch, target, name, value):
    """The frame as shipped and with `name` in `target` replaced by `value`."""
    a = Renderer(ctx)
    try:
        first = a.render(scene, st).hdr
    finally:
        a.release()
    monkeypatch.setattr(target, name, value)
    b = Renderer(ctx)
    try:
        second = b.render(scene, st).hdr
    finally:
        b.release()
    monkeypatch.undo()
    return first, second


def test_near_light_code_compiled_out_changes_nothing_and_is_needed_under_a_point_light(ctx, head, monkeypatch):
    st = RenderSettings.for_technique("tsd", 48, 48, shadow_size=512, size=128)
    shipped, near_on = _both(ctx, head, st, monkeypatch, forward, "near_defines", lambda lights: {"NEAR_LIGHTS": 1})
    np.testing.assert_array_equal(shipped, near_on)  # the head's two suns: compiled out, the same frame
    point = load_scene(REFERENCE / "point-light-skin1.toml")
    st = RenderSettings(32, 32)
    shipped, near_off = _both(ctx, point, st, monkeypatch, forward, "near_defines", lambda lights: {"NEAR_LIGHTS": 0})
    assert np.isfinite(shipped).all()
    assert np.abs(shipped - near_off).max() > 1e-4 * np.abs(shipped).max()  # the point light needs it


def test_the_boundary_rest_is_compiled_in_only_where_a_material_has_one(ctx, monkeypatch):
    skin = load_scene(REFERENCE / "head-skin1.toml")
    matched = load_scene(REFERENCE / "head-skin1-matched.toml")
    assert boundary_defines(skin.mesh_nodes()[0].material) == {}  # eta > 1: the rest is zero
    assert boundary_defines(matched.mesh_nodes()[0].material) == {"SSS_MS_REST": 1}
    assert boundary_defines(None) == {}
    st = RenderSettings.for_technique("tsd", 32, 32, shadow_size=512, size=128)
    shipped, rest_on = _both(ctx, skin, st, monkeypatch, forward, "boundary_defines", lambda m: {"SSS_MS_REST": 1})
    np.testing.assert_array_equal(shipped, rest_on)
    shipped, rest_off = _both(ctx, matched, st, monkeypatch, forward, "boundary_defines", lambda m: {})
    assert np.abs(shipped - rest_off).max() > 1e-5 * np.abs(shipped).max()  # the matched skin's rest is in its frame
