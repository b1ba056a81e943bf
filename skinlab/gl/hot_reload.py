"""Shader hot reload: watch the shader folder, recompile only the programs that include a
changed file, keep the last good program when the new source fails.

File events come from watchdog on a background thread; they are only *collected* there. The
render thread calls :meth:`ShaderWatcher.poll` once per frame, which applies the changes that
have been quiet for ``settle_s`` (editors save in several writes; half-written files must not
win), so GL is only touched from the thread that owns the context.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

from .programs import ProgramCache
from .shader_source import ShaderError

SHADER_SUFFIXES = {".glsl", ".vert", ".frag", ".geom", ".comp"}
CHANGE_EVENTS = {"created", "modified", "moved", "deleted", "closed"}


class ShaderWatcher:
    def __init__(
        self, cache: ProgramCache, root: Path | None = None, settle_s: float = 0.05, use_watchdog: bool = True
    ):
        self.cache = cache
        self.root = Path(root or cache.library.root).resolve()
        self.settle_s = settle_s
        self._pending: dict[Path, float] = {}
        self._lock = threading.Lock()
        self._observer: Any = None  # a watchdog Observer, once started
        self.errors: list[ShaderError] = []  # errors of the last reload that failed
        self.reloads = 0
        self._mtimes = self._scan()
        if use_watchdog:
            self._start_observer()

    # -- change detection -------------------------------------------------------------
    def _scan(self) -> dict[Path, int]:
        out = {}
        for p in self.root.rglob("*"):
            if p.suffix in SHADER_SUFFIXES and p.is_file():
                try:
                    out[p.resolve()] = p.stat().st_mtime_ns
                except OSError:
                    pass
        return out

    def _start_observer(self) -> None:
        try:
            from watchdog.events import FileSystemEventHandler
            from watchdog.observers import Observer
        except ImportError:  # polling via poll(scan=True) still works
            return
        watcher = self

        class Handler(FileSystemEventHandler):
            def on_any_event(self, event):
                # only events that change content: reading a file (as a recompile does) emits
                # "opened"/"closed_no_write", which must not trigger another reload
                if event.event_type not in CHANGE_EVENTS or event.is_directory:
                    return
                for attr in ("src_path", "dest_path"):
                    p = getattr(event, attr, None)
                    if p and Path(p).suffix in SHADER_SUFFIXES:
                        watcher.notify(Path(p))

        self._observer = Observer()
        self._observer.schedule(Handler(), str(self.root), recursive=True)
        self._observer.daemon = True
        self._observer.start()

    def notify(self, path: Path) -> None:
        with self._lock:
            self._pending[Path(path).resolve()] = time.monotonic()

    def poll(self, scan: bool = False) -> list[ShaderError] | None:
        """Apply settled changes. Returns None when nothing was reloaded, else the errors (empty
        list: all recompiled). ``scan=True`` also compares modification times (no watchdog needed)."""
        if scan:
            now = self._scan()
            for p, m in now.items():
                if self._mtimes.get(p) != m:
                    self.notify(p)
            self._mtimes = now
        t = time.monotonic()
        with self._lock:
            ready = {p for p, when in self._pending.items() if t - when >= self.settle_s}
            for p in ready:
                del self._pending[p]
        if not ready:
            return None
        errors = self.cache.reload(ready)
        self.reloads += 1
        self.errors = errors
        return errors

    def stop(self) -> None:
        if self._observer is not None:
            self._observer.stop()
            self._observer.join(timeout=2)
            self._observer = None
