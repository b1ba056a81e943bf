"""Compiled programs cached by (stage files, defines), with last-good fallback on failure: vertex +
fragment programs (:meth:`ProgramCache.get`) and compute shaders (:meth:`ProgramCache.compute`, GL 4.3;
skinlab/render/compute.py decides where they run)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import moderngl

from .shader_source import ExpandedSource, ShaderError, ShaderLibrary, parse_errors


def normalize_defines(defines: Mapping[str, object] | None) -> dict[str, str]:
    """True -> "1"; False/None dropped; everything else as its string."""
    out = {}
    for k, v in (defines or {}).items():
        if v is None or v is False:
            continue
        out[k] = "1" if v is True else str(v)
    return out


COMPUTE = "<compute>"  # the vertex-stage slot of a compute shader's key


def _key(vs: str, fs: str, defines: Mapping[str, object] | None, includes: Mapping[str, str] | None) -> tuple:
    return (vs, fs, tuple(sorted(normalize_defines(defines).items())), tuple(sorted((includes or {}).items())))


@dataclass
class ProgramEntry:
    program: moderngl.Program | moderngl.ComputeShader
    deps: set[Path] = field(default_factory=set)
    error: str | None = None  # last failed compile, if the current program is older
    generation: int = 0  # bumps on every successful (re)compile


def compile_program(
    ctx: moderngl.Context,
    library: ShaderLibrary,
    vs: str,
    fs: str,
    defines: Mapping[str, object] | None = None,
    includes: Mapping[str, str] | None = None,
) -> tuple[moderngl.Program | moderngl.ComputeShader, set[Path]]:
    """Compile one program; on failure raise :class:`ShaderError` naming file and line. ``includes``:
    include names resolved to other files for this program (ShaderLibrary.expand's aliases). With
    ``vs`` = COMPUTE, ``fs`` is a compute shader's file and the result a moderngl.ComputeShader."""
    defines = normalize_defines(defines)
    if vs == COMPUTE:
        src = library.expand(fs, defines, includes)
        deps = {p for p in src.paths if p is not None}
        try:
            return ctx.compute_shader(src.text), deps
        except moderngl.Error:
            raise _diagnose_compute(ctx, src) from None
    srcs: dict[str, ExpandedSource] = {
        "vertex_shader": library.expand(vs, defines, includes),
        "fragment_shader": library.expand(fs, defines, includes),
    }
    deps = {p for s in srcs.values() for p in s.paths if p is not None}
    try:
        prog = _program(ctx, {k: s.text for k, s in srcs.items()})
    except moderngl.Error:
        raise _diagnose(ctx, srcs) from None
    return prog, deps


def _program(ctx: moderngl.Context, stages: Mapping[str, str]) -> moderngl.Program:
    """ctx.program with the stages by keyword (vertex_shader=..., fragment_shader=...)."""
    return ctx.program(vertex_shader=stages["vertex_shader"], fragment_shader=stages["fragment_shader"])


def _diagnose(ctx: moderngl.Context, srcs: dict[str, ExpandedSource]) -> ShaderError:
    """Recompile the flat texts stage by stage to map errors to (file, line)."""
    trivial = {
        "vertex_shader": "#version 330 core\nvoid main(){ gl_Position = vec4(0.0); }\n",
        "fragment_shader": "#version 330 core\nout vec4 o;\nvoid main(){ o = vec4(0.0); }\n",
    }
    messages: list[str] = []
    locs: list[tuple[str, int]] = []
    for stage, src in srcs.items():
        other = {k: v for k, v in trivial.items() if k != stage}
        try:
            _program(ctx, {stage: src.flat, **other}).release()
        except moderngl.Error as exc:
            log = str(exc)
            if stage.split("_")[0] not in log and "link" in log.lower() and not locs:
                continue  # a link error against the trivial partner: not this stage's fault
            msg, where = parse_errors(log, src, stage.split("_")[0])
            if not where:  # a link error ("vertex shader lacks `main'") has no line: the stage's file
                where = [(src.files[0], 1)]
                msg = msg.replace(" failed to compile:\n", f" failed to compile:\n{src.files[0]}:1: ", 1)
            messages.append(msg)
            locs.extend(where)
    if not messages:
        try:
            _program(ctx, {k: s.flat for k, s in srcs.items()}).release()
            messages.append("program failed to compile, but the flat source compiles (driver issue?)")
        except moderngl.Error as exc:
            messages.append("program failed to link:\n" + str(exc).strip())
    return ShaderError("\n".join(messages), locs)


def _diagnose_compute(ctx: moderngl.Context, src: ExpandedSource) -> ShaderError:
    try:
        ctx.compute_shader(src.flat).release()
    except moderngl.Error as exc:
        msg, where = parse_errors(str(exc), src, "compute")
        return ShaderError(msg, where)
    return ShaderError("compute shader failed to compile, but the flat source compiles (driver issue?)")


class ProgramCache:
    """Programs keyed by (stage files, defines, include aliases). ``reload`` recompiles programs whose files
    changed and keeps the last good program when the new source fails."""

    def __init__(self, ctx: moderngl.Context, library: ShaderLibrary | None = None):
        self.ctx = ctx
        self.library = library or ShaderLibrary()
        self.entries: dict[tuple, ProgramEntry] = {}
        self.compiles = 0
        self.generation = 0  # bumps whenever a program is recompiled (frame reuse keys on it)

    def get(
        self,
        vs: str,
        fs: str,
        defines: Mapping[str, object] | None = None,
        includes: Mapping[str, str] | None = None,
    ) -> moderngl.Program:
        key = _key(vs, fs, defines, includes)
        entry = self.entries.get(key)
        if entry is None:
            prog, deps = compile_program(self.ctx, self.library, vs, fs, defines, includes)
            self.compiles += 1
            entry = self.entries[key] = ProgramEntry(prog, deps, None, 1)
        return cast(moderngl.Program, entry.program)  # a compute shader's entry: `compute`

    def compute(
        self, cs: str, defines: Mapping[str, object] | None = None, includes: Mapping[str, str] | None = None
    ) -> moderngl.ComputeShader:
        """The compute shader of file `cs` (a ``#version 430`` file under the shader root) for a variant;
        reloaded like the programs."""
        return cast(moderngl.ComputeShader, self.get(COMPUTE, cs, defines, includes))

    def dependents(self, changed: set[Path]) -> list[tuple]:
        changed = {Path(p).resolve() for p in changed}
        return [k for k, e in self.entries.items() if {d.resolve() for d in e.deps} & changed]

    def reload(self, changed: set[Path] | None = None) -> list[ShaderError]:
        """Recompile the programs that include any of ``changed`` (all when None)."""
        keys = list(self.entries) if changed is None else self.dependents(changed)
        errors = []
        for key in keys:
            vs, fs, defs, incs = key
            entry = self.entries[key]
            try:
                prog, deps = compile_program(self.ctx, self.library, vs, fs, dict(defs), dict(incs))
            except ShaderError as exc:
                entry.error = str(exc)
                errors.append(exc)
                continue
            self.compiles += 1
            entry.program.release()
            entry.program, entry.deps, entry.error = prog, deps, None
            entry.generation += 1
            self.generation += 1
        return errors

    def release(self) -> None:
        for e in self.entries.values():
            e.program.release()
        self.entries.clear()
