"""Closed meshes: open and non-manifold edges counted, the bundled bunny closed (its scan had 123 open
and 150 non-manifold edges and folded triangles: dark specks), and a warning where translucency
reads the thickness of an open mesh."""

import numpy as np
import pytest

from skinlab.render.plan import plan_frame
from skinlab.render.settings import RenderSettings
from skinlab.scene.mesh import Mesh
from skinlab.scene.mesh_topology import (
    boundary_loops,
    close_mesh,
    edge_report,
    folded_triangles,
    open_mesh_warning,
    weld,
    welded_mesh,
)
from skinlab.scene.scenefile import load_scene
from tests.tsd_scenes import light_from, quad_mesh, slab_scene

CUBE_P = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], np.float64)
CUBE_F = np.array(
    [
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # x = 0, x = 1
        [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # y = 0, y = 1
        [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # z = 0, z = 1
    ]
)  # fmt: skip


def _volume(p, f):
    t = p[f]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def test_edge_report_counts_holes_and_non_manifold_edges():
    assert edge_report(Mesh("cube", CUBE_P, CUBE_F)).closed
    assert abs(_volume(CUBE_P, CUBE_F) - 1.0) < 1e-12  # outward winding
    open_box = Mesh("box", CUBE_P, CUBE_F[2:])  # the x = 0 side missing: a square hole
    report = edge_report(open_box)
    assert (report.open, report.non_manifold) == (4, 0) and not report.closed
    assert "4 open edges" in open_mesh_warning(open_box, "translucency")
    fin = Mesh("fin", np.vstack([CUBE_P, [[0.5, -1, 0.5]]]), np.vstack([CUBE_F, [[0, 1, 8]]]))  # a third on 0-1
    assert (edge_report(fin).open, edge_report(fin).non_manifold) == (2, 1)
    # vertices split at one position (a UV seam) are no hole
    split = np.vstack([CUBE_P, CUBE_P[:1]])
    faces = CUBE_F.copy()
    faces[0, 0] = 8
    assert edge_report(Mesh("seam", split, faces)).closed


def test_one_weld_one_answer_to_is_it_closed():
    """The UV seams, the truth's hole capping and the thickness's closed test weld with
    mesh_topology.weld: exactly equal float32 positions (-0.0 and 0.0 one), nothing merely near."""
    from skinlab.scene.mesh_thickness import is_closed
    from skinlab.scene.uv_seams import seam_edges

    w = weld(np.array([[0, 0, 0], [-0.0, 0, 0], [1e-7, 0, 0], [1, 0, 0]], np.float32), np.array([[0, 2, 3]]))
    assert w.ids[0] == w.ids[1] != w.ids[2] and len(w.positions) == 3 and w.first_faces().tolist() == [[0, 2, 3]]
    # the cube with a UV seam (vertex 0 repeated as 8) is closed for all three; moved by 1e-6 it is open
    split = np.vstack([CUBE_P, CUBE_P[:1]])
    faces = CUBE_F.copy()
    faces[0, 0] = 8
    uvs = np.zeros((9, 2), np.float32)
    uvs[8] = 1.0  # vertex 0's other chart
    seam = Mesh("seam", split, faces, uvs=uvs)
    gap = split.copy()
    gap[8, 1] += 1e-6
    torn = Mesh("torn", gap, faces, uvs=uvs)
    for mesh, closed in ((seam, True), (torn, False)):
        loops = boundary_loops(weld(mesh.positions, mesh.indices).first_faces())
        assert (edge_report(mesh).closed, is_closed(mesh), loops == []) == (closed,) * 3, mesh.name
    # the seam's two edges at vertex 0/8 are found; the torn cube's cut edges are no seam (one side each)
    assert len(seam_edges(seam)[0]) == len(seam_edges(torn)[0]) + 2
    # a triangle the weld collapses to a point adds no edge: still closed
    collapsed = Mesh("collapsed", split, np.vstack([faces, [[0, 8, 0]]]))
    assert edge_report(collapsed).closed and is_closed(collapsed)
    point = Mesh("point", np.zeros((3, 3), np.float32), np.array([[0, 1, 2]]))  # no edge at all: not closed
    assert not edge_report(point).closed and not is_closed(point) and "no edges" in open_mesh_warning(point, "x")


def test_weld_is_kept_per_mesh_version():
    mesh = Mesh("cube", CUBE_P.copy(), CUBE_F.copy())
    first = welded_mesh(mesh)
    assert welded_mesh(mesh) is first and len(first.positions) == 8
    mesh.positions[1] = mesh.positions[0]  # geometry changed: the version says so
    mesh.version += 1
    again = welded_mesh(mesh)
    assert again is not first and len(again.positions) == 7 and again.ids[0] == again.ids[1]


def test_close_mesh_fills_a_hole_and_drops_doubled_triangles():
    extra = np.vstack([CUBE_P, [[2, 0, 0], [3, 0, 0], [2, 1, 0]]])
    doubled = np.vstack([CUBE_F[2:], [[8, 9, 10], [8, 10, 9]]])  # a square hole, and a fin stored both ways
    p, f = close_mesh(extra, doubled)
    assert edge_report(Mesh("closed", p, f)).closed
    assert len(p) == 9 and len(f) == 14  # the fin and its vertices gone, one vertex in the hole's centre
    assert abs(_volume(p, f) - 1.0) < 1e-9  # the caps are wound like the rest: the volume is the cube's


def test_bundled_bunny_is_closed_without_folds_above_its_base():
    scene = load_scene("bunny-marble")
    (node,) = scene.mesh_nodes()
    mesh = node.mesh
    assert edge_report(mesh).closed, edge_report(mesh)
    p, f = mesh.positions.astype(np.float64), mesh.indices.astype(np.int64)
    folded = folded_triangles(p, f)
    base = p[:, 1].min()
    # only where the filled base meets the sides (a right angle within 7 mm of the bottom) do faces meet
    # at more than 90 degrees; the scan had 92 such folds all over the body
    assert (p[f[folded]][:, :, 1].max(axis=1) < base + 0.007).all()
    assert not mesh.notes  # no normal had to be recomputed


def test_a_sheet_is_open_on_purpose():
    quad = quad_mesh("q", -1, 1, -1, 1)
    assert edge_report(quad).sheet and open_mesh_warning(quad, "translucency") is None
    open_box = Mesh("box", CUBE_P, CUBE_F[2:])
    assert edge_report(open_box).hole_area == pytest.approx(0.2) and not edge_report(open_box).sheet


def test_translucency_on_an_open_mesh_warns_once():
    settings = RenderSettings(32, 32, shadow_size=64)  # tsd with translucency (its default)

    def warnings(mesh, shadow=True):
        scene = slab_scene(mesh=mesh)
        scene.add(light_from((0.3, 0.0, -1.0), shadow=shadow))
        return [w for w in plan_frame(scene, settings).warnings if "not closed" in w]

    box = Mesh("box", CUBE_P - 0.5, CUBE_F[2:])  # a cube with one side missing
    (line,) = warnings(box)
    assert "translucency" in line and "'box'" in line and "4 open edges" in line
    assert warnings(Mesh("cube", CUBE_P - 0.5, CUBE_F)) == []
    assert warnings(quad_mesh("q", -1, 1, -1, 1)) == []  # a sheet
    # no shadow-casting light, no translucency: nothing reads the thickness, nothing to say
    scene = slab_scene(mesh=box)
    assert not [w for w in plan_frame(scene, settings).warnings if "closed" in w]


def test_the_truth_notes_non_manifold_edges():
    """The path tracer caps holes itself (and says so); a non-manifold edge it cannot repair: a note."""
    from skinlab.truth.export import describe

    fin = Mesh("fin", np.vstack([CUBE_P, [[0.5, -1, 0.5]]]) - 0.5, np.vstack([CUBE_F, [[0, 1, 8]]]))
    notes = describe(slab_scene(mesh=fin), 8, 8).notes
    assert any("1 non-manifold edge" in n for n in notes), notes
    assert not any(
        "non-manifold" in n for n in describe(slab_scene(mesh=Mesh("cube", CUBE_P - 0.5, CUBE_F)), 8, 8).notes
    )
