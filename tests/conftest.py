import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")


@pytest.fixture(scope="session")
def ctx():
    from app.gl.context import create_headless_context

    c = create_headless_context()
    yield c


@pytest.fixture(scope="session")
def glsl(ctx):
    from app.gl.glsl_eval import GLSLEvaluator

    return GLSLEvaluator(ctx)
