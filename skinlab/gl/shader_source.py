"""GLSL source files with ``#include``, defines and exact error locations.

A pass file such as ``skinlab/shaders/passes/forward.frag`` starts with ``#version`` and may say
``#include "lib/brdf.glsl"``. :class:`ShaderLibrary` expands includes (each file once, like
``#pragma once``), inserts ``#define`` lines for the variant, and emits ``#line LINE FILE``
directives so that drivers that honour source-string numbers report the right file. An
``#extension`` line of any file moves up to just after ``#version`` (GLSL allows it only before
the first code; ``lib/shadow.glsl``'s textureGather with a compare), each distinct one once.

Mesa reports every error as source string 0, so the ``#line`` numbers alone cannot tell which
file an error is in. Each expansion therefore also keeps a table from the *flat* text (the same
text without ``#line`` directives) to (file, line); :func:`compile_error` recompiles that flat
text when a compile fails and maps its global line numbers back through the table. The result is
an error like ``shaders/lib/brdf.glsl:42: error: ...`` followed by the offending source line on
every driver (the approach of vispy's error display, with moderngl-window's include handling).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from skinlab.resources import shader_root

SHADER_ROOT = shader_root()

_INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]([^">]+)[">]\s*(//.*)?$')
_VERSION = re.compile(r"^\s*#\s*version\b")
_EXTENSION = re.compile(r"^\s*#\s*extension\b")
_INCLUDE_WORD = re.compile(r"#\s*include\b")
# Mesa: "0:12(5): error: ..."; NVIDIA: "0(12) : error C0000: ..."; AMD/Intel Windows: "ERROR: 0:12: ..."
_ERROR_LOC = [
    re.compile(r"^(?P<pre>.*?)(?P<src>\d+):(?P<line>\d+)\((?P<col>\d+)\):\s*(?P<msg>.*)$"),
    re.compile(r"^(?P<pre>.*?)(?P<src>\d+)\((?P<line>\d+)\)\s*:\s*(?P<msg>.*)$"),
    re.compile(r"^(?P<pre>ERROR:\s*|WARNING:\s*)(?P<src>\d+):(?P<line>\d+):\s*(?P<msg>.*)$"),
]


class ShaderError(Exception):
    """A shader file could not be read or compiled. ``str()`` names file and line."""

    def __init__(self, message: str, locations: list[tuple[str, int]] | None = None):
        super().__init__(message)
        self.locations = locations or []


class _NotFound(ShaderError):
    """An included file that does not exist (the include site adds its file and line)."""


def code_outside_comments(line: str, in_comment: bool) -> tuple[str, bool]:
    """The line's text outside // and /* */ comments, and whether a /* */ comment is still open at
    its end (``in_comment``: one was open at its start)."""
    if not in_comment and "/" not in line:  # most lines: nothing to strip
        return line, False
    code: list[str] = []
    i, n = 0, len(line)
    while i < n:
        if in_comment:
            end = line.find("*/", i)
            if end < 0:
                return "".join(code), True
            in_comment, i = False, end + 2
            continue
        j = line.find("/", i)
        while 0 <= j < n - 1 and line[j + 1] not in "/*":  # a division, not a comment
            j = line.find("/", j + 1)
        if j < 0 or j >= n - 1:
            code.append(line[i:])
            break
        code.append(line[i:j])
        if line[j + 1] == "/":
            break
        in_comment, i = True, j + 2
    return "".join(code), in_comment


@dataclass
class ExpandedSource:
    """One shader stage after include expansion."""

    text: str  # with #line directives: what is compiled
    flat: str  # same code without #line directives (for error mapping)
    line_map: list[tuple[int, int]]  # flat line index (0-based) -> (file index, 1-based line)
    files: list[str]  # file index -> display name
    paths: list[Path | None]  # file index -> path on disk (None for virtual files)

    def locate(self, flat_line: int) -> tuple[str, int]:
        """(file name, line) for a 1-based line number of the flat text."""
        idx = min(max(flat_line - 1, 0), len(self.line_map) - 1)
        f, ln = self.line_map[idx]
        return self.files[f], ln

    def source_line(self, file_name: str, line: int) -> str:
        i = self.files.index(file_name)
        for (f, ln), text in zip(self.line_map, self.flat.splitlines()):
            if f == i and ln == line:
                return text
        return ""


@dataclass
class ShaderLibrary:
    """Resolves shader files under ``root`` plus generated virtual files (e.g. constants). ``defines``
    adds, per pass file, defines to every variant expanded from it: the measurement variants a
    shader declares with ``#ifdef MEASURE_...`` (tools/forward_cost.py, tools/irradiance_cost.py time a
    pass with one part taken out, in a renderer of its own), never set by the renderer."""

    root: Path = SHADER_ROOT
    virtual: Mapping[str, Callable[[], str]] = field(default_factory=dict)
    defines: Mapping[str, Mapping[str, object]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.root = Path(self.root)
        if not self.virtual:
            from skinlab.scene.materials import glsl_material_uniforms
            from skinlab.scene.optics.constants import glsl_header

            self.virtual = {"skinlab/constants.glsl": glsl_header, "skinlab/material.glsl": glsl_material_uniforms}

    # -- reading -------------------------------------------------------------------------
    def display_name(self, path: Path) -> str:
        try:
            return str(Path(self.root.name) / path.resolve().relative_to(self.root.resolve()))
        except ValueError:
            return str(path)

    def _read(self, name: str, including: Path | None) -> tuple[str, Path | None, str]:
        """(text, path, display name) of an include; _NotFound (a ShaderError) naming where it looked."""
        if name in self.virtual:
            return self.virtual[name](), None, f"<{name}>"
        candidates = []
        if including is not None:
            candidates.append(including.parent / name)
        candidates.append(self.root / name)
        candidates.append(self.root / "lib" / name)
        for c in candidates:
            if c.is_file():
                try:
                    return c.read_text(encoding="utf-8"), c, self.display_name(c)
                except (OSError, UnicodeDecodeError) as exc:
                    raise ShaderError(f"{self.display_name(c)}: cannot read shader file: {exc}") from exc
        where = f" (included from {self.display_name(including)})" if including else ""
        raise _NotFound(f"shader file '{name}' not found{where}; looked in: " + ", ".join(str(c) for c in candidates))

    # -- expansion -----------------------------------------------------------------------
    def expand(
        self, name: str, defines: Mapping[str, object] | None = None, aliases: Mapping[str, str] | None = None
    ) -> ExpandedSource:
        """Expand ``name`` (relative to the shader root) with ``defines`` for its variant. ``aliases``
        map an include name to a file under the root for this expansion only: the forward pass's
        ``#include "skinlab/sss_hook.glsl"`` names the technique's hook file this way."""
        aliases = dict(aliases or {})
        defines = {**self.defines.get(name, {}), **(defines or {})}
        files: list[str] = []
        paths: list[Path | None] = []
        out: list[str] = []
        flat: list[str] = []
        line_map: list[tuple[int, int]] = []
        seen: set[str] = set()
        hoisted: list[str] = []  # the #extension lines, in the order met
        head = [0, 0]  # where they go in out and in flat: after the top file's #version

        def emit(code: str, file_idx: int, line: int) -> None:
            flat.append(code)
            line_map.append((file_idx, line))
            out.append(code)

        def hoist(code: str, file_idx: int, line: int) -> None:
            directive = " ".join(code.split())
            if directive not in hoisted:
                k = len(hoisted)
                hoisted.append(directive)
                out.insert(head[0] + k, code)
                flat.insert(head[1] + k, code)
                line_map.insert(head[1] + k, (file_idx, line))
            emit("", file_idx, line)  # the line keeps its place (the line numbers after it stay)

        def visit(fname: str, including: Path | None, include_site: tuple[int, int] | None) -> None:
            if fname in aliases:
                fname, including = aliases[fname], None
            text, path, shown = self._read(fname, including)
            key = str(path.resolve()) if path else shown
            if key in seen:
                return
            seen.add(key)
            idx = len(files)
            files.append(shown)
            paths.append(path)
            lines = text.splitlines()
            first = 0
            if include_site is None:
                # top file: #version first, then the variant's defines
                if lines and _VERSION.match(lines[0]):
                    emit(lines[0], idx, 1)
                    first = 1
                head[:] = [len(out), len(flat)]
                for k, v in defines.items():
                    emit(f"#define {k} {'' if v is True else v}".rstrip(), idx, 0)
            out.append(f"#line {first + 1} {idx}")
            in_comment = False  # inside a /* */ comment at the start of the line
            for i in range(first, len(lines)):
                code, after = code_outside_comments(lines[i], in_comment)
                m = _INCLUDE.match(lines[i]) if not in_comment else None
                in_comment = after
                if m:
                    try:
                        visit(m.group(1), path, (idx, i + 1))
                    except _NotFound as exc:
                        raise ShaderError(f"{shown}:{i + 1}: {exc}", [(shown, i + 1)]) from None
                    out.append(f"#line {i + 2} {idx}")
                    continue
                if _INCLUDE_WORD.search(code):  # an include line an edit mangled: say where, not moderngl's KeyError
                    raise ShaderError(
                        f'{shown}:{i + 1}: malformed #include (expected #include "file" alone on its line)\n'
                        f"    {i + 1:>4} | {lines[i].strip()}",
                        [(shown, i + 1)],
                    )
                if _VERSION.match(code):
                    raise ShaderError(
                        f"{shown}:{i + 1}: #version is only allowed on the first line of a pass file",
                        [(shown, i + 1)],
                    )
                if _EXTENSION.match(code):
                    hoist(code.strip(), idx, i + 1)
                    continue
                # moderngl scans the whole source for #include "..." again, comments too: defuse it there
                emit(_INCLUDE_WORD.sub("# include", lines[i]), idx, i + 1)

        visit(name, None, None)
        return ExpandedSource("\n".join(out) + "\n", "\n".join(flat) + "\n", line_map, files, paths)


def parse_errors(log: str, src: ExpandedSource, stage: str) -> tuple[str, list[tuple[str, int]]]:
    """Rewrite a driver log of the *flat* source so each line names file:line and shows the code."""
    lines_out: list[str] = []
    locs: list[tuple[str, int]] = []
    for raw in log.splitlines():
        raw = raw.rstrip()
        if not raw or set(raw) <= {"="} or raw in ("GLSL Compiler failed", "GLSL Linker failed", "Program"):
            continue
        if raw.endswith("_shader"):
            continue
        for pat in _ERROR_LOC:
            m = pat.match(raw)
            if m:
                fname, ln = src.locate(int(m.group("line")))
                locs.append((fname, ln))
                msg = m.group("msg").strip()
                lines_out.append(f"{fname}:{ln}: {msg}")
                code = src.source_line(fname, ln).strip()
                if code:
                    lines_out.append(f"    {ln:>4} | {code}")
                break
        else:
            lines_out.append(raw)
    return f"{stage} shader failed to compile:\n" + "\n".join(lines_out), locs
