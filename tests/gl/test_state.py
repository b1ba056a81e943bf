"""GL state in scopes (skinlab/gl/state.py): a scope sets what its block needs and puts back the
enclosing one's, an exception included; a frame of every technique leaves the baseline behind
(moderngl cannot read the state back, so it is read from what a draw does)."""

import moderngl
import numpy as np
import pytest

from skinlab.gl.state import BASELINE, current_state, gl_state

VS = "#version 330\nin vec3 in_pos;\nvoid main() { gl_Position = vec4(in_pos, 1.0); }"
FS = "#version 330\nuniform vec4 u_color;\nout vec4 f;\nvoid main() { f = u_color; }"


def _probe(ctx) -> dict:
    """What the current state does: a red quad at depth 0 (z = 0), then a half-transparent green
    quad behind it (z = 0.5), then the green quad again at depth 0, into a cleared 4x4 target."""
    prog = ctx.program(vertex_shader=VS, fragment_shader=FS)
    out = {}
    fbo = ctx.framebuffer([ctx.texture((4, 4), 4, dtype="f4")], ctx.depth_texture((4, 4)))
    fbo.use()
    ctx.viewport = (0, 0, 4, 4)
    fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)

    def quad(z, color):
        p = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
        vbo = ctx.buffer(p.tobytes())
        vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")])
        prog["u_color"].value = color
        vao.render(moderngl.TRIANGLES)
        vao.release()
        vbo.release()
        return np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(-1, 4)[0].round(3).tolist()

    quad(0.0, (1.0, 0.0, 0.0, 1.0))
    out["behind"] = quad(0.5, (0.0, 1.0, 0.0, 0.5))  # red kept: a depth test; a mix: blending
    out["equal"] = quad(0.0, (0.0, 1.0, 0.0, 0.5))  # kept under "<", drawn under "<=" or no test
    fbo.release()
    prog.release()
    return out


BASELINE_DOES = {"behind": [0.0, 1.0, 0.0, 0.5], "equal": [0.0, 1.0, 0.0, 0.5]}  # no test, no blending


def test_scopes_nest_and_restore_even_after_an_exception(ctx):
    with gl_state(ctx):
        assert _probe(ctx) == BASELINE_DOES
        with gl_state(ctx, moderngl.DEPTH_TEST):
            assert _probe(ctx) == {"behind": [1.0, 0.0, 0.0, 1.0], "equal": [1.0, 0.0, 0.0, 1.0]}
            with gl_state(ctx, depth_func="<="):  # the depth test kept, the function changed
                assert current_state(ctx).flags == moderngl.DEPTH_TEST
                assert _probe(ctx)["equal"] == [0.0, 1.0, 0.0, 0.5]
            assert _probe(ctx)["equal"] == [1.0, 0.0, 0.0, 1.0]  # "<" again
            with pytest.raises(RuntimeError):
                with gl_state(ctx, enable=moderngl.BLEND, depth_func="1"):
                    assert _probe(ctx)["behind"] == [0.5, 0.5, 0.0, 0.75]  # blended over red
                    raise RuntimeError("mid-draw")
            assert _probe(ctx)["behind"] == [1.0, 0.0, 0.0, 1.0]  # the depth scope's state, not blending
        assert _probe(ctx) == BASELINE_DOES
    assert current_state(ctx) == BASELINE


@pytest.mark.parametrize("technique", ["tsd", "ssss", "disk", "exact", "preintegrated"])
def test_a_frame_leaves_the_baseline_state(ctx, technique):
    """Every pass runs in a baseline scope and its helpers in their own: after a frame (the depth
    pre-pass on, shadows, the technique's passes) a draw does what it does at the baseline."""
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from tests.tsd_scenes import slab_scene

    r = Renderer(ctx)
    extra = {"size": 32} if technique in ("tsd", "exact") else {}
    st = RenderSettings.for_technique(technique, 24, 24, shadow_size=64, **extra)
    r.render(slab_scene(occluder=True), st)
    assert _probe(ctx) == BASELINE_DOES
    r.release()
