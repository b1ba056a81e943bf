"""Reload scene and preset files when they change, keeping the last good version on errors.

Same scheme as ``skinlab.gl.hot_reload.ShaderWatcher``: watchdog threads only *record* that a file
changed; the render thread calls :meth:`Reloadable.poll` each frame, which reloads once every
pending change has been quiet for ``settle_s`` (editors save in several writes, so half-written
files are not loaded while writes keep coming). Each poll also compares the files' (mtime,
size) signatures, so changes are seen even where watchdog delivers no event. A reload that fails
for any reason (bad TOML, unknown key, missing mesh, truncated file...) keeps the last good
value and records an error that names the file; a later good save recovers.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from pathlib import Path
from typing import Generic, TypeVar

log = logging.getLogger("skinlab.view")
T = TypeVar("T")
CHANGE_EVENTS = {"created", "modified", "moved", "deleted", "closed"}


def _signature(p: Path):
    try:
        st = p.stat()
    except OSError:
        return None
    return (st.st_mtime_ns, st.st_size)


class FileWatcher:
    """Collects changes to a set of files (watchdog events plus stat signatures)."""

    def __init__(self, paths, settle_s: float = 0.1, use_watchdog: bool = True):
        self.settle_s = float(settle_s)
        self._lock = threading.Lock()
        self._pending: dict[Path, float] = {}
        self._paths: set[Path] = set()
        self._sigs: dict[Path, object] = {}
        self._observer = None
        self._watched_dirs: dict[Path, object] = {}
        self._use_watchdog = use_watchdog
        self.set_paths(paths)

    @property
    def paths(self) -> set[Path]:
        return set(self._paths)

    def set_paths(self, paths) -> None:
        new = {Path(p).resolve() for p in paths}
        with self._lock:
            self._paths = new
            self._sigs = {p: self._sigs.get(p, _signature(p)) for p in new}
        if self._use_watchdog:
            self._watch_dirs({p.parent for p in new})

    def _watch_dirs(self, dirs: set[Path]) -> None:
        try:
            from watchdog.events import FileSystemEventHandler
            from watchdog.observers import Observer
        except ImportError:  # stat signatures in poll() still see every change
            return
        if self._observer is None:
            self._observer = Observer()
            self._observer.daemon = True
            self._observer.start()
        watcher = self

        class Handler(FileSystemEventHandler):
            def on_any_event(self, event):
                if event.event_type not in CHANGE_EVENTS or event.is_directory:
                    return  # reading a file (as a reload does) emits "opened"/"closed_no_write"
                for attr in ("src_path", "dest_path"):
                    p = getattr(event, attr, None)
                    if p:
                        watcher.notify(Path(p))

        for d in dirs - set(self._watched_dirs):
            if d.is_dir():
                try:
                    self._watched_dirs[d] = self._observer.schedule(Handler(), str(d), recursive=False)
                except OSError as exc:  # e.g. inotify watch limit: polling still works
                    log.warning("cannot watch %s (%s); changes are still seen by polling", d, exc)
        for d in set(self._watched_dirs) - dirs:
            self._observer.unschedule(self._watched_dirs.pop(d))

    def notify(self, path: Path) -> None:
        p = Path(path).resolve()
        with self._lock:
            if p in self._paths:
                self._pending[p] = time.monotonic()

    def poll(self) -> set[Path]:
        """Paths whose changes have settled (empty set: nothing to do yet)."""
        for p in list(self._paths):
            sig = _signature(p)
            if sig != self._sigs.get(p):
                self._sigs[p] = sig
                self.notify(p)
        now = time.monotonic()
        with self._lock:
            if not self._pending or any(now - t < self.settle_s for t in self._pending.values()):
                return set()
            ready = set(self._pending)
            self._pending.clear()
        return ready

    def stop(self) -> None:
        if self._observer is not None:
            self._observer.stop()
            self._observer.join(timeout=2)
            self._observer = None
            self._watched_dirs.clear()


class Reloadable(Generic[T]):
    """A value loaded from files that reloads when they change; the last good value survives
    failed reloads. ``load()`` returns the value; ``files(value)`` names the files it came from
    (watched from then on)."""

    def __init__(
        self,
        name: str,
        load: Callable[[], T],
        files: Callable[[T], set[Path]],
        settle_s: float = 0.1,
        watch: bool = True,
        use_watchdog: bool = True,
        background: bool = False,
    ):
        self.name = name
        self._load = load
        self._files = files
        self.value: T = load()  # the first load must succeed (the caller reports its error)
        self.error: str | None = None
        self.reloads = 0
        self.failures = 0
        self.last_changed: set[Path] = set()
        self.watcher = FileWatcher(files(self.value), settle_s, use_watchdog) if watch else None
        # background: a reload runs on a worker thread (a new mesh may need seconds of UV atlas);
        # poll() applies it on the call after it has finished, the last good value stays meanwhile
        self.background = background
        self._loading: Future | None = None

    @property
    def loading(self) -> bool:
        """A reload is running on a worker thread."""
        return self._loading is not None

    def poll(self) -> str | None:
        """'reloaded', 'failed' or None (nothing changed, or a reload still running)."""
        if self.watcher is None:
            return None
        if self._loading is not None:
            if not self._loading.done():
                return None
            job, self._loading = self._loading, None
            exc = job.exception()
            return self._failed(exc) if exc is not None else self._adopt(job.result())
        changed = self.watcher.poll()
        if not changed:
            return None
        self.last_changed = changed
        if self.background:
            from skinlab.cache import in_background

            self._loading = in_background(self._load)
            return None
        try:
            value = self._load()
        except Exception as exc:  # any failure keeps the last good value; never crash the viewer
            return self._failed(exc)
        return self._adopt(value)

    def _failed(self, exc: BaseException) -> str:
        msg = str(exc).strip() or exc.__class__.__name__
        changed = self.last_changed
        names = ", ".join(sorted(str(p) for p in changed))
        self.error = msg if any(p.name in msg for p in changed) else f"{names}: {msg}"
        self.failures += 1
        log.error("%s reload failed, keeping the last good version: %s", self.name, self.error)
        return "failed"

    def _adopt(self, value: T) -> str:
        self.value = value
        self.error = None
        self.reloads += 1
        assert self.watcher is not None
        self.watcher.set_paths(self._files(value))
        log.info("%s reloaded (%s)", self.name, ", ".join(sorted(p.name for p in self.last_changed)))
        return "reloaded"

    def stop(self) -> None:
        if self.watcher is not None:
            self.watcher.stop()


# -- what the viewer watches ------------------------------------------------------------------------


def scene_files(scene) -> set[Path]:
    """The scene file and the files it references: meshes and material textures."""
    files = {Path(scene.source)} if scene.source else set()
    for n in scene.mesh_nodes(visible_only=False):
        src = getattr(n.mesh, "source", None)
        if src:
            files.add(Path(src))
        for tex, _cs in n.material.textures().values():
            files.add(Path(tex))
    return files


def scene_reloader(
    path,
    settle_s: float = 0.1,
    watch: bool = True,
    use_watchdog: bool = True,
    background: bool = False,
    edits=None,
    prepare=None,
) -> Reloadable:
    """The scene file, reloaded when it or a file it references changes. ``edits`` (SceneEdits: the
    command line's --preset, --set, --mm-per-unit) change its data before each build and ``prepare(scene)``
    (--exposure, --environment ...) the built scene, on every reload as on the first load."""
    from skinlab.scene.scenefile import load_scene, resolve_scene_path

    path = resolve_scene_path(path)

    def load():
        scene = load_scene(path, edits)
        if prepare is not None:
            prepare(scene)
        return scene

    return Reloadable(f"scene {path}", load, scene_files, settle_s, watch, use_watchdog, background)


def load_presets() -> dict:
    """name -> Medium from the presets file, read afresh (errors name the file)."""
    from skinlab.scene.optics import media

    media.forget_presets()
    try:
        return {n: media.preset(n) for n in media.preset_names()}
    except Exception as exc:
        msg = str(exc).strip() or exc.__class__.__name__
        raise ValueError(f"{media.PRESET_FILE}: cannot read presets: {msg}") from None
    finally:
        media.forget_presets()  # a broken file must not stay cached for other users


def preset_reloader(settle_s: float = 0.1, watch: bool = True, use_watchdog: bool = True) -> Reloadable:
    from skinlab.scene.optics.media import PRESET_FILE

    return Reloadable(f"presets {PRESET_FILE}", load_presets, lambda _v: {PRESET_FILE}, settle_s, watch, use_watchdog)
