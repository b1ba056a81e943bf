"""Write the slab meshes of the reference scenes (skinlab/assets/meshes/*.obj): `python -m tools.make_reference_meshes`.
Sizes in millimetres (the scenes say mm_per_unit = 1)."""

from pathlib import Path

from skinlab.scene.primitives import box_mesh, write_obj

OUT = Path(__file__).resolve().parents[1] / "skinlab" / "assets" / "meshes"  # the package data (skinlab/resources.py)
MESHES = {
    "slab-160x160x40.obj": (160.0, 160.0, 40.0),  # a thick slab: a shadow edge on its top face
    "plate-400x200x4.obj": (400.0, 200.0, 4.0),  # the occluder casting the edge
    "slab-60x60x3.obj": (60.0, 60.0, 3.0),  # a thin slab lit from behind: translucency
}

if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    for name, size in MESHES.items():
        write_obj(box_mesh(size, name.split(".")[0]), OUT / name)
        print(f"wrote {OUT / name}")
