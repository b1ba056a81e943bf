"""Write Python/NumPy values into program uniforms; names the program lacks are skipped (the
compiler drops unused uniforms, which is not an error)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, cast

import moderngl
import numpy as np

# what a uniform is written into: a program, or a compute shader (skinlab/render/compute.py)
Shader = moderngl.Program | moderngl.ComputeShader


def set_uniform(prog: Shader, name: str, value: Any) -> bool:
    if name not in prog:
        return False
    u = cast(moderngl.Uniform, prog[name])
    if isinstance(value, np.ndarray) and value.ndim == 2 and value.shape in ((4, 4), (3, 3)):
        u.write(np.ascontiguousarray(value.T, dtype=np.float32).tobytes())  # GL is column-major
        return True
    if isinstance(value, (bytes, bytearray)):
        u.write(value)
        return True
    if isinstance(value, np.ndarray):
        value = tuple(float(x) for x in value.reshape(-1)) if value.size > 1 else float(value)
    elif isinstance(value, (list, tuple)):
        value = tuple(float(x) for x in value)
    elif isinstance(value, (bool, np.bool_)):
        value = int(value)
    u.value = value
    return True


def set_uniforms(prog: Shader, values: Mapping[str, Any]) -> None:
    for k, v in values.items():
        set_uniform(prog, k, v)


def set_array(prog: Shader, name: str, rows: np.ndarray, length: int) -> None:
    """Fill a uniform array (``vec3 name[length]`` etc.) from rows, zero-padded. The compiler may keep
    only the leading elements a variant uses; only those are written."""
    if name not in prog:
        return
    length = min(length, max(getattr(prog[name], "array_length", length), 1))
    rows = np.asarray(rows, np.float32)[:length]
    width = rows.shape[1] if rows.ndim == 2 else 1
    buf = np.zeros((length, width) if width > 1 else (length,), np.float32)
    buf[: len(rows)] = rows
    cast(moderngl.Uniform, prog[name]).write(buf.tobytes())
