import atexit
import os
import shutil
import tempfile

import pytest

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
# derived-data caches (UV atlases) go to a folder of this test session, never the user's ~/.cache
_CACHE = tempfile.mkdtemp(prefix="skinlab-test-cache-")
os.environ["SKINLAB_CACHE_DIR"] = _CACHE
atexit.register(shutil.rmtree, _CACHE, ignore_errors=True)

from hypothesis import settings as _hyp_settings  # noqa: E402

# Local runs explore new random examples every time; CI (CI=true) is derandomised so a landing
# never depends on luck. Run `SKINLAB_HYPOTHESIS=thorough pytest` to search much harder.
_hyp_settings.register_profile("ci", max_examples=60, derandomize=True, deadline=None, print_blob=True)
_hyp_settings.register_profile("thorough", max_examples=2000, deadline=None)
_hyp_settings.register_profile("dev", max_examples=60, deadline=None, print_blob=True)
_hyp_settings.load_profile(os.environ.get("SKINLAB_HYPOTHESIS") or ("ci" if os.environ.get("CI") else "dev"))


@pytest.fixture(scope="session")
def ctx():
    from skinlab.gl.context import create_headless_context

    c = create_headless_context()
    yield c


@pytest.fixture(scope="session")
def glsl(ctx):
    from skinlab.gl.glsl_eval import GLSLEvaluator

    return GLSLEvaluator(ctx)


@pytest.fixture(scope="module")
def renderer(ctx):
    """One renderer per test module (its GPU caches are reset between modules)."""
    from skinlab.render.renderer import Renderer

    r = Renderer(ctx)
    yield r
    r.release()


@pytest.fixture
def multiple_only(monkeypatch):
    """Frames without Jensen's single-scattering term (it is local, unblurred) and without the
    multiple scattering's non-separable rest (lib/sss_boundary.glsl sss_ms_rest: local too, or spread
    by a screen-space hook): what is left is the separable multiple scattering the profile spreads."""
    import dataclasses

    import numpy as np

    import skinlab.render.boundary as render_boundary

    whole = render_boundary.material_boundary

    def without_single(material):
        t = whole(material)
        return None if t is None else dataclasses.replace(t, single=np.zeros(3))

    monkeypatch.setattr(render_boundary, "material_boundary", without_single)
    rest = render_boundary.material_ms_rest
    monkeypatch.setattr(render_boundary, "material_ms_rest", lambda material: np.zeros_like(rest(material)))
