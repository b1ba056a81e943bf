"""`skinlab scenes`: the bundled scenes, one line each: the name to give `skinlab render NAME`,
`skinlab view NAME` or ``skinlab.load(NAME)``, and what the scene is for (skinlab/resources.py)."""

from __future__ import annotations

import json

from skinlab.commands.field_options import add_command_options
from skinlab.declare import Field

SCENES_OPTIONS = (Field("json", "bool", False, doc="print name, file and summary of each as JSON"),)


def register(sub) -> None:
    p = sub.add_parser("scenes", help="list the bundled scenes (names for render, view, reference and skinlab.load)")
    add_command_options(p, SCENES_OPTIONS)
    p.set_defaults(func=run)


def run(args) -> int:
    from skinlab.resources import bundled_scenes

    scenes = bundled_scenes()
    if args.json:
        print(json.dumps([{"name": s.name, "file": str(s.path), "summary": s.summary} for s in scenes], indent=2))
        return 0
    width = max(len(s.name) for s in scenes)
    for s in scenes:
        print(f"{s.name:{width}s}  {s.summary}")
    return 0
