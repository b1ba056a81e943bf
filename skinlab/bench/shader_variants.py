"""Shader trees for cost experiments: a copy of the project's shaders with text edits applied, so a
tool can time a variant of a pass (tools/forward_cost.py, tools/irradiance_cost.py) against the
shaders as they are, in one process, interleaved."""

from __future__ import annotations

import shutil
from collections.abc import Iterable
from pathlib import Path

from skinlab.gl.shader_source import SHADER_ROOT


def apply_edits(root: Path, name: str, edits: Iterable[tuple[str, str, str]]) -> None:
    """Replace `old` by `new` in each (relative path, old, new) under `root`; a clear error naming the
    file and the variant when `old` no longer occurs (the shader changed under the tool)."""
    for rel, old, new in edits:
        f = root / rel
        text = f.read_text()
        if old not in text:
            raise SystemExit(f"{rel}: the variant {name!r} no longer matches the shader; update this tool")
        f.write_text(text.replace(old, new))


def edited_shader_root(root: Path, name: str, edits: Iterable[tuple[str, str, str]] = ()) -> Path:
    """Copy the project's shaders to `root` and apply `edits` (apply_edits); returns `root`."""
    shutil.copytree(SHADER_ROOT, root)
    apply_edits(root, name, edits)
    return root
