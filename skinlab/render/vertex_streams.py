"""Extra per-vertex data a technique asks for (``Technique.vertex_streams``), beyond the vertex
buffer every mesh has (position, normal, uv, tangent, colour; skinlab/render/gpu_resources.py).

A stream is computed from the mesh on the CPU and uploaded as its own buffer, only in the frames whose
technique declares it, then kept with the mesh's GPU copy until the mesh changes. A shader input the
frame does not supply reads the generic attribute value (0, 0, 0, 1)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from skinlab.scene.mesh import Mesh


@dataclass(frozen=True)
class VertexStream:
    """One vertex attribute: the shader input it feeds (``attribute``, e.g. ``in_curvature``), its
    moderngl format (``"1f"``, ``"3f"``) and ``compute(mesh)``: (vertices, components) float32."""

    attribute: str
    format: str
    compute: Callable[[Mesh], np.ndarray]
