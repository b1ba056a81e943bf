"""Work that is slow is computed once and cached by its inputs: in memory, and on disk where it is
worth it (tables that take more than about 50 ms, per-mesh data such as interreflection rays).

- :func:`table` decorates a function of hashable arguments that returns an array, a number or a
  tuple of them: one evaluation per process and arguments; with ``disk=True`` also stored under
  ``cache_dir()/tables`` keyed by the function's name, its arguments, its ``version`` and
  :func:`code_version` (an edit of the code is a new key).
- :func:`stored` does the same for data keyed by content (a mesh's arrays): the caller hashes
  what the result depends on with :func:`content_key`.

A dataclass field with ``metadata={"transient": True}`` is not stored (a process-unique id, a memo):
the rebuilt object makes it anew. Files are written to a temporary name and renamed; a file that
does not load (truncated, garbage, another layout) is discarded with a one-line warning and the
result computed again. ``BUILT`` and ``LOADED`` count, per name, the results computed and the ones
read from disk in this process, ``BUILT_S`` the seconds the computing took (the startup benchmark
reports them; a test asserts that importing the package builds nothing). ``SKINLAB_CACHE_DIR=off``
keeps everything in memory only.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib
import json
import os
import sys
import tempfile
import threading
import time
from collections import Counter, defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

__all__ = [
    "BUILT",
    "BUILT_S",
    "LOADED",
    "Memo",
    "cache_dir",
    "code_version",
    "computing",
    "content_key",
    "disk_enabled",
    "in_background",
    "parallel_map",
    "stored",
    "table",
]

BUILT: Counter[str] = Counter()
LOADED: Counter[str] = Counter()
# wall seconds spent computing each name's results (what it computes inside included: a table that builds
# another counts that one's time too; a result made on a worker thread counts there)
BUILT_S: dict[str, float] = defaultdict(float)

F = TypeVar("F", bound=Callable[..., Any])


_ACTIVE: Counter[str] = Counter()  # what is being computed now, by label (all threads)
_ACTIVE_LOCK = threading.Lock()


@contextmanager
def _working(label: str, counted: str) -> Iterator[None]:
    """``label`` listed by :func:`computing` meanwhile; the time spent counted in BUILT_S[counted]."""
    with _ACTIVE_LOCK:
        _ACTIVE[label] += 1
    start = time.perf_counter()
    try:
        yield
    finally:
        with _ACTIVE_LOCK:
            BUILT_S[counted] += time.perf_counter() - start
            _ACTIVE[label] -= 1
            if _ACTIVE[label] <= 0:
                del _ACTIVE[label]


def computing() -> list[str]:
    """The names of the tables and stored results being computed right now, on any thread (the
    viewer's overlay shows what a frame waits for)."""
    with _ACTIVE_LOCK:
        return sorted(_ACTIVE)


def cache_dir() -> Path:
    """Where derived data is cached: $SKINLAB_CACHE_DIR, else $XDG_CACHE_HOME/skinlab, else
    ~/.cache/skinlab. Deleting it is always safe."""
    env = os.environ.get("SKINLAB_CACHE_DIR")
    if env:
        return Path(env)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "skinlab"


def disk_enabled() -> bool:
    return os.environ.get("SKINLAB_CACHE_DIR", "").lower() != "off"


def content_key(*parts: Any) -> str:
    """A hex digest of bytes, arrays (dtype, shape and bytes) and other values (their repr)."""
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, bytes | bytearray | memoryview):
            h.update(b"bytes")
            h.update(p)
        elif isinstance(p, np.ndarray):
            a = np.ascontiguousarray(p)
            h.update(f"{a.dtype.str}{a.shape}".encode())
            h.update(a.tobytes())
        else:
            h.update(repr(p).encode())
        h.update(b"\x00")
    return h.hexdigest()[:32]


@functools.cache
def code_version(module_name: str) -> str:
    """A digest of the code a cached result may depend on: every module of ``skinlab.scene`` (the
    physics and the mesh code) and the module that defines the cached function. An edit to any of
    them makes new keys, so a stale table is never read (the old files are left for `cache clean`)."""
    root = Path(__file__).resolve().parent
    files = sorted((root / "scene").rglob("*.py"))
    module = sys.modules.get(module_name)
    own = getattr(module, "__file__", None)
    if own:
        files.append(Path(own))
    h = hashlib.sha256()
    for f in files:
        h.update(f.relative_to(root).as_posix().encode() if f.is_relative_to(root) else f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


# -- (de)serialising a result: arrays, numbers, strings, None, tuples/lists/dicts of them, and
# dataclasses of those (rebuilt from their init fields), as arrays plus a JSON layout ----------------


def _flatten(value: Any, out: dict[str, np.ndarray]) -> Any:
    if isinstance(value, np.ndarray):
        name = f"a{len(out)}"
        out[name] = value
        return {"a": name}
    if value is None or isinstance(value, bool | str):
        return {"v": value}
    if isinstance(value, int | np.integer):
        return {"i": int(value)}
    if isinstance(value, float | np.floating):
        return {"f": float(value).hex()}  # exact, NaN and inf included
    if isinstance(value, tuple | list):
        return {"t" if isinstance(value, tuple) else "l": [_flatten(v, out) for v in value]}
    if isinstance(value, dict) and all(isinstance(k, str) for k in value):
        return {"d": {k: _flatten(v, out) for k, v in value.items()}}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        cls = type(value)
        fields = {
            f.name: _flatten(getattr(value, f.name), out)
            for f in dataclasses.fields(value)
            if f.init and not f.metadata.get("transient")  # e.g. a process-unique id: made anew
        }
        return {"c": f"{cls.__module__}:{cls.__qualname__}", "fields": fields}
    raise TypeError(f"cache: cannot store a {type(value).__name__}")


def _unflatten(node: Any, arrays: Any) -> Any:
    if "a" in node:
        return arrays[node["a"]]
    if "v" in node:
        return node["v"]
    if "i" in node:
        return int(node["i"])
    if "f" in node:
        return float.fromhex(node["f"])
    if "t" in node:
        return tuple(_unflatten(v, arrays) for v in node["t"])
    if "l" in node:
        return [_unflatten(v, arrays) for v in node["l"]]
    if "d" in node:
        return {k: _unflatten(v, arrays) for k, v in node["d"].items()}
    module, _, qualname = node["c"].partition(":")
    cls: Any = importlib.import_module(module)
    for part in qualname.split("."):
        cls = getattr(cls, part)
    return cls(**{k: _unflatten(v, arrays) for k, v in node["fields"].items()})


def _digest(arrays: dict[str, np.ndarray], layout: str) -> str:
    return content_key(layout, *(arrays[k] for k in sorted(arrays)))


def _read(path: Path) -> Any:
    """The stored value, or raise (any reason: missing, truncated, garbage, wrong checksum)."""
    with np.load(path, allow_pickle=False) as z:
        layout = str(z["__layout__"])
        check = str(z["__digest__"])
        arrays = {k: z[k] for k in z.files if not k.startswith("__")}
    if _digest(arrays, layout) != check:
        raise ValueError("checksum mismatch")
    return _unflatten(json.loads(layout), arrays)


def _write(path: Path, value: Any) -> None:
    arrays: dict[str, np.ndarray] = {}
    layout = json.dumps(_flatten(value, arrays))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            digest = _digest(arrays, layout)
            named: dict[str, Any] = {"__layout__": np.asarray(layout), "__digest__": np.asarray(digest), **arrays}
            np.savez(f, **named)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def stored(
    kind: str,
    key: str,
    compute: Callable[[], Any],
    what: str = "",
    count_as: str | None = None,
    code: str | None = None,
    valid: Callable[[Any], bool] | None = None,
) -> Any:
    """The value cached on disk as ``cache_dir()/kind/KEY.npz``, else ``compute()`` stored there.
    ``what`` names it in the warning printed when a stored file was unusable; ``count_as`` the
    name it is counted under in BUILT / LOADED (default ``kind``); ``code`` a module name whose
    :func:`code_version` joins the key (the result depends on the code, not only on the data);
    ``valid(value)`` False for a stored value makes it a miss, computed and stored again (a cached
    mesh whose extracted textures were deleted)."""
    label = count_as or kind
    if code is not None:
        key = f"{key}-{code_version(code)}"
    if not disk_enabled():
        BUILT[label] += 1
        return compute()
    path = cache_dir() / kind / f"{key}.npz"
    if path.is_file():
        try:
            value = _read(path)
        except Exception as exc:  # noqa: BLE001 - any unusable file is made again
            print(
                f"skinlab: discarding the unusable cache file {path} ({exc}); computing {what or kind} again",
                file=sys.stderr,
            )
            path.unlink(missing_ok=True)
        else:
            if valid is None or valid(value):
                LOADED[label] += 1
                return value
    BUILT[label] += 1
    with _working(what or label, label):
        value = compute()
    try:
        _write(path, value)
    except (OSError, TypeError) as exc:  # a read-only home (or a value of a kind not stored) fails no render
        print(f"skinlab: could not cache {what or kind} in {path.parent}: {exc}", file=sys.stderr)
    return value


class Memo:
    """An in-memory cache of at most ``maxsize`` results (oldest out first) that threads share: a
    key being computed by one thread is waited for by the others, not computed twice (the viewer
    and the frame plan compute on worker threads, see skinlab/render/prepare.py)."""

    def __init__(self, maxsize: int | None = 256):
        self.maxsize = maxsize
        self._values: dict[Any, Any] = {}
        self._running: dict[Any, threading.Event] = {}
        self._lock = threading.Lock()

    def get(self, key: Any, compute: Callable[[], Any]) -> Any:
        while True:
            with self._lock:
                if key in self._values:
                    return self._values[key]
                event = self._running.get(key)
                if event is None:
                    event = self._running[key] = threading.Event()
                    break
            event.wait()  # another thread computes it; if that failed, try ourselves
        try:
            value = compute()
            with self._lock:
                if self.maxsize is not None and len(self._values) >= self.maxsize:
                    self._values.pop(next(iter(self._values)))
                self._values[key] = value
            return value
        finally:
            with self._lock:
                self._running.pop(key, None)
            event.set()

    def clear(self) -> None:
        with self._lock:
            self._values.clear()

    def __contains__(self, key: Any) -> bool:
        with self._lock:
            return key in self._values


_POOL: list[Any] = []


def in_background(fn: Callable[..., Any], *args: Any) -> Any:
    """Run ``fn(*args)`` on a worker thread (two at most) and return its Future. For work whose result
    lands in a :class:`Memo`: whoever asks for it later waits for it there; an error is raised
    again by that later call, so the Future's own is dropped."""
    from concurrent.futures import ThreadPoolExecutor

    with _POOL_LOCK:
        if not _POOL:
            _POOL.append(ThreadPoolExecutor(max_workers=2, thread_name_prefix="skinlab-prepare"))
    future = _POOL[0].submit(fn, *args)
    future.add_done_callback(lambda f: f.exception())  # retrieved: no "exception never retrieved" noise
    return future


_POOL_LOCK = threading.Lock()
_MAP_POOL: list[Any] = []


def parallel_map(fn: Callable[[Any], Any], items: list[Any]) -> list[Any]:
    """[fn(x) for x in items], the items after the first on a pool of their own (NumPy releases the
    GIL in its array loops: two cores, about twice as fast). The results are the same numbers as
    the loop's: each item is computed alone."""
    if len(items) < 2:
        return [fn(x) for x in items]
    from concurrent.futures import ThreadPoolExecutor

    with _POOL_LOCK:
        if not _MAP_POOL:
            _MAP_POOL.append(ThreadPoolExecutor(max_workers=2, thread_name_prefix="skinlab-map"))
    futures = [_MAP_POOL[0].submit(fn, x) for x in items[1:]]
    first = fn(items[0])
    return [first, *(f.result() for f in futures)]


def table(name: str | None = None, *, disk: bool = False, version: int = 1, maxsize: int | None = 256):
    """Memoise a function of hashable arguments (see the module docstring)."""

    def deco(fn: F) -> F:
        label = name or f"{fn.__module__.rpartition('.')[2]}.{fn.__name__}"
        memo = Memo(maxsize)

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            key = (args, tuple(sorted(kwargs.items())))

            def compute() -> Any:
                if not disk:
                    BUILT[label] += 1
                    with _working(label, label):
                        return fn(*args, **kwargs)
                digest = content_key(label, version, key)
                return stored(
                    "tables",
                    f"{label}-{digest}",
                    lambda: fn(*args, **kwargs),
                    label,
                    count_as=label,
                    code=fn.__module__,
                )

            return memo.get(key, compute)

        wrapper.cache_clear = memo.clear  # type: ignore[attr-defined]
        wrapper.table_name = label  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return deco
