"""Hot reload under bad edits: a copy of the shader library edited the way a person mid-typing (or a
fuzzer) would. No exception other than ShaderError leaves ProgramCache.get or reload, and every
failed compile names a file of the library and a line inside it; the last good program stays."""

from __future__ import annotations

import random
import shutil
from pathlib import Path

import pytest

from skinlab.gl.programs import ProgramCache
from skinlab.gl.shader_source import SHADER_ROOT, ShaderError, ShaderLibrary

LIGHTS = {"MAX_LIGHTS": 4, "SHADOW_SLOTS": 1}
PROGRAMS = [  # a few programs whose files cover lib/, passes/ and a technique's hook
    ("passes/fullscreen.vert", "passes/tonemap.frag", {}, {}),
    ("passes/forward.vert", "passes/forward.frag", LIGHTS, {"skinlab/sss_hook.glsl": "techniques/tsd/forward.glsl"}),
    ("techniques/tsd/uv.vert", "techniques/tsd/irradiance.frag", LIGHTS, {}),
]


@pytest.fixture()
def library(ctx, tmp_path):
    root = tmp_path / "shaders"
    shutil.copytree(SHADER_ROOT, root)
    cache = ProgramCache(ctx, ShaderLibrary(root=root))
    for vs, fs, defines, includes in PROGRAMS:
        cache.get(vs, fs, defines, includes)
    yield root, cache
    cache.release()


def _assert_located(error: ShaderError, root: Path) -> None:
    """The error names at least one (file, line) of the library, and the line exists."""
    assert error.locations, str(error)
    for name, line in error.locations:
        assert name.startswith("shaders/"), (name, str(error))
        path = root / name.removeprefix("shaders/")
        assert path.is_file(), (name, str(error))
        assert 1 <= line <= len(path.read_text().splitlines()) + 1, (name, line, str(error))
        assert f"{name}:{line}:" in str(error), str(error)


def _edit(root: Path, cache: ProgramCache, rel: str, old: str, new: str) -> list[ShaderError]:
    f = root / rel
    text = f.read_text()
    assert old in text, (rel, old)
    f.write_text(text.replace(old, new, 1))
    return cache.reload({f})


def _line_of(root: Path, rel: str, piece: str) -> int:
    return next(i for i, line in enumerate((root / rel).read_text().splitlines(), 1) if piece in line)


def test_missing_include_names_the_including_line(library):
    root, cache = library
    errors = _edit(root, cache, "passes/tonemap.frag", '#include "lib/tonemap.glsl"', '#include "lib/tonemapp.glsl"')
    assert len(errors) == 1
    line = _line_of(root, "passes/tonemap.frag", "tonemapp.glsl")
    assert str(errors[0]).startswith(f"shaders/passes/tonemap.frag:{line}: shader file 'lib/tonemapp.glsl' not found")
    _assert_located(errors[0], root)


def test_mangled_include_is_a_compile_error_not_a_key_error(library):
    root, cache = library
    rel = "passes/tonemap.frag"
    errors = _edit(root, cache, rel, '#include "lib/tonemap.glsl"', '#include "lib/tonemap.glsl#include "lib/x.glsl"')
    assert len(errors) == 1 and "malformed #include" in str(errors[0])
    assert errors[0].locations == [("shaders/passes/tonemap.frag", _line_of(root, rel, "lib/x.glsl"))]
    # the edit of the issue: the include's closing quote eaten by a second include
    (root / rel).write_text(
        (root / rel).read_text().replace('"lib/tonemap.glsl#include "lib/x.glsl"', '"lib/a.glsl#include "')
    )
    errors = cache.reload({root / rel})
    assert len(errors) == 1
    _assert_located(errors[0], root)


def test_include_in_a_comment_is_left_alone(library, ctx):
    """moderngl scans the whole source for #include "..." itself; in a comment it must not see one."""
    root, cache = library
    assert (
        _edit(root, cache, "lib/color.glsl", "vec3 tonemap_aces", '// see #include "lib/other.glsl"\nvec3 tonemap_aces')
        == []
    )
    assert (
        _edit(
            root,
            cache,
            "lib/color.glsl",
            "vec3 tonemap_aces",
            '/* #include "lib/a.glsl"\n#include "lib/b.glsl" */\nvec3 tonemap_aces',
        )
        == []
    )
    # a fresh program from the edited library (ProgramCache.get, not only reload) compiles too
    fresh = ProgramCache(ctx, ShaderLibrary(root=root))
    assert fresh.get("passes/fullscreen.vert", "passes/tonemap.frag") is not None
    fresh.release()


def test_link_error_without_a_line_names_the_stage_file(library):
    root, cache = library
    errors = _edit(root, cache, "passes/fullscreen.vert", "void main()", "void mian()")
    assert len(errors) == 1 and "main" in str(errors[0])
    _assert_located(errors[0], root)


TOKENS = (
    "(", ")", ";", "{", "}", "=", "float ", "vec3 ", "@", "1.0.0", "\\", "*/", "/*", "#endif", "#if 0",
    "#define X(", '#include "lib/nope.glsl"', '#include "lib/', '// see #include "lib/other.glsl"',
)  # fmt: skip


def _random_edit(rng: random.Random, lines: list[str]) -> tuple[list[str], int]:
    """One edit (a character deleted, a token inserted, a line deleted or doubled, an include mangled)
    and the 1-based line it touched."""
    out, i = list(lines), rng.randrange(len(lines))
    kind = rng.randrange(5)
    if kind == 0 and out[i]:
        j = rng.randrange(len(out[i]))
        out[i] = out[i][:j] + out[i][j + 1 :]
    elif kind == 1:
        j = rng.randrange(len(out[i]) + 1)
        out[i] = out[i][:j] + rng.choice(TOKENS) + out[i][j:]
    elif kind == 2:
        del out[i]
    elif kind == 3:
        includes = [n for n, line in enumerate(out) if "#include" in line]
        if includes:
            i = rng.choice(includes)
            out[i] += '#include "'
    else:
        out.insert(i, out[i])
    return out, i + 1


@pytest.mark.parametrize("seed", [1, 2])
def test_random_edits_never_escape_and_always_name_file_and_line(library, seed):
    root, cache = library
    files = sorted({p for e in cache.entries.values() for p in e.deps})
    assert len(files) >= 15  # the programs above cover most of the library
    rng = random.Random(seed)
    failed = 0
    for _ in range(30):
        f = rng.choice(files)
        good = f.read_text()
        edited, _line = _random_edit(rng, good.splitlines())
        f.write_text("\n".join(edited) + "\n")
        try:
            errors = cache.reload({f})  # anything but ShaderError would escape here
        finally:
            f.write_text(good)
        for error in errors:
            failed += 1
            _assert_located(error, root)
        assert all(e.program is not None for e in cache.entries.values())  # the last good programs stay
    assert failed >= 10  # the edits do break things (the test is not vacuous)
    assert cache.reload(set(files)) == []  # the restored library compiles again
