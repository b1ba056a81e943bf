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


def test_extension_directives_move_up_to_the_version(ctx, root):
    """An #extension in an included file (GLSL allows it only before the first code) goes just after
    #version, once however many files say it; the error locations after it stay right."""
    ext = "#extension GL_ARB_gpu_shader5 : enable"
    (root / "lib" / "util.glsl").write_text(f"// util\n{ext}  // gather\n" + UTIL.split("\n", 1)[1])
    (root / "p.frag").write_text(FS.replace('#include "lib/util.glsl"', f'#include "lib/util.glsl"\n{ext}'))
    src = ShaderLibrary(root=root).expand("p.frag", {"HAS_MAP": "1"})
    lines = src.text.splitlines()
    assert lines[:3] == ["#version 330 core", ext, "#define HAS_MAP 1"] and src.text.count("#extension") == 1
    assert src.locate(2) == (f"{root.name}/lib/util.glsl", 2)
    ProgramCache(ctx, ShaderLibrary(root=root)).get("p.vert", "p.frag")  # compiles (Mesa refuses it mid-shader)
    (root / "lib" / "util.glsl").write_text(f"// util\n{ext}\n" + UTIL.split("\n", 1)[1].replace("1.0;", "bogus;"))
    with pytest.raises(ShaderError) as info:
        ProgramCache(ctx, ShaderLibrary(root=root)).get("p.vert", "p.frag")
    assert f"{root.name}/lib/util.glsl:5:" in str(info.value), str(info.value)


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


CS = """#version 430 core
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/util.glsl"
layout(rgba32f) writeonly uniform image2D u_dst;
void main() {
    imageStore(u_dst, ivec2(gl_GlobalInvocationID.xy), vec4(util_value()));
}
"""


def test_compute_shaders_include_report_errors_and_reload(ctx, root):
    """ProgramCache.compute: includes and defines as for programs, an error names the included file
    and line, a reload keeps the last good shader and then picks up the fix."""
    import numpy as np

    (root / "p.comp").write_text(CS)
    cache = ProgramCache(ctx, ShaderLibrary(root=root))
    cs = cache.compute("p.comp")
    assert cache.compute("p.comp") is cs and "u_dst" in cs
    tex = ctx.texture((8, 8), 4, dtype="f4")
    tex.bind_to_image(0, read=False, write=True)
    cs.run(1, 1, 1)
    ctx.memory_barrier()
    assert np.allclose(np.frombuffer(tex.read(), np.float32), 1.0)
    util = root / "lib" / "util.glsl"
    util.write_text(UTIL.replace("return PI * 0.0 + 1.0;", "return undefined_symbol;"))
    errors = cache.reload({util})
    assert len(errors) == 1 and f"{root.name}/lib/util.glsl:4:" in str(errors[0]), errors
    assert "compute shader failed to compile" in str(errors[0])
    assert cache.compute("p.comp") is cs  # the last good one
    util.write_text(UTIL.replace("1.0;", "2.0;"))
    assert cache.reload({util}) == []
    cache.compute("p.comp").run(1, 1, 1)
    ctx.memory_barrier()
    assert np.allclose(np.frombuffer(tex.read(), np.float32), 2.0)
    tex.release()
    with pytest.raises(ShaderError, match=r"p2.comp:6: error: `nothing_here. undeclared"):
        (root / "p2.comp").write_text(CS.replace("vec4(util_value())", "vec4(nothing_here)"))
        cache.compute("p2.comp")


def _strip_comments_by_char(line: str, in_comment: bool) -> tuple[str, bool]:
    """A character-by-character reading of // and /* */ comments: the reference for the fast one."""
    code, i = [], 0
    while i < len(line):
        if in_comment:
            end = line.find("*/", i)
            if end < 0:
                return "".join(code), True
            in_comment, i = False, end + 2
        elif line.startswith("//", i):
            break
        elif line.startswith("/*", i):
            in_comment, i = True, i + 2
        else:
            code.append(line[i])
            i += 1
    return "".join(code), in_comment


def test_comment_stripping_matches_a_character_by_character_reading():
    """The include scanner's comment stripping (it runs on every line of every expanded stage) gives
    what reading the line a character at a time gives: divisions kept, // and /* */ removed, a /*
    comment carried into the next line."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from skinlab.gl.shader_source import code_outside_comments

    @settings(max_examples=3000, deadline=None)
    @given(st.text(alphabet="ab/* x", max_size=16), st.booleans())
    def check(line, in_comment):
        assert code_outside_comments(line, in_comment) == _strip_comments_by_char(line, in_comment)

    check()
    assert code_outside_comments("a / b // c", False) == ("a / b ", False)
    assert code_outside_comments("x /* y", False) == ("x ", True)
    assert code_outside_comments("y */ z", True) == (" z", False)
