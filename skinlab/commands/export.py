"""`skinlab export [SCENE|MESH] --out PATH.glb`: the scene as glTF 2.0 (meshes, materials with their
subsurface extensions, lights, camera: skinlab/scene/gltf_export.py); `skinlab reference --export-xml`
writes the path tracer's scene for Mitsuba instead."""

from __future__ import annotations

import sys
from pathlib import Path

from skinlab.commands.field_options import add_command_options
from skinlab.commands.scene_options import add_scene_edit_options, scene_edits_from_args
from skinlab.declare import Field

EXPORT_OPTIONS = (Field("out", "string", "out/scene.glb", doc="output .glb or .gltf"),)


def register(sub) -> None:
    p = sub.add_parser("export", help="write a scene as glTF 2.0 (.glb or .gltf) with its materials, lights and camera")
    p.add_argument("scene", nargs="?", help="scene file (TOML) or a mesh file; default: the Lee Perry-Smith head")
    add_command_options(p, EXPORT_OPTIONS)
    add_scene_edit_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from skinlab.image_output import check_output_path
    from skinlab.scene.gltf_export import export_gltf
    from skinlab.scene.scenefile import load_scene

    out = Path(args.out)
    if out.suffix.lower() not in (".glb", ".gltf"):
        raise ValueError(f"--out: expected a .glb or .gltf path, got {out}")
    check_output_path(out.with_suffix(".png"), "--out")  # the folder is writable (before loading)
    scene = load_scene(args.scene, scene_edits_from_args(args))
    path, warnings = export_gltf(scene, out)
    for w in warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(f"wrote {path.resolve()}")
    return 0
