"""#include expansion, #line directives, error locations through includes, last-good programs."""

import pytest

from skinlab.gl.programs import ProgramCache
from skinlab.gl.shader_source import ShaderError, ShaderLibrary

VS = """#version 330 core
in vec2 in_pos;
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }
"""
FS = """#version 330 core
// a pass file
#include "lib/util.glsl"
out vec4 o;
void main() {
    o = vec4(util_value());
}
"""
UTIL = """// util
#include "skinlab/constants.glsl"
float util_value() {
    return PI * 0.0 + 1.0;
}
"""


@pytest.fixture()
def root(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "p.vert").write_text(VS)
    (tmp_path / "p.frag").write_text(FS)
    (tmp_path / "lib" / "util.glsl").write_text(UTIL)
    return tmp_path


def test_expand_inserts_line_directives_and_includes_once(root):
    (root / "lib" / "twice.glsl").write_text('#include "lib/util.glsl"\n#include "lib/util.glsl"\n')
    lib = ShaderLibrary(root=root)
    src = lib.expand("p.frag", {"HAS_MAP": "1"})
    lines = src.text.splitlines()
    assert lines[0] == "#version 330 core" and lines[1] == "#define HAS_MAP 1"
    assert "#line 1 1" in lines and "#line 4 0" in lines
    assert src.text.count("float util_value()") == 1
    assert "const float PI" in src.text  # generated constants header
    twice = lib.expand("lib/twice.glsl")
    assert twice.text.count("float util_value()") == 1


def test_missing_include_names_the_including_file(root):
    (root / "lib" / "util.glsl").write_text('#include "lib/nope.glsl"\n')
    with pytest.raises(ShaderError, match=r"lib/nope.glsl' not found \(included from .*lib/util.glsl\)"):
        ShaderLibrary(root=root).expand("p.frag")


def test_compile_error_names_included_file_and_line(ctx, root):
    (root / "lib" / "util.glsl").write_text(UTIL.replace("return PI * 0.0 + 1.0;", "return undefined_symbol;"))
    cache = ProgramCache(ctx, ShaderLibrary(root=root))
    with pytest.raises(ShaderError) as info:
        cache.get("p.vert", "p.frag")
    msg = str(info.value)
    assert f"{root.name}/lib/util.glsl:4:" in msg, msg
    assert "undefined_symbol" in msg and "4 | return undefined_symbol;" in msg
    assert (f"{root.name}/lib/util.glsl", 4) in info.value.locations


def test_error_in_pass_file_after_include(ctx, root):
    (root / "p.frag").write_text(FS.replace("o = vec4(util_value());", "o = vec4(util_value()) + bogus;"))
    with pytest.raises(ShaderError) as info:
        ProgramCache(ctx, ShaderLibrary(root=root)).get("p.vert", "p.frag")
    assert f"{root.name}/p.frag:6:" in str(info.value)


def test_reload_keeps_last_good_program_and_recovers(ctx, root):
    cache = ProgramCache(ctx, ShaderLibrary(root=root))
    good = cache.get("p.vert", "p.frag")
    util = root / "lib" / "util.glsl"
    util.write_text(UTIL.replace("1.0;", "1.0 +;"))
    errors = cache.reload({util})
    assert len(errors) == 1 and "util.glsl:4" in str(errors[0])
    assert cache.get("p.vert", "p.frag") is good  # last good stays
    util.write_text(UTIL.replace("1.0;", "2.0;"))
    assert cache.reload({util}) == []
    assert cache.get("p.vert", "p.frag") is not good
    # a file that no program includes recompiles nothing
    before = cache.compiles
    cache.reload({root / "unrelated.glsl"})
    assert cache.compiles == before
