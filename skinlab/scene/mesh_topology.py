"""Is a mesh closed? Open edges (used by one triangle: a hole) and non-manifold edges (used by three
or more), counted per mesh, and a small repair for scans: drop duplicated triangles, cut the sheets
meeting at non-manifold edges apart, fill the holes (``tools/repair_bunny.py`` made the bundled
bunny with it).

A closed mesh matters where light is followed inside the medium: the path-traced truth (Mitsuba's
medium needs an inside) and the thickness a technique reads for light through thin parts; at a hole
the light leaks out and the surface shows dark specks. Open meshes are warned about where such a
frame or reference is made (``skinlab/render/scattering.py``, ``skinlab/truth/export.py``).

The one meaning of "the same vertex" for topology (:func:`weld`): vertices at the same float32
position (-0.0 and 0.0 one) are one, as an atlas generator or a hard edge splits them; nothing closer
than that is merged. The UV seams (``skinlab/scene/uv_seams.py``), the truth's hole capping
(``skinlab/truth/export.py``) and the thickness's closed test (``skinlab/scene/mesh_thickness.py``) all
weld with it, so "is this mesh closed?" has one answer; :func:`welded_mesh` keeps it per mesh version.
(``skinlab/scene/interreflection.py`` merges copies of one position *and* normal, a vertex's shading
copies, on purpose.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SHEET_HOLES = 0.25  # holes this large against the surface's area (a quad: 1, a plane: 1) make a sheet, not a solid


@dataclass(frozen=True)
class EdgeReport:
    edges: int
    open: int  # used by one triangle
    non_manifold: int  # used by three or more
    hole_area: float = 0.0  # the holes' area (each loop capped flat) over the surface's area

    @property
    def closed(self) -> bool:
        return self.open == 0 and self.non_manifold == 0 and self.edges > 0  # no edges: every triangle a point

    @property
    def sheet(self) -> bool:
        """Open on purpose: a quad, a ground plane, a leaf (its holes as large as a good part of it),
        no non-manifold edge."""
        return self.open > 0 and self.non_manifold == 0 and self.hole_area >= SHEET_HOLES

    def describe(self) -> str:
        parts = [
            f"{n} {what} edge{'s' if n != 1 else ''}"
            for n, what in ((self.open, "open"), (self.non_manifold, "non-manifold"))
            if n
        ]
        return " and ".join(parts) if parts else "closed" if self.edges else "no edges: every triangle welds to a point"


def _undirected_edges(indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct edges (a < b) of a triangle list and how many triangles use each; a side from a
    vertex to itself (a triangle collapsed by the weld) is no edge."""
    f = np.asarray(indices, np.int64).reshape(-1, 3)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    e = e[e[:, 0] != e[:, 1]]
    n = int(e.max()) + 1 if e.size else 1
    codes, counts = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)  # one int per edge: a 1-D sort
    return np.stack([codes // n, codes % n], axis=1), counts


@dataclass(frozen=True)
class Welded:
    """A triangle list with vertices at one position merged (:func:`weld`)."""

    ids: np.ndarray  # (N,) int64: the welded vertex of each vertex
    first: np.ndarray  # (W,) int64: each welded vertex's first vertex
    positions: np.ndarray  # (W, 3) float64: each welded vertex's position
    faces: np.ndarray  # (F, 3) int64: the triangles in welded vertices

    def first_faces(self) -> np.ndarray:
        """The triangles in original vertex indices, each welded vertex as its first copy."""
        return self.first[self.faces]


def weld(positions: np.ndarray, indices: np.ndarray) -> Welded:
    """The triangles `indices` over `positions` with vertices at the same float32 position merged: a
    UV seam or a hard edge splits vertices, which is no hole (-0.0 and 0.0 are one position)."""
    p = np.ascontiguousarray(np.asarray(positions, np.float32).reshape(-1, 3) + np.float32(0.0))  # -0.0 -> 0.0
    rows = p.view(np.dtype((np.void, 12))).reshape(-1)  # each position's 12 bytes as one sortable key
    _, first, inverse = np.unique(rows, return_index=True, return_inverse=True)
    ids = inverse.reshape(-1).astype(np.int64)
    f = ids[np.asarray(indices, np.int64).reshape(-1, 3)]
    return Welded(ids, first.astype(np.int64), p[first].astype(np.float64), f)


_WELDED: dict[tuple[int, int], Welded] = {}


def welded_mesh(mesh) -> Welded:
    """:func:`weld` of a mesh, once per mesh version (``Mesh.version``, bumped when its geometry
    changes)."""
    key = (mesh.uid, mesh.version)
    hit = _WELDED.get(key)
    if hit is None:
        hit = _WELDED[key] = weld(mesh.positions, mesh.indices)
        if len(_WELDED) > 32:
            _WELDED.pop(next(iter(_WELDED)))
    return hit


_REPORTS: dict[tuple[int, int], EdgeReport] = {}


def edge_report(mesh) -> EdgeReport:
    """Open and non-manifold edges of ``mesh`` (vertices at one position count as one), once per mesh
    version."""
    key = (mesh.uid, mesh.version)
    if key not in _REPORTS:
        w = welded_mesh(mesh)
        p, f = w.positions, w.faces
        _, counts = _undirected_edges(f)
        holes = _hole_area(p, f) if (counts == 1).any() else 0.0
        _REPORTS[key] = EdgeReport(int(counts.size), int((counts == 1).sum()), int((counts > 2).sum()), holes)
        if len(_REPORTS) > 256:
            _REPORTS.pop(next(iter(_REPORTS)))
    return _REPORTS[key]


def _hole_area(p: np.ndarray, f: np.ndarray) -> float:
    """The area of the surface's holes, each boundary loop capped by a fan from its centroid, over
    the surface's own area (inf where the boundary does not form loops)."""
    t = p[f]
    area = 0.5 * float(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum())
    try:
        loops = boundary_loops(f)
    except ValueError:
        return float("inf")
    holes = 0.0
    for loop in loops:
        ring = p[loop]
        c = ring.mean(axis=0)
        holes += 0.5 * float(np.linalg.norm(np.cross(ring - c, np.roll(ring, -1, axis=0) - c).sum(axis=0)))
    return holes / area if area > 0 else float("inf")


def open_mesh_warning(mesh, needs: str) -> str | None:
    """One line for a mesh that is not closed, saying what needs it closed; None for a closed one
    and for a sheet (EdgeReport.sheet: a quad is open on purpose)."""
    report = edge_report(mesh)
    if report.closed or report.sheet:
        return None
    where = f"mesh {mesh.name!r}" + (f" ({mesh.source})" if mesh.source else "")
    return (
        f"{where} is not closed ({report.describe()}): {needs} needs a closed surface, light leaks out at the "
        "holes (dark specks); fill them (Blender: Select > All by Trait > Non Manifold, then Face > Fill)"
    )


def _face_pairs(f: np.ndarray) -> np.ndarray:
    """(P, 2) the pairs of triangles sharing an edge that exactly two triangles use."""
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    n = int(f.max()) + 1
    code = e[:, 0] * n + e[:, 1]
    face = np.tile(np.arange(len(f)), 3)
    order = np.argsort(code, kind="stable")
    code, face = code[order], face[order]
    _, first, count = np.unique(code, return_index=True, return_counts=True)
    two = first[count == 2]
    return np.stack([face[two], face[two + 1]], axis=1)


def folded_triangles(p: np.ndarray, f: np.ndarray, ignore: np.ndarray | None = None) -> np.ndarray:
    """Triangles meeting a neighbour at more than 90 degrees: a scan's folded-over triangles (pairs
    with a triangle in ``ignore``, a boolean mask, left out)."""
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
    pairs = _face_pairs(f)
    if ignore is not None:
        pairs = pairs[~(ignore[pairs[:, 0]] | ignore[pairs[:, 1]])]
    folded = pairs[np.einsum("ij,ij->i", fn[pairs[:, 0]], fn[pairs[:, 1]]) < 0.0]
    return np.unique(folded.reshape(-1))


def unfold(
    positions: np.ndarray, indices: np.ndarray, rounds: int = 10, ignore: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """A scan's folds (adjacent triangles facing more than 90 degrees apart: dark specks, the vertex
    normal points inward) smoothed out: each fold's vertices moved to the mean of their neighbours,
    ``rounds`` times; the triangles around folds that remain are removed (close_mesh fills the holes)
    unless ``ignore`` is given (a mask of triangles whose creases are meant: a flat cap's rim)."""
    p = np.asarray(positions, np.float64).copy()
    f = np.asarray(indices, np.int64).reshape(-1, 3)
    edges, _ = _undirected_edges(f)
    degree = np.bincount(edges.reshape(-1), minlength=len(p)).astype(np.float64)
    for _ in range(rounds):
        folded = folded_triangles(p, f, ignore)
        if not len(folded):
            return p, f
        moving = np.unique(f[folded].reshape(-1))
        total = np.zeros_like(p)
        np.add.at(total, edges[:, 0], p[edges[:, 1]])
        np.add.at(total, edges[:, 1], p[edges[:, 0]])
        p[moving] = total[moving] / np.maximum(degree[moving], 1.0)[:, None]
    if ignore is not None:
        return p, f
    stuck = np.unique(f[folded_triangles(p, f)].reshape(-1))
    return p, f[~np.isin(f, stuck).any(axis=1)]


BIG_HOLE = 16  # a hole of this many edges or more is a cut (the bunny's flat base): its rim is a real crease


def close_mesh(positions: np.ndarray, indices: np.ndarray, unfold_rounds: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A scan made closed: duplicated triangles (both copies: they are fins of zero volume) and the
    triangles at non-manifold edges removed, with ``unfold_rounds`` > 0 its folds smoothed
    (:func:`unfold`), then every hole filled by a fan around a new vertex at the hole's centroid,
    wound like its neighbours. Raises ValueError if the result is still open."""
    p = np.asarray(positions, np.float64)
    f = np.asarray(indices, np.int64).reshape(-1, 3)
    _, inverse, counts = np.unique(np.sort(f, axis=1), axis=0, return_inverse=True, return_counts=True)
    f = f[counts[inverse.reshape(-1)] == 1]
    for _ in range(8):  # removing triangles can leave new non-manifold corners; a few rounds settle it
        edges, counts = _undirected_edges(f)
        bad = edges[counts > 2]
        if not len(bad):
            break
        e = np.sort(np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], axis=1), axis=2)  # (F, 3, 2)
        bad_set = {tuple(x) for x in bad.tolist()}
        keep = np.array([not any(tuple(x) in bad_set for x in tri) for tri in e.tolist()])
        f = f[keep]
    if unfold_rounds:
        p, f = unfold(p, f, unfold_rounds)
    big = np.zeros(len(f), bool)
    for _ in range(3):
        p, f, big = _fill_holes(p, f, big)
        if not unfold_rounds:
            break
        # a small hole's fan in a curved place may fold against its rim: smooth it in, else cut it out
        # with its surroundings and fill the larger hole again
        p, f = unfold(p, f, unfold_rounds, ignore=big)
        stuck = np.unique(f[folded_triangles(p, f, big)].reshape(-1))
        if not len(stuck):
            break
        kept = ~np.isin(f, stuck).any(axis=1)
        f, big = f[kept], big[kept]
    _, counts = _undirected_edges(f)
    if (counts != 2).any():
        raise ValueError(f"close_mesh: {int((counts != 2).sum())} edges are still open or non-manifold")
    used = np.unique(f.reshape(-1))  # vertices of removed caps: dropped, the rest renumbered in order
    renumber = np.full(len(p), -1, np.int64)
    renumber[used] = np.arange(len(used))
    return p[used], renumber[f]


def boundary_loops(f: np.ndarray) -> list[list[int]]:
    """The boundary's loops (directed edges whose reverse no triangle has), each in the order a cap
    must run (against its neighbours' winding): a fan (loop[i], loop[i + 1], centre) closes it wound
    like the rest. ValueError where an open boundary does not close."""
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    present = {tuple(x) for x in directed.tolist()}
    # a boundary edge a->b has no b->a; the fill runs the other way, b->a
    step: dict[int, list[int]] = {}
    for a, b in directed.tolist():
        if (b, a) not in present:
            step.setdefault(b, []).append(a)
    loops = []
    while step:
        start = next(iter(step))
        loop = [start]
        while True:
            nxt = step[loop[-1]].pop()
            if not step[loop[-1]]:
                del step[loop[-1]]
            if nxt == start:
                break
            loop.append(nxt)
            if nxt not in step:
                raise ValueError(f"close_mesh: a hole's boundary does not close at vertex {nxt}")
        loops.append(loop)
    return loops


def _fill_holes(p: np.ndarray, f: np.ndarray, big: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every hole filled by a fan around its centroid; ``big`` (a mask of the triangles of fans of
    holes of BIG_HOLE edges or more) extended to the new triangles."""
    new_p, new_f, new_big = [p], [f], [big]
    n = len(p)
    for loop in boundary_loops(f):
        centre = p[loop].mean(axis=0)
        new_p.append(centre[None])
        new_f.append(np.array([[loop[i], loop[(i + 1) % len(loop)], n] for i in range(len(loop))], np.int64))
        new_big.append(np.full(len(loop), len(loop) >= BIG_HOLE))
        n += 1
    return np.concatenate(new_p), np.concatenate(new_f), np.concatenate(new_big)
