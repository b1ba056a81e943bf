"""A frame's slow CPU work off the caller's thread, for the viewer: the window must keep answering
while a preset, a setting or a reloaded scene needs profile fits, tables, interreflection rays or
UV seams (skinlab/cache.py keeps each once made; planning a frame is what asks for them).

:class:`FramePreparer` plans the frame on a worker thread (``plan_frame`` with no renderer state:
pure CPU, no GL) and says whether that has finished; the caller renders once it has, when the real
plan finds everything cached and costs milliseconds. Only a change other than the camera or the
window size starts a new preparation (those cost nothing to plan again). The work in progress is
named by :func:`skinlab.cache.computing` for the overlay.
"""

from __future__ import annotations

import time
from concurrent.futures import Future
from dataclasses import fields
from typing import TYPE_CHECKING

from skinlab.cache import in_background

from .plan import plan_frame

if TYPE_CHECKING:
    from skinlab.scene.graph import Scene

    from .settings import RenderSettings


class FramePreparer:
    def __init__(self) -> None:
        self._key: object = None  # what the current or last preparation was for
        self._future: Future | None = None
        self._started = 0.0

    @staticmethod
    def key(scene: Scene, settings: RenderSettings, version: object) -> object:
        """What the slow work depends on: the scene object, the caller's version of its contents
        (a counter bumped on every edit) and the settings apart from the frame size."""
        rest = tuple((f.name, getattr(settings, f.name)) for f in fields(settings) if f.name not in ("width", "height"))
        return (id(scene), version, rest)

    def ready(self, scene: Scene, settings: RenderSettings, version: object) -> bool:
        """True when the frame for (scene, settings, version) may be rendered without slow work:
        it was prepared (or is being prepared and has just finished). False starts or continues
        the preparation on a worker thread; ask again on the next iteration of the event loop."""
        key = self.key(scene, settings, version)
        if key != self._key:
            self._key, self._started = key, time.monotonic()
            self._future = in_background(plan_frame, scene, settings, None)
        return self._future is None or self._future.done()  # a failed one: the real plan reports it

    @property
    def waiting_s(self) -> float | None:
        """Seconds the current preparation has run, None when there is none running."""
        if self._future is None or self._future.done():
            return None
        return time.monotonic() - self._started
