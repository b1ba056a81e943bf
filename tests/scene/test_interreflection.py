"""Interreflection's NumPy reference (skinlab/scene/interreflection.py): ray directions, records and gather
against analytic form factors and a furnace."""

import numpy as np
import pytest
import trimesh

from skinlab.scene.graph import MeshNode
from skinlab.scene.interreflection import (
    bounce_irradiance,
    build_transfer,
    clear_cache,
    cosine_directions,
    gather,
    one_rings,
    open_toward,
    ring_power,
    sender_albedo,
    sky_visible_share,
    smooth,
    smoothing_rings,
    weld,
    world_geometry,
)
from skinlab.scene.materials import Material
from skinlab.scene.mesh import Mesh
from skinlab.scene.primitives import box_mesh

# Form factor between two unit squares sharing an edge at a right angle (Howell, "A Catalog of
# Radiation Heat Transfer Configuration Factors", C-14; Hottel's value 0.20004)
PERPENDICULAR_SQUARES = 0.2000438


def grid_mesh(n, origin, du, dv, name="grid") -> Mesh:
    """An n x n grid of quads spanning origin + [0, 1] du + [0, 1] dv, normal du x dv."""
    u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    p = np.asarray(origin, float) + u[..., None] * np.asarray(du, float) + v[..., None] * np.asarray(dv, float)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    nrm = np.cross(du, dv) / np.linalg.norm(np.cross(du, dv))
    return Mesh(name, p.reshape(-1, 3), faces, np.tile(nrm, ((n + 1) ** 2, 1)), np.stack([u, v], -1).reshape(-1, 2))


def open_book(n=24):
    """Plate A in z = 0 (normal +z) and plate B in x = 0 (normal +x), sharing the edge along y."""
    a = MeshNode("A", grid_mesh(n, (0, 0, 0), (1, 0, 0), (0, 1, 0), "A"), Material())
    b = MeshNode("B", grid_mesh(n, (0, 0, 0), (0, 1, 0), (0, 0, 1), "B"), Material())
    return a, b


def area_mean(values, n):
    """Mean over a grid's area of per-vertex values (trapezoid weights)."""
    w = np.ones(n + 1)
    w[0] = w[-1] = 0.5
    ww = np.outer(w, w).reshape(-1)
    return float((values * ww).sum() / ww.sum())


@pytest.mark.parametrize("rays", [16, 64])
def test_perpendicular_plates_receive_their_form_factor(rays):
    """Plate A leaving exitance 1, plate B receives on average F_BA x 1 = 0.20004 (reciprocity, equal
    areas): the gather is the one-bounce estimator of the rendering equation."""
    n = 24
    a, b = open_book(n)
    tr = build_transfer([a, b], rays)
    m = np.zeros((tr.total_vertices, 1))
    m[tr.offsets[a.uid] : tr.offsets[a.uid] + tr.counts[a.uid]] = 1.0
    e = gather(tr, m)
    on_b = e[tr.offsets[b.uid] :, 0]
    assert area_mean(on_b, n) == pytest.approx(PERPENDICULAR_SQUARES, abs=0.006)
    # A sees only B, which sends nothing; B's light falls off away from the shared edge
    assert np.all(e[: tr.counts[a.uid]] == 0.0)
    rows = on_b.reshape(n + 1, n + 1).mean(0)  # by height above A
    assert rows[0] > 0.4 and rows[-1] < 0.15
    # every ray of A's vertices that meets B is counted in A's hit fraction, and the fraction is the form factor
    assert tr.hit_fraction[a.uid] == pytest.approx(PERPENDICULAR_SQUARES, abs=0.02)


def test_sky_share_holds_a_sharp_occluder():
    """The share of a map's light a vertex's rays see, per channel, from three one-sided skies: B's
    middle (0, 0.5, 0.5) sees all the light from above (nothing is there), none from a cone that only
    plate A fills, and of the light from below what misses A, as a dense independent count of the
    geometry gives it (no ray record). Nine SH coefficients of the blocked rays cannot hold such a
    step. A uniform sky's share is the rays' share (the fourth column); scaling the sky changes nothing."""
    n = 24
    a, b = open_book(n)
    tr = build_transfer([a, b], 64)

    def sky(d):
        below = d[..., 2] < 0.0
        cone = (d[..., 2] < -0.6) & (np.abs(d[..., 1]) < 0.3)  # from B's middle and its ring these all meet A
        return np.stack([below, ~below, cone], -1).astype(np.float64)

    share = sky_visible_share(tr, sky(tr.sky_directions))
    mid = share[tr.offsets[b.uid] + (n // 2) * (n + 1) + n // 2]
    d = cosine_directions(np.array([[1.0, 0.0, 0.0]]), 400_000, seed=3)[0]
    down = d[:, 2] < 0.0
    t = 0.5 / np.maximum(-d[:, 2], 1e-12)
    y = 0.5 + t * d[:, 1]
    hits_a = down & (t * d[:, 0] <= 1.0) & (y >= 0.0) & (y <= 1.0)
    want_below = 1.0 - hits_a.sum() / down.sum()
    assert 0.2 < want_below < 0.8  # a real test: A hides part of the light from below
    assert mid[0] == pytest.approx(want_below, abs=0.05)
    assert mid[1] == pytest.approx(1.0, abs=1e-6)
    assert mid[2] == 0.0
    # uniform light: the share is the rays' share, per channel alike; a brighter sky the same share
    flat = sky_visible_share(tr, np.ones(tr.sky_directions.shape))
    assert np.allclose(flat[:, :3], flat[:, 3:4], atol=1e-6)
    assert np.allclose(sky_visible_share(tr, 5.0 * sky(tr.sky_directions)), share, atol=1e-6)
    # A's vertices see B above them only toward -x
    on_a = share[tr.offsets[a.uid] : tr.offsets[a.uid] + tr.counts[a.uid]]
    assert np.all((on_a >= 0.0) & (on_a <= 1.0)) and on_a[:, 3].max() < 1.0


def test_rays_toward_a_source_meet_what_is_in_the_way():
    """One ray per vertex and direction: from B's middle, toward A (down at 60 degrees) it is blocked,
    along B's normal and straight up it leaves, behind B (through B itself) it is blocked; A's vertices
    see B toward -x and up where it is in the way; a convex box sees every direction it faces."""
    n = 24
    a, b = open_book(n)
    tr = build_transfer([a, b], 16)
    toward = np.array([[0.5, 0.0, -np.sqrt(0.75)], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-0.6, 0.0, 0.8]])
    seen = open_toward([a, b], tr.key, toward)
    assert seen.shape == (tr.total_vertices, 4)
    mid = tr.offsets[b.uid] + (n // 2) * (n + 1) + n // 2
    assert seen[mid].tolist() == [False, True, True, False]
    on_a = seen[tr.offsets[a.uid] : tr.offsets[a.uid] + tr.counts[a.uid]]
    assert on_a[:, 2].all() and not on_a[:, 3].all() and on_a[:, 3].any()
    box = MeshNode("box", box_mesh((1.0, 2.0, 3.0)), Material())
    facing = world_geometry(box)[1] @ toward.T > 1e-6  # what a vertex receives a source from
    seen = open_toward([box], build_transfer([box], 4).key, toward)
    assert seen[facing].all() and facing.any()


def test_sky_share_of_a_convex_mesh_is_whole():
    node = MeshNode("box", box_mesh((1.0, 2.0, 3.0)), Material())
    tr = build_transfer([node], 16)
    assert not tr.any_blocked
    d = tr.sky_directions
    lit = sky_visible_share(tr, np.stack([d[..., 0] > 0.5, d[..., 1] ** 2, np.ones(d.shape[:-1])], -1))
    assert np.all(lit == 1.0)


def test_cosine_directions_are_unit_in_the_hemisphere_and_cosine_weighted():
    rng = np.random.default_rng(3)
    nrm = rng.normal(size=(200, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm[0] = (0, 0, -1)  # the frame's singular direction
    nrm[1] = (0, 0, 1)
    d = cosine_directions(nrm, 64, seed=1)
    assert np.allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-9)
    cos = np.einsum("vkc,vc->vk", d, nrm)
    assert cos.min() >= 0.0
    # cosine-weighted: E[cos] = 2/3 and E[cos^2] = 1/2 (stratified, so close per vertex)
    assert np.abs(cos.mean(1) - 2 / 3).max() < 0.02
    assert np.abs((cos**2).mean(1) - 0.5).max() < 0.03


def test_convex_mesh_sees_nothing_of_itself():
    node = MeshNode("box", box_mesh((1.0, 2.0, 3.0)), Material())
    tr = build_transfer([node], 32)
    assert not tr.any_hit
    assert tr.hit_fraction[node.uid] == 0.0
    assert np.all(gather(tr, np.ones((tr.total_vertices, 3))) == 0.0)


def closed_sphere_inside() -> MeshNode:
    """An icosphere with its normals (and windings) turned inward: every ray meets its front."""
    ico = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    faces = ico.faces[:, ::-1].copy()
    return MeshNode("inside", Mesh("inside", ico.vertices, faces, -ico.vertex_normals), Material())


@pytest.mark.parametrize("albedo", [0.0, 0.5, 1.0])
def test_furnace_inside_a_closed_sphere(albedo):
    """Inside a closed sphere every ray meets the wall: a uniform exitance M comes back as
    irradiance M everywhere, and N orders of bounce light from a uniform direct irradiance E0 sum to
    E0 (a + a^2 + ... + a^N), finite at albedo 0 and 1."""
    node = closed_sphere_inside()
    tr = build_transfer([node], 16)
    assert tr.hit_fraction[node.uid] == pytest.approx(1.0)
    v = tr.total_vertices
    assert np.allclose(gather(tr, np.full((v, 3), 2.5)), 2.5, rtol=1e-5)
    e0 = np.ones((v, 1))
    for bounces in (1, 3):
        got = bounce_irradiance(tr, e0, np.full((v, 1), albedo), bounces)
        want = sum(albedo**k for k in range(1, bounces + 1))
        assert np.all(np.isfinite(got))
        assert np.allclose(got, want, rtol=1e-5, atol=1e-12)


def test_back_faces_and_vertices_without_normals_send_and_receive_nothing():
    """A ray that meets the back of a surface (the inside of an open mesh) records nothing; a vertex
    no triangle uses (zero normal) casts no rays."""
    a, b = open_book(8)
    gap = np.array([-0.01, 0.0, 0.0])  # A's edge vertices must not lie on B's plane (a degenerate ray start)
    flipped = Mesh("B-back", b.mesh.positions + gap, b.mesh.indices[:, ::-1].copy(), -b.mesh.normals, b.mesh.uvs)
    back = MeshNode("B-back", flipped, Material())
    tr = build_transfer([a, back], 32)
    assert tr.hit_fraction[a.uid] == 0.0  # A's rays meet B's back
    pos = np.vstack([a.mesh.positions, [[0.5, 0.5, 0.5]]])
    nrm = np.vstack([a.mesh.normals, [[0.0, 0.0, 0.0]]])
    lone = MeshNode("lone", Mesh("lone", pos, a.mesh.indices, nrm), Material())
    tr = build_transfer([lone, b], 16)
    last = tr.offsets[lone.uid] + tr.counts[lone.uid] - 1
    assert np.all(tr.weights[last * 16 : (last + 1) * 16] == 0.0)
    assert np.all(np.isfinite(gather(tr, np.ones((tr.total_vertices, 3)))))


def test_transfer_is_cached_by_geometry_not_by_node():
    clear_cache()
    a, b = open_book(6)
    first = build_transfer([a, b], 8)
    a2, b2 = open_book(6)  # new nodes, the same geometry
    second = build_transfer([a2, b2], 8)
    assert second.vertices is first.vertices
    assert set(second.offsets) == {a2.uid, b2.uid}
    b2.translation = (0.0, 0.0, 0.5)  # moved: new records
    third = build_transfer([a2, b2], 8)
    assert third.key != first.key and third.vertices is not first.vertices


def test_bad_input_names_what_was_expected():
    a, b = open_book(2)
    with pytest.raises(ValueError, match="rays per vertex"):
        build_transfer([a, b], 0)
    tr = build_transfer([a, b], 4)
    with pytest.raises(ValueError, match="exitance has 3 vertices"):
        gather(tr, np.ones((3, 3)))


def test_sender_albedo():
    """Diffuse albedo plus principled F0 (0.08 x specular for a dielectric, the base colour for a metal)."""
    base = np.array([0.5, 0.2, 0.1])
    assert np.allclose(sender_albedo(base, 0.0, 0.5), base + 0.04)
    assert np.allclose(sender_albedo(base, 1.0, 0.5), base)
    assert np.allclose(sender_albedo(base, 0.0, 0.0), base)


def test_copies_along_a_seam_share_their_rays_and_rings():
    """A plate cut along x = 0.5 into two charts (the vertices on the cut duplicated, as a UV seam
    does): the copies get the same records and the same one-ring, so bounce light is continuous."""
    n = 8
    a, b = open_book(n)
    m = a.mesh
    cut = np.where(np.isclose(m.positions[:, 0], 0.5))[0]
    copies = np.arange(len(m.positions), len(m.positions) + len(cut))
    remap = np.arange(len(m.positions))
    remap[cut] = copies
    faces = m.indices.astype(np.int64).copy()
    right = m.positions[faces].mean(1)[:, 0] > 0.5
    faces[right] = remap[faces[right]]  # the right chart uses the copies
    pos = np.vstack([m.positions, m.positions[cut]])
    split = MeshNode("A-cut", Mesh("A-cut", pos, faces, np.vstack([m.normals, m.normals[cut]])), Material())
    first, inverse = weld(split.mesh.positions, split.mesh.normals)
    assert len(first) == len(m.positions) and np.all(inverse[cut] == inverse[copies])
    tr = build_transfer([split, b], 16)
    k = tr.rays
    for c, d in zip(cut, copies):
        assert np.array_equal(tr.vertices[c * k : (c + 1) * k], tr.vertices[d * k : (d + 1) * k])
    rng = np.random.default_rng(0)
    e = smooth(tr, rng.random((tr.total_vertices, 3)))
    assert np.allclose(e[cut], e[copies])


def test_one_ring_average_keeps_constants_and_sums_to_one():
    a, b = open_book(6)
    tr = build_transfer([a, b], 64)
    sums = np.add.reduceat(tr.ring_weights.astype(np.float64), tr.ring_offsets[:-1])
    assert np.allclose(sums, 1.0, atol=1e-6)
    assert np.allclose(smooth(tr, np.full((tr.total_vertices, 2), 3.0)), 3.0)
    # an interior grid vertex averages itself and its 6 neighbours; a corner fewer
    counts = np.diff(tr.ring_offsets)
    assert counts.max() == 7 and counts.min() >= 3


def test_one_rings_match_a_vertex_by_vertex_construction():
    """one_rings (CSR over integer edge keys) against the definition written out vertex by vertex: each
    vertex's ring is itself and its edge neighbours on the welded mesh (as their first copies, in
    ascending order), weighted by a third of their incident triangles' areas, summing to 1; a welded
    vertex no triangle uses has itself alone at weight 1; copies of a vertex have the same ring."""
    rng = np.random.default_rng(3)
    positions = rng.random((12, 3))
    positions[10] = positions[2]  # a copy of vertex 2 (a seam): welded with it
    normals = np.tile([0.0, 0.0, 1.0], (12, 1))
    faces = np.array([[0, 1, 2], [1, 3, 2], [3, 4, 10], [4, 5, 6], [6, 7, 8], [0, 8, 7], [1, 9, 3]])  # 11 unused
    first, inverse = weld(positions, normals)
    offsets, ring_vertices, ring_weights = one_rings(positions, faces, first, inverse)
    nw = len(first)
    wf = inverse[faces]
    area = np.zeros(nw)
    for tri, (i, j, k) in zip(wf, faces):
        a = 0.5 * np.linalg.norm(np.cross(positions[j] - positions[i], positions[k] - positions[i]))
        area[tri] += a / 3.0
    for v in range(len(positions)):
        w = inverse[v]
        ring = {w} | {int(x) for tri in wf if w in tri for x in tri}
        ring = sorted(ring)
        weights = area[ring] / area[ring].sum() if area[ring].sum() > 0 else np.array([1.0])
        got = slice(offsets[v], offsets[v + 1])
        np.testing.assert_array_equal(ring_vertices[got], first[ring])
        np.testing.assert_allclose(ring_weights[got], weights, rtol=1e-6)
    assert offsets[11 + 1] - offsets[11] == 1 and ring_weights[offsets[11]] == 1.0  # the unused vertex
    np.testing.assert_array_equal(
        ring_vertices[offsets[2] : offsets[3]], ring_vertices[offsets[10] : offsets[11]]
    )  # copies share the ring


def test_sender_rows_sum_to_the_gather_with_fewer_terms():
    """The records collapsed per receiver (what the GPU sums) give gather's irradiance, each sender
    once per receiver and no empty ray; a ray that met nothing adds no entry."""
    tr = build_transfer(open_book(), rays=32)
    offsets, senders, weights = tr.sender_offsets, tr.sender_vertices, tr.sender_weights
    assert offsets.shape == (tr.total_vertices + 1,) and offsets[-1] == len(senders) == len(weights)
    assert 0 < len(senders) < np.count_nonzero(tr.weights)  # collapsed: fewer entries than live corners
    assert (weights > 0).all()
    for i in range(tr.total_vertices):  # distinct, increasing senders per receiver
        assert np.all(np.diff(senders[offsets[i] : offsets[i + 1]]) > 0)
    m = np.random.default_rng(3).uniform(0.0, 2.0, (tr.total_vertices, 3))
    owner = np.repeat(np.arange(tr.total_vertices), np.diff(offsets))
    rows = np.zeros_like(m)
    np.add.at(rows, owner, weights.astype(np.float64)[:, None] * m[senders])
    np.testing.assert_allclose(rows, gather(tr, m), rtol=1e-6, atol=1e-9)
    # a convex mesh: every ray leaves the scene, every row is empty
    convex = build_transfer([MeshNode("box", box_mesh((1.0, 2.0, 3.0)), Material())], rays=16)
    assert len(convex.sender_vertices) == 0 and np.all(convex.sender_offsets == 0)


def test_fewer_rays_average_over_more_rings():
    """At the default's 64 rays a vertex averages its one-ring; at 13 (a mesh over the ray budget) its
    3-ring (13 x 37 >= 448 rays averaged), the one-ring's average applied three times: rows still sum
    to 1, constants kept, an interior vertex of a grid averaging its 37 nearest and its own estimate
    weighing less; the noise of independent per-vertex estimates falls by more than the one-ring's."""
    assert smoothing_rings(64) == 1 and smoothing_rings(13) == 3 and smoothing_rings(4) >= 5
    a, b = open_book(12)
    one = build_transfer([a, b], 64)
    few = build_transfer([a, b], 13)
    sums = np.add.reduceat(few.ring_weights.astype(np.float64), few.ring_offsets[:-1])
    assert np.allclose(sums, 1.0, atol=1e-5)
    assert np.allclose(smooth(few, np.full((few.total_vertices, 3), 2.0)), 2.0, atol=1e-5)
    inner = 6 * 13 + 6  # plate A's middle vertex (a 12 x 12 grid, 13 vertices a row)
    assert few.ring_offsets[inner + 1] - few.ring_offsets[inner] == 37
    assert one.ring_offsets[inner + 1] - one.ring_offsets[inner] == 7
    rng = np.random.default_rng(1)
    noise = rng.normal(size=(few.total_vertices, 1))
    n = a.mesh.positions.shape[0]
    assert smooth(few, noise)[:n].std() < 0.7 * smooth(one, noise)[:n].std()
    powered = ring_power((one.ring_offsets, one.ring_vertices, one.ring_weights), 3)
    np.testing.assert_allclose(smooth(few, noise), smooth(one, smooth(one, smooth(one, noise))), atol=1e-5)
    assert np.array_equal(powered[0], few.ring_offsets)
