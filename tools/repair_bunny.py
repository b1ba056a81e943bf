"""Maintenance, not a feature: make the bundled Stanford bunny a closed surface
(skinlab/assets/stanford-bunny/bunny.ply).

The scan (bun_zipper_res2: 8,171 vertices, 16,301 triangles) had 123 open edges (holes in its base)
and 150 non-manifold ones (81 triangles stored twice, with both windings, and five edges where two
sheets meet), and 92 triangles folded over their neighbours (more than 90 degrees between them:
the vertex normal points inward), so light leaked out of the medium at the holes and every
technique showed dark specks. This drops the doubled triangles and the sheets at non-manifold
edges, smooths the folds (their vertices moved to their neighbours' mean), fills each hole with a fan
around its centroid and cuts out (and fills again) the few places where that still folds
(skinlab/scene/mesh_topology.py ``close_mesh``); the result is watertight with consistent winding.

    git show 4bd519b:skinlab/assets/stanford-bunny/bunny.ply > /tmp/bunny-scan.ply   # the scan as it was
    .venv/bin/python -m tools.repair_bunny --source /tmp/bunny-scan.ply [--out PLY]

The repaired file is what the repository ships (run on the original scan, not on its own output:
the filled base meets the sides at a right angle, which the fold search would take for a fold).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from skinlab.atomic_write import write_text_atomic
from skinlab.scene.mesh_topology import close_mesh

BUNNY = Path(__file__).resolve().parents[1] / "skinlab" / "assets" / "stanford-bunny" / "bunny.ply"


def ply_text(positions: np.ndarray, faces: np.ndarray) -> str:
    head = [
        "ply",
        "format ascii 1.0",
        "comment zipper output (Stanford bun_zipper_res2), closed by tools/repair_bunny.py",
        f"element vertex {len(positions)}",
        "property float x",
        "property float y",
        "property float z",
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    verts = [f"{x:.7g} {y:.7g} {z:.7g}" for x, y, z in positions.tolist()]
    tris = [f"3 {a} {b} {c}" for a, b, c in faces.tolist()]
    return "\n".join(head + verts + tris) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.repair_bunny", description=__doc__.split("\n\n")[0])
    ap.add_argument("--source", type=Path, required=True, help="the original scan (see above)")
    ap.add_argument("--out", type=Path, default=BUNNY)
    args = ap.parse_args(argv)
    import trimesh

    mesh = trimesh.load_mesh(str(args.source), process=False)
    positions, faces = close_mesh(mesh.vertices, mesh.faces, unfold_rounds=10)
    write_text_atomic(args.out, ply_text(positions, faces))
    closed = trimesh.Trimesh(positions, faces, process=False)
    print(
        f"{args.out}: {len(positions)} vertices, {len(faces)} triangles, watertight {closed.is_watertight}, "
        f"winding consistent {closed.is_winding_consistent}, volume {closed.volume * 1e9:.0f} mm^3"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
