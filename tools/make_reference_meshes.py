"""Maintenance, not a feature: write the slab and occluder meshes of the reference scenes
(skinlab/assets/meshes/*.obj). Sizes in millimetres (the scenes say mm_per_unit = 1).

    python -m tools.make_reference_meshes [--out DIR]   # default: the package's meshes folder
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "skinlab" / "assets" / "meshes"  # the package data (skinlab/resources.py)
MESHES = {
    "slab-160x160x40.obj": (160.0, 160.0, 40.0),  # a thick slab: a shadow edge on its top face
    "plate-400x200x4.obj": (400.0, 200.0, 4.0),  # the occluder casting the edge
    "slab-60x60x3.obj": (60.0, 60.0, 3.0),  # a thin slab lit from behind: translucency
    # the slit scenes (skinlab/assets/scenes/reference/slit-*.toml): a slab and, high above it and out
    # of the camera's view, two black plates side by side with the slit between them; all no larger
    # than they must be, so that the shadow map's texels across the slit are small (0.04-0.06 mm)
    "slab-80x80x40.obj": (80.0, 80.0, 40.0),
    "plate-41x124x2.obj": (41.0, 124.0, 2.0),
    "slab-120x120x60.obj": (120.0, 120.0, 60.0),
    "plate-61x184x2.obj": (61.0, 184.0, 2.0),
    # the back slab of the two back-lit slabs with an air gap (wider than the front one, 60 x 60 x 3)
    "slab-100x100x3.obj": (100.0, 100.0, 3.0),
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.make_reference_meshes", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=OUT, help=f"folder to write into (default {OUT})")
    out = ap.parse_args(argv).out
    from skinlab.scene.primitives import box_mesh, write_obj

    out.mkdir(parents=True, exist_ok=True)
    for name, size in MESHES.items():
        write_obj(box_mesh(size, name.split(".")[0]), out / name)
        print(f"wrote {out / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
