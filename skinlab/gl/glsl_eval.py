"""Evaluate GLSL library functions over parameter grids, for tests against NumPy twins.

Each input array becomes an RGBA32F texture (one texel per sample); a generated fragment shader
includes the library file, fetches the inputs at its texel, evaluates an expression and writes up
to four floats into an RGBA32F target, which is read back. No interpolation, no blending, so the
only differences from the NumPy twin are the GPU's fp32 arithmetic.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from pathlib import Path

import moderngl
import numpy as np

from .programs import compile_program
from .shader_source import ShaderLibrary
from .state import gl_state

_GLSL_TYPES = {1: "float", 2: "vec2", 3: "vec3", 4: "vec4"}
_SWIZZLE = {1: "x", 2: "xy", 3: "xyz", 4: "xyzw"}
_WIDTH = 256

_VS = """#version 330 core
in vec2 in_pos;
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }
"""


class GLSLEvaluator:
    """``evaluate(include, expr, inputs, out_components)`` -> ndarray (N, out_components)."""

    def __init__(self, ctx: moderngl.Context, library: ShaderLibrary | None = None):
        self.ctx = ctx
        self.library = library or ShaderLibrary()
        self._tmpdir = tempfile.TemporaryDirectory(prefix="skinlab-glsl-eval-")  # removed with the evaluator
        self._tmp = Path(self._tmpdir.name)
        (self._tmp / "eval.vert").write_text(_VS)
        self._vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], dtype="f4").tobytes())
        self._n = 0

    def evaluate(
        self,
        includes: str | list[str],
        expr: str,
        inputs: Mapping[str, np.ndarray],
        out_components: int = 1,
        prelude: str = "",
        uniforms: Mapping[str, tuple[str, object]] | None = None,
        samplers: Mapping[str, tuple[str, moderngl.Texture]] | None = None,
        setup=None,
    ) -> np.ndarray:
        """``uniforms``: name -> (GLSL type, value) shared by all samples (matrices as 4x4 arrays);
        ``samplers``: name -> (GLSL sampler type, texture) bound for the expression; ``setup``:
        called with the compiled program to set uniforms the included files declare themselves."""
        from .uniforms import set_uniform

        uniforms = uniforms or {}
        samplers = samplers or {}
        if isinstance(includes, str):
            includes = [includes]
        arrays = {}
        n = None
        for name, a in inputs.items():
            a = np.asarray(a, dtype=np.float32)
            if a.ndim == 1:
                a = a[:, None]
            if a.ndim != 2 or a.shape[1] > 4:
                raise ValueError(f"input {name!r}: expected shape (N,) or (N, 1..4), got {a.shape}")
            if n is None:
                n = a.shape[0]
            elif a.shape[0] != n:
                raise ValueError(f"input {name!r} has {a.shape[0]} samples, others have {n}")
            arrays[name] = a
        if not n:
            raise ValueError("evaluate() needs at least one non-empty input")
        w = min(n, _WIDTH)
        h = -(-n // w)
        lib_root = self.library.root.resolve()
        lines = ["#version 330 core"]
        lines += [f'#include "{inc}"' for inc in includes]
        lines += [f"uniform sampler2D u_{k};" for k in arrays]
        lines += [f"uniform {t} {k};" for k, (t, _) in uniforms.items()]
        lines += [f"uniform {t} {k};" for k, (t, _) in samplers.items()]
        lines += ["out vec4 f_out;", prelude, "void main() {", "    ivec2 p = ivec2(gl_FragCoord.xy);"]
        for k, a in arrays.items():
            c = a.shape[1]
            lines.append(f"    {_GLSL_TYPES[c]} {k} = texelFetch(u_{k}, p, 0).{_SWIZZLE[c]};")
        pad = ", ".join(["0.0"] * (4 - out_components))
        res = f"{_GLSL_TYPES[out_components]}({expr})"
        lines.append(f"    f_out = vec4({res}{', ' + pad if pad else ''});")
        lines.append("}")
        self._n += 1
        frag = self._tmp / f"eval_{self._n}.frag"
        frag.write_text("\n".join(lines) + "\n")
        lib = ShaderLibrary(root=lib_root, virtual=self.library.virtual)
        prog, _ = compile_program(self.ctx, lib, str(self._tmp / "eval.vert"), str(frag))
        textures = []
        try:
            for unit, (k, a) in enumerate(arrays.items()):
                c = a.shape[1]
                buf = np.zeros((h * w, c), np.float32)
                buf[:n] = a
                tex = self.ctx.texture((w, h), c, buf.tobytes(), dtype="f4")
                tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
                tex.use(unit)
                textures.append(tex)
                set_uniform(prog, f"u_{k}", unit)
            for unit, (k, (_, tex)) in enumerate(samplers.items(), start=len(arrays)):
                tex.use(unit)
                set_uniform(prog, k, unit)
            for k, (_, v) in uniforms.items():
                set_uniform(prog, k, v)
            if setup is not None:
                setup(prog)
            target = self.ctx.texture((w, h), 4, dtype="f4")
            fbo = self.ctx.framebuffer(color_attachments=[target])
            vao = self.ctx.vertex_array(prog, [(self._vbo, "2f", "in_pos")])
            fbo.use()
            with gl_state(self.ctx):  # nothing enabled: every fragment written as it is
                vao.render(moderngl.TRIANGLES)
            out = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(h * w, 4)
            vao.release()
            fbo.release()
            target.release()
        finally:
            for t in textures:
                t.release()
            prog.release()
        return out[:n, :out_components].astype(np.float64)


def assert_close_fp32(gpu: np.ndarray, ref: np.ndarray, rtol: float = 1e-4, atol: float = 1e-6, what: str = "") -> None:
    """GPU (fp32) vs NumPy (float64): each value within rtol relative OR atol absolute; no NaN/Inf."""
    gpu = np.asarray(gpu, np.float64)
    ref = np.asarray(ref, np.float64).reshape(gpu.shape)
    if not np.all(np.isfinite(ref)):
        raise AssertionError(f"{what}: NumPy reference has {np.sum(~np.isfinite(ref))} non-finite values")
    if not np.all(np.isfinite(gpu)):
        raise AssertionError(f"{what}: GPU result has {np.sum(~np.isfinite(gpu))} non-finite values")
    err = np.abs(gpu - ref)
    ok = (err <= atol) | (err <= rtol * np.abs(ref))
    if not ok.all():
        i = np.unravel_index(np.argmax(np.where(ok, 0, err / np.maximum(np.abs(ref), atol))), err.shape)
        raise AssertionError(
            f"{what}: {np.sum(~ok)} of {ok.size} values outside rtol={rtol} / atol={atol}; "
            f"worst at {i}: gpu={gpu[i]!r} numpy={ref[i]!r}"
        )
