"""Light through thin parts (skinlab/scene/optics/translucency.py) and its GLSL twin (lib/sss_translucency.glsl):
the thickness lookup in the shadow pass's distance map and the slab transmission through it."""

import numpy as np

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.render.boundary import bind_boundary, material_boundary
from skinlab.scene.optics import translucency as tr
from skinlab.scene.optics.material_medium import material_medium
from tests.translucency_maps import distance_texture, layer_textures, lookup_setup, no_exit
from tests.tsd_scenes import skin

# (hit, thickness) of sss_thickness_mm as one value
LOOK = """vec2 look(int slot, vec3 p, vec3 n, float c) {
    float d;
    bool hit = sss_thickness_mm(slot, p, n, c, d);
    return vec2(hit ? 1.0 : 0.0, d);
}"""


def test_thickness_lookup_matches_numpy_twin(ctx, glsl):
    """sss_thickness_mm against thickness_mm for a directional (slot 0) and a point light (slot 1) on
    random distance maps, including texels with no surface, points outside the map, points in front
    of the first surface (thickness clamps to the shrink) and grazing cosines; within fp32 (1e-4)."""
    rng = np.random.default_rng(12)
    h, w = 16, 24
    maps, texes = [], []
    for _ in range(2):
        d = rng.uniform(5.0, 10.0, (h, w))
        d[rng.uniform(size=(h, w)) < 0.1] = 1e30  # cleared: no surface
        maps.append(d)
        texes.append(distance_texture(ctx, d))
    m = np.eye(4)
    m[:3, :3] *= 0.5
    m[:3, 3] = 0.5  # world [-1, 1]^3 -> texture [0, 1]^3
    eyes = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -5.0, 1.0]])  # travels +z; a point at z = -5
    n = 3000
    # points away from texel borders and centres (where the texel containing them and the four
    # bilinear neighbours change: fp32 may pick the other side), normals nearly along z so the
    # shrink (0.004 units, 0.05 texel) keeps the point in its quarter of the texel
    off = rng.uniform(0.12, 0.38, (n, 2)) + 0.5 * rng.integers(0, 2, (n, 2))
    uv = (rng.integers(0, [w, h], (n, 2)) + off) / [w, h]
    world = np.stack([uv[:, 0] * 2 - 1, uv[:, 1] * 2 - 1, rng.uniform(3.0, 12.0, n)], 1)
    world[:60, 0] = 1.5  # outside the map
    normal = np.column_stack([rng.normal(0, 0.2, (n, 2)), np.ones(n)])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    back = rng.uniform(0.0, 1.0, n)
    back[:100] = rng.uniform(0.0, 1e-4, 100)  # grazing
    shrink, mm = 0.004, 20.0
    world, normal, back = (x.astype(np.float32).astype(np.float64) for x in (world, normal, back))
    none = no_exit(ctx)
    setup = lookup_setup(texes, [m, m], eyes, shrink, mm, exits=(none, none))
    for slot in (0, 1):
        gpu = glsl.evaluate(
            "lib/sss_translucency.glsl",
            f"look({slot}, pos, nrm, c)",
            {"pos": world, "nrm": normal, "c": back},
            2,
            prelude=LOOK,
            setup=setup,
        )
        ref, hit = tr.thickness_mm(maps[slot], m, eyes[slot], world, normal, back, shrink, mm)
        assert np.array_equal(gpu[:, 0] == 1.0, hit), f"slot {slot}: hit flags differ"
        assert 0.5 < hit.mean() < 0.95 and not hit[:60].any()
        assert_close_fp32(gpu[:, 1], ref, rtol=1e-4, atol=1e-4, what=f"sss_thickness_mm slot {slot}")
        clamped = hit & (ref == 0)  # points in front of the first surface
        assert clamped.sum() > 50 and (ref[hit & ~clamped] >= shrink * mm).all()
    for t in (*texes, *none):
        t.release()


def _slab_map(direction, size, radius, z_lit):
    """(distance map, shadow matrix, eye) of a directional light travelling along `direction` onto
    the plane z = z_lit (the slab's lit face), orthographic over a disc of `radius` around the origin
    as skinlab/render/passes/shadow.py fits it: each texel holds the distance of the plane along the ray
    through the texel's centre."""
    d = np.asarray(direction, np.float64) / np.linalg.norm(direction)
    e1 = np.cross(d, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    m = np.eye(4)
    m[0, :3], m[1, :3] = e1 / (2 * radius), e2 / (2 * radius)
    m[0, 3] = m[1, 3] = 0.5
    m[2, :3], m[2, 3] = 0.0, 0.0
    c = (np.arange(size) + 0.5) / size * 2 * radius - radius
    a, bb = np.meshgrid(c, c)  # columns: e1, rows: e2
    q = a[..., None] * e1 + bb[..., None] * e2
    t = (z_lit - q[..., 2]) / d[2]  # along the ray to the plane; q is perpendicular to d
    return t, m, np.append(d, 0.0)


def test_flat_slab_keeps_its_thickness():
    """A 3 mm slab lit at 30 degrees from behind: the thickness read on its far face is 3 mm (the
    shrink added back, the map interpolated between texel centres; the nearest texel alone would be
    off by up to half a texel times the lit face's slope); 0 where the point is itself the first
    surface."""
    d = (np.sin(np.radians(30)), 0.0, np.cos(np.radians(30)))
    size, radius = 512, 40.0
    dist, m, eye = _slab_map(d, size, radius, -1.5)
    texel = 2 * radius / size
    shrink = radius / size  # half a texel (skinlab/render/translucency.py thickness_shrink)
    rng = np.random.default_rng(3)
    p = np.column_stack([rng.uniform(-25, 25, (4000, 2)), np.full(4000, 1.5)])
    nrm = np.tile([0.0, 0.0, 1.0], (4000, 1))
    back = np.full(4000, float(np.dot(nrm[0], d)))
    got, hit = tr.thickness_mm(dist, m, eye, p, nrm, back, shrink, 1.0)
    assert hit.all()
    np.testing.assert_allclose(got, 3.0, atol=1e-9)  # the bilinear lookup is exact on a plane
    # the texel containing the point alone (what a NEAREST sampler returns) is off by up to half a
    # texel times the lit face's slope
    i = np.clip(np.floor((np.c_[p, np.ones(len(p))] @ m.T)[:, :2] * size).astype(int), 0, size - 1)
    near = (p @ np.asarray(d) - dist[i[:, 1], i[:, 0]]) * back[0]
    assert 0.3 * texel * np.sin(np.radians(30)) < np.abs(near - 3.0).max() <= 0.5 * texel * np.sin(np.radians(30))
    # a point that is itself the first surface although its (interpolated) normal faces away from
    # the light, as near a smooth mesh's terminator, reads 0
    lit = np.column_stack([p[:, :2], np.full(4000, -1.5)])
    got_lit, _ = tr.thickness_mm(dist, m, eye, lit, nrm, back, shrink, 1.0)
    assert np.all(got_lit == 0)


def test_through_matches_slab_transmission_and_glsl(glsl):
    """sss_through(back, d) against its twin (the exact slab transmittance, skinlab/scene/optics/slab.py
    slab_through) within 1e-4, for skin at eta 1 and 1.4, at the hard cases: zero thickness (nothing
    collides: 0), grazing light (finite), very thick (0); past a few mean free paths thicker passes less."""
    backs = np.array([1.0, 0.866, 0.5, 1e-3, 0.0, 1.0, 0.3, 1.0])
    dd = np.array([0.5, 3.0, 1.0, 2.0, 2.0, 0.0, 1e-5, 1e4])
    for eta in (1.0, 1.4):
        # specular 0.347: F0 = 0.08 x 0.347 = ((1.4 - 1) / (1.4 + 1))^2, the medium's index 1.4
        mat = skin(specular=0.347) if eta != 1.0 else skin()
        med = material_medium(mat.values)
        tabs = material_boundary(mat)
        ref = tr.through(backs, dd, tabs, med, mat["subsurface_color"])
        assert np.all(np.isfinite(ref)) and np.all(ref >= 0)
        assert np.all(ref[5] == 0) and np.all(ref[-1] < 1e-12)
        thick = tr.through([1.0, 1.0], [3.0, 10.0], tabs, med, mat["subsurface_color"])
        assert np.all(thick[0] > thick[1])  # past a few mean free paths, thicker lets less through
        gpu = glsl.evaluate(
            "lib/sss_translucency.glsl",
            "sss_through(c, d)",
            {"c": backs, "d": dd},
            3,
            setup=lambda prog, mat=mat: bind_boundary(prog, mat),
        )
        assert_close_fp32(gpu, ref, atol=1e-4, what=f"sss_through eta {eta}")


def test_through_incidence_is_the_slabs_ratio_and_1_where_nothing_passes(glsl):
    """sss_through_incidence (the transfer's entering light at a cosine, passes/through_entering.frag) against
    its twin: the slab transmittance at the cosine over at normal incidence, 1 at normal incidence, below 1
    at an oblique one (light entering obliquely goes less deep), and 1, finite, where the slab lets nothing
    through at normal incidence: no depth (a vertex whose rays met nothing) and a part too thick for a float;
    grazing light (cosine 0) finite. GPU within 1e-4 of NumPy."""
    mat = skin()
    med, tabs = material_medium(mat.values), material_boundary(mat)
    cs = np.array([1.0, 0.3, 0.3, 0.0, 1e-3, 0.5, 0.3, 0.3])
    dd = np.array([3.0, 3.0, 0.5, 3.0, 3.0, 0.0, 0.0, 1e4])
    ref = tr.through_incidence(cs, dd, tabs, med, mat["subsurface_color"])
    assert np.all(np.isfinite(ref)) and np.all(ref >= 0)
    np.testing.assert_allclose(ref[0], 1.0, rtol=1e-12)
    assert np.all(ref[1] < 1.0) and np.all(ref[1] > 0.0)
    assert np.all(ref[5:] == 1.0)  # nothing passes at normal incidence: the guard
    gpu = glsl.evaluate(
        "lib/sss_translucency.glsl",
        "sss_through_incidence(c, d)",
        {"c": cs, "d": dd},
        3,
        setup=lambda prog: bind_boundary(prog, mat),
    )
    assert_close_fp32(gpu, ref, atol=1e-4, what="sss_through_incidence")


def test_translucent_light_matches_numpy(ctx, glsl):
    """sss_translucent_light for one shadow-casting directional light on a flat map: e back through
    where the light is behind the surface and 0 where it is in front, at grazing incidence or where
    the map has no surface; GPU within 1e-4 of NumPy."""
    mat = skin()
    med, tabs = material_medium(mat.values), material_boundary(mat)
    dist = np.full((8, 8), 10.0)
    dist[:, :2] = 1e30
    tex = distance_texture(ctx, dist)
    m = np.eye(4)
    m[:3, :3] *= 0.5
    m[:3, 3] = 0.5
    eye = np.array([0.0, 0.0, 1.0, 0.0])  # travels +z: l = (0, 0, -1)
    world = np.array([[0.1, 0.1, 10.05], [0.1, 0.1, 10.2], [0.1, 0.1, 10.2], [-0.9, 0.1, 10.2], [0.3, 0.3, 11.0]])
    ng = np.array([[0, 0, 1.0], [0, 0, 1.0], [0, 0, -1.0], [0, 0, 1.0], [0.9999995, 0, 0.001]])
    ng /= np.linalg.norm(ng, axis=1, keepdims=True)
    l = np.array([0.0, 0.0, -1.0])
    e = np.array([2.0, 1.0, 0.5])
    shrink, mm = 0.01, 10.0
    none = no_exit(ctx)
    setup = lookup_setup([tex, tex], [m, m], [eye, eye], shrink, mm, mat, exits=(none, none))
    gpu = glsl.evaluate(
        "lib/sss_translucency.glsl",
        "sss_translucent_light(0, pos, nrm, vec3(0.0, 0.0, -1.0), vec3(2.0, 1.0, 0.5))",
        {"pos": world, "nrm": ng},
        3,
        setup=setup,
    )
    back = -(ng @ l)
    # the part crossed at the larger of the point's cosine and the entry face's (1 on this flat map)
    c = tr.through_cosine(dist, m, eye, world, ng, back, shrink)
    assert np.allclose(c[[0, 1, 4]], 1.0) and c[3] == back[3]  # no surface at [3]: its own cosine
    d_mm, hit = tr.thickness_mm(dist, m, eye, world, ng, c, shrink, mm)
    ref = tr.translucent_irradiance(e, np.where(back > 0, c, back), d_mm, hit, tabs, med, mat["subsurface_color"])
    assert_close_fp32(gpu, ref, atol=1e-4, what="sss_translucent_light")
    assert ref[0].min() > 0 and ref[1].min() > 0 and ref[0, 2] > ref[1, 2]  # thinner passes more (blue)
    assert np.all(ref[2] == 0) and np.all(ref[3] == 0)  # light in front; no surface in the map
    # a face grazing the light behind a flat entry face: the slab parallel to the entry, 10 mm of it
    # (11.0 - 10.0 scene units x 10 mm, and the shrink added back)
    assert np.isclose(d_mm[4], 10.0 + shrink * mm, rtol=1e-4)
    assert np.all(np.isfinite(ref[4])) and 0 < ref[4].max() < ref[1].max()
    tex.release()
    for t in none:
        t.release()


def test_layered_thickness_lookup_matches_numpy_twin(ctx, glsl):
    """With the exit and next-entry layers (another part in front, air between; at half the distance
    map's texels per side, as the renderer's): sss_thickness_mm against thickness_mm on random
    layered maps, points in the first part, past its exit within and beyond the part gap, with and
    without a next entry, exit cosines down to 0; within fp32."""
    rng = np.random.default_rng(21)
    h, w = 16, 24
    first = rng.uniform(5.0, 6.0, (h, w))
    exit_d = 6.0 + rng.uniform(0.5, 1.5, (h // 2, w // 2))
    exit_c = rng.uniform(0.0, 1.0, (h // 2, w // 2))
    nxt = exit_d + rng.uniform(1.0, 3.0, (h // 2, w // 2))
    nxt[rng.uniform(size=nxt.shape) < 0.15] = 1e30  # no next entry
    exit_d[rng.uniform(size=nxt.shape) < 0.1] = 1e30  # no exit: one part
    dist = first
    ex = np.stack([exit_d, exit_c, nxt], -1)
    tex, etex = distance_texture(ctx, dist), layer_textures(ctx, ex)
    m = np.eye(4)
    m[:3, :3] *= 0.5
    m[:3, 3] = 0.5
    eye = np.array([0.0, 0.0, 1.0, 0.0])  # travels +z
    n = 3000
    off = rng.uniform(0.12, 0.38, (n, 2)) + 0.5 * rng.integers(0, 2, (n, 2))
    uv = (rng.integers(0, [w, h], (n, 2)) + off) / [w, h]
    world = np.stack([uv[:, 0] * 2 - 1, uv[:, 1] * 2 - 1, rng.uniform(5.2, 11.0, n)], 1)
    normal = np.tile([0.0, 0.0, 1.0], (n, 1))
    back = rng.uniform(0.05, 1.0, n)
    shrink, gap, mm = 0.004, 0.3, 20.0
    world, back = world.astype(np.float32).astype(np.float64), back.astype(np.float32).astype(np.float64)
    setup = lookup_setup([tex, tex], [m, m], [eye, eye], shrink, mm, exits=(etex, etex), part_gap=gap)
    gpu = glsl.evaluate(
        "lib/sss_translucency.glsl", "look(0, pos, nrm, c)", {"pos": world, "nrm": normal, "c": back}, 2,
        prelude=LOOK, setup=setup,
    )  # fmt: skip
    ref, hit = tr.thickness_mm(dist, m, eye, world, normal, back, shrink, mm, exit_map=ex, part_gap=gap)
    assert np.array_equal(gpu[:, 0] == 1.0, hit) and hit.all()
    assert_close_fp32(gpu[:, 1], ref, rtol=1e-4, atol=1e-4, what="layered sss_thickness_mm")
    lay = tr.part_layers(ex, m, world - shrink * normal)
    at = world[:, 2] - shrink
    other = (lay[:, 0] < 1e29) & (at > lay[:, 0] + gap)
    assert 500 < other.sum() < n - 500  # both cases present
    one = tr.thickness_mm(dist, m, eye, world, normal, back, shrink, mm)[0]
    np.testing.assert_array_equal(ref[~other], one[~other])  # one part: as without layers
    # past the first part the air between is not counted: thinner than the whole chord where the
    # first part's exit cosine is no larger than the point's own
    less = other & (lay[:, 1] <= back)
    assert less.sum() > 200 and np.all(ref[less] < one[less])
    for t in (tex, *etex):
        t.release()


def _parallel_slabs_maps(direction, size, radius, faces):
    """The distance map and part layers of parallel slabs z in [a_k, b_k] (ascending along the light,
    which travels along `direction` with d_z > 0): first surface; first part's exit, its cosine and
    the next part's entry, as skinlab/shaders/passes/shadow.frag writes them (its part gap ignored:
    the gaps are wide)."""
    first, m, eye = _slab_map(direction, size, radius, faces[0][0])
    cos = float(direction[2] / np.linalg.norm(direction))
    step = lambda z: first + (z - faces[0][0]) / cos  # the plane z's distance along each texel's ray
    nxt = step(faces[1][0]) if len(faces) > 1 else np.full(first.shape, 1e30)
    ex = np.stack([step(faces[0][1]), np.full(first.shape, cos), nxt], -1)
    return first, ex, m, eye


def test_two_slabs_apart_are_not_one_thick_slab():
    """Two 3 mm slabs 10 mm apart, lit at 30 degrees from behind: the front slab's far face reads
    6 mm (the two slabs; index-matched parallel slabs transmit as one slab of their summed
    thickness), not the 16 mm from the back slab's lit face (slab, air and slab as if all tissue);
    the back slab's far face 3 mm; one slab 16 mm thick still reads 16 mm."""
    d = (np.sin(np.radians(30)), 0.0, np.cos(np.radians(30)))
    size, radius = 512, 40.0
    shrink, gap = radius / size, 8 * radius / size
    rng = np.random.default_rng(5)
    xy = rng.uniform(-20, 20, (2000, 2))
    nrm = np.tile([0.0, 0.0, 1.0], (2000, 1))
    back = np.full(2000, d[2])
    dist, ex, m, eye = _parallel_slabs_maps(d, size, radius, [(-16.0, -13.0), (-3.0, 0.0)])
    front = np.column_stack([xy, np.zeros(2000)])
    got, hit = tr.thickness_mm(dist, m, eye, front, nrm, back, shrink, 1.0, exit_map=ex, part_gap=gap)
    assert hit.all()
    np.testing.assert_allclose(got, 6.0, atol=1e-6)
    air, _ = tr.thickness_mm(dist, m, eye, front, nrm, back, shrink, 1.0)  # no layers: as before
    np.testing.assert_allclose(air, 16.0, atol=1e-6)
    back_face = np.column_stack([xy, np.full(2000, -13.0)])
    got, _ = tr.thickness_mm(dist, m, eye, back_face, nrm, back, shrink, 1.0, exit_map=ex, part_gap=gap)
    np.testing.assert_allclose(got, 3.0, atol=1e-6)
    dist, ex, m, eye = _parallel_slabs_maps(d, size, radius, [(-16.0, 0.0)])
    got, _ = tr.thickness_mm(dist, m, eye, front, nrm, back, shrink, 1.0, exit_map=ex, part_gap=gap)
    np.testing.assert_allclose(got, 16.0, atol=1e-6)


ENTRY = """vec4 entry(int slot, vec3 p, vec3 n, float c) {
    vec4 f = entry_face(slot, p);
    return vec4(f.xz, f.w, sss_through_cosine(slot, p, n, c));
}"""


def test_entry_face_matches_numpy_twin_and_reads_a_plane(ctx, glsl):
    """entry_face and sss_through_cosine against their twins on a random map (silhouettes, points
    outside it, a point light: 0, the point's own cosine) and on a tilted plane's distances, whose
    slope they read exactly: the entry face's normal (0.6, 0, -0.8), its cosine 0.8; the sheet's
    cosine the larger of it and the point's where the point's face faces away from the entry face,
    the point's own where both face one side (issue 21's model)."""
    rng = np.random.default_rng(21)
    h, w = 16, 24
    m = np.eye(4)
    m[:3, :3] *= 0.5
    m[:3, 3] = 0.5  # world [-1, 1]^3 -> texture [0, 1]^3: a texel 2 / 24 x 2 / 16 scene units
    eyes = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -5.0, 1.0]])
    rand = rng.uniform(5.0, 6.0, (h, w))
    rand[rng.uniform(size=(h, w)) < 0.1] = 1e30
    xs = (np.arange(w) + 0.5) / w * 2 - 1
    slope = 0.75
    plane = np.tile(8.0 + slope * xs, (h, 1))  # z = 8 + 0.75 x: the normal toward the light (0.6, 0, -0.8)
    n = 2000
    off = rng.uniform(0.12, 0.38, (n, 2)) + 0.5 * rng.integers(0, 2, (n, 2))
    uv = (rng.integers(0, [w, h], (n, 2)) + off) / [w, h]
    world = np.stack([uv[:, 0] * 2 - 1, uv[:, 1] * 2 - 1, rng.uniform(3.0, 12.0, n)], 1)
    world[:40, 0] = 1.5  # outside the map
    normal = np.column_stack([rng.normal(0, 0.2, (n, 2)), np.ones(n)])
    normal[n // 2 :] *= -1  # half facing the light's side: with the plane's normal, not a sheet
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    back = rng.uniform(0.0, 1.0, n)
    shrink = 0.004
    world, normal, back = (x.astype(np.float32).astype(np.float64) for x in (world, normal, back))
    none = no_exit(ctx)
    for dist in (rand, plane):
        tex = distance_texture(ctx, dist)
        setup = lookup_setup([tex, tex], [m, m], eyes, shrink, 20.0, exits=(none, none))
        for slot in (0, 1):
            gpu = glsl.evaluate(
                "lib/sss_translucency.glsl",
                f"entry({slot}, pos, nrm, c)",
                {"pos": world, "nrm": normal, "c": back},
                4,
                prelude=ENTRY,
                setup=setup,
            )
            face = tr.entry_face(dist, m, eyes[slot], world)
            ct = tr.through_cosine(dist, m, eyes[slot], world, normal, back, shrink)
            assert_close_fp32(gpu[:, :3], face[:, [0, 2, 3]], rtol=1e-4, atol=1e-5, what=f"entry_face slot {slot}")
            assert_close_fp32(gpu[:, 3], ct, rtol=1e-4, atol=1e-5, what=f"sss_through_cosine slot {slot}")
            assert not face[:40].any() and np.array_equal(ct[:40], back[:40])  # outside: its own cosine
            if slot == 1:
                assert not face.any() and np.array_equal(ct, back)  # a point light: its own cosine
            elif dist is plane:
                inner = (uv[:, 0] > 1.0 / w) & (uv[:, 0] < 1 - 1.0 / w) & (world[:, 0] < 1)
                assert np.allclose(face[inner], [0.6, 0.0, -0.8, 0.8], atol=1e-6)
                sheet = inner & (normal @ [0.6, 0.0, -0.8] < 0)
                assert sheet[: n // 2].sum() > 0.95 * inner[: n // 2].sum() and not sheet[n // 2 :].any()
                assert np.array_equal(ct[sheet], np.maximum(back[sheet], 0.8))
                assert np.array_equal(ct[inner & ~sheet], back[inner & ~sheet])
            else:
                assert 0.2 < (face[:, 3] > 0).mean() < 0.9  # silhouettes (a cleared texel among the four): 0
        tex.release()
    for t in none:
        t.release()
