"""skinlab/cache.py: results computed once, kept in memory and on disk, self-checking on load."""

from __future__ import annotations

import dataclasses
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from skinlab import cache
from skinlab.scene.mesh import Mesh


@pytest.fixture
def disk(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path))
    return tmp_path


@dataclasses.dataclass
class Record:
    table: np.ndarray
    scale: float
    name: str
    parts: tuple
    memo: list = dataclasses.field(default_factory=list, metadata={"transient": True})


def test_a_stored_value_round_trips_exactly(disk):
    value = (
        np.arange(12, dtype=np.float32).reshape(3, 4),
        [1, 2.5, float("nan"), float("inf"), None, True, "text"],
        {"a": np.zeros(0), "b": (np.int64(3), -0.0)},
        Record(np.eye(3), 1e-300, "r", (np.ones(2, np.uint8),), memo=[1, 2]),
    )
    calls = []
    first = cache.stored("kind", "key1", lambda: calls.append(1) or value)
    again = cache.stored("kind", "key1", lambda: calls.append(1) or value)
    assert calls == [1] and first is value
    arr, items, mapping, rec = again
    np.testing.assert_array_equal(arr, value[0])
    assert arr.dtype == np.float32
    assert items[:2] == [1, 2.5] and np.isnan(items[2]) and items[3] == np.inf and items[4:] == [None, True, "text"]
    assert mapping["a"].shape == (0,) and mapping["b"][0] == 3 and str(mapping["b"][1]) == "-0.0"
    assert (
        isinstance(rec, Record) and rec.scale == 1e-300 and rec.name == "r" and rec.memo == []
    )  # transient: made anew
    np.testing.assert_array_equal(rec.parts[0], np.ones(2, np.uint8))
    assert cache.LOADED["kind"] >= 1


def test_a_mesh_round_trips_with_a_new_uid(disk):
    m = Mesh("m", np.eye(3, dtype=np.float32), np.array([[0, 1, 2]]), normals=np.eye(3, dtype=np.float32))
    cache.stored("mesh", "k", lambda: m)
    back = cache.stored("mesh", "k", lambda: pytest.fail("recomputed"))
    assert back is not m and back.uid != m.uid and back.name == "m"
    np.testing.assert_array_equal(back.positions, m.positions)
    assert cache.content_key(back.positions, back.indices) == cache.content_key(m.positions, m.indices)


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty", "flip"])
def test_a_damaged_file_is_discarded_with_one_line_and_made_again(disk, capsys, damage):
    cache.stored("kind", "dmg", lambda: np.arange(1000.0))
    (path,) = (disk / "kind").glob("dmg.npz")
    data = path.read_bytes()
    if damage == "truncate":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"not a cache file" * 10)
    elif damage == "empty":
        path.write_bytes(b"")
    else:  # one value changed, the zip still valid: the checksum sees it
        import io
        import zipfile

        buf = io.BytesIO()
        with zipfile.ZipFile(io.BytesIO(data)) as zin, zipfile.ZipFile(buf, "w") as zout:
            for item in zin.infolist():
                raw = zin.read(item)
                if item.filename.startswith("a"):
                    raw = raw[:-8] + np.float64(-1.0).tobytes()
                zout.writestr(item, raw)
        path.write_bytes(buf.getvalue())
    capsys.readouterr()
    again = cache.stored("kind", "dmg", lambda: np.arange(1000.0) * 1.0)
    np.testing.assert_array_equal(again, np.arange(1000.0))
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "discarding the unusable cache file" in err and str(path) in err
    np.testing.assert_array_equal(cache.stored("kind", "dmg", lambda: pytest.fail("again")), np.arange(1000.0))


def test_temporary_files_are_never_read_and_off_writes_nothing(disk, monkeypatch):
    (disk / "kind").mkdir()
    (disk / "kind" / ".tmpkey.123.tmp").write_bytes(b"half")
    assert cache.stored("kind", "tmpkey", lambda: 7) == 7
    monkeypatch.setenv("SKINLAB_CACHE_DIR", "off")
    calls = []
    for _ in range(2):
        cache.stored("offkind", "k", lambda: calls.append(1) or 1)
    assert calls == [1, 1] and not (disk / "offkind").exists()


def test_a_value_of_a_kind_not_stored_still_returns_with_a_warning(disk, capsys):
    obj = object()
    assert cache.stored("kind", "obj", lambda: obj) is obj
    assert "could not cache" in capsys.readouterr().err


def test_table_computes_once_per_arguments_and_counts(disk):
    calls = []

    @cache.table(name="test.square", disk=True)
    def square(x: float) -> np.ndarray:
        calls.append(x)
        return np.full(3, x * x)

    before = cache.BUILT["test.square"]
    assert square(2.0)[0] == 4.0 and square(2.0)[0] == 4.0 and square(3.0)[0] == 9.0
    assert calls == [2.0, 3.0] and cache.BUILT["test.square"] == before + 2
    square.cache_clear()  # a new process: the disk has them
    assert square(2.0)[0] == 4.0 and calls == [2.0, 3.0]
    assert any(p.name.startswith("test.square-") for p in (disk / "tables").iterdir())


def test_the_code_version_is_part_of_a_tables_key(disk, monkeypatch):
    calls = []

    @cache.table(name="test.versioned", disk=True)
    def f() -> float:
        calls.append(1)
        return 1.0

    f()
    f.cache_clear()
    monkeypatch.setattr(cache, "code_version", lambda module: "edited")
    f()
    assert calls == [1, 1]  # the edited code's key is new: not the old file


def test_memo_computes_a_key_once_when_threads_ask_at_once():
    memo = cache.Memo()
    calls, results = [], []

    def slow():
        calls.append(1)
        time.sleep(0.2)
        return 42

    threads = [threading.Thread(target=lambda: results.append(memo.get("k", slow))) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert calls == [1] and results == [42] * 4


def test_memo_after_a_failure_lets_the_next_caller_try():
    memo = cache.Memo()
    with pytest.raises(ZeroDivisionError):
        memo.get("k", lambda: 1 / 0)
    assert memo.get("k", lambda: 5) == 5


def test_computing_names_the_work_in_progress(disk):
    seen = []
    cache.stored("kind", "busy", lambda: seen.append(cache.computing()) or 1, "the busy thing")
    assert seen == [["the busy thing"]] and cache.computing() == []


def test_parallel_map_equals_the_loop():
    items = list(range(7))
    assert cache.parallel_map(lambda x: np.sin(np.arange(1000.0) * x).sum(), items) == [
        np.sin(np.arange(1000.0) * x).sum() for x in items
    ]


def test_a_cached_mesh_whose_extracted_textures_were_deleted_is_loaded_again(disk, tmp_path):
    """Meshes are cached by the file's bytes (``meshes/``), the textures taken out of a GLB apart
    (``gltf/``): deleting only the textures must not leave a cached mesh naming files that are gone."""
    import shutil

    from skinlab.scene import loaders
    from tests.gltf_builder import GlbBuilder, checker

    b = GlbBuilder()
    b.quad("card", b.material(name="m", pbr={"baseColorTexture": {"index": b.image(checker(8))}}))
    glb = b.save(tmp_path / "card.glb")

    def load():
        loaders.clear_cache()  # a new process: only the disk cache is left
        return loaders.load_mesh_file(glb)[0].material.values["base_color_map"]

    first = Path(load())
    assert first.is_file() and first.parent == disk / "gltf"
    before = dict(cache.BUILT), dict(cache.LOADED)
    assert Path(load()) == first and cache.LOADED["meshes"] == before[1].get("meshes", 0) + 1  # a hit
    shutil.rmtree(disk / "gltf")
    again = Path(load())
    assert again == first and again.is_file()  # re-extracted, same content-named file
    assert cache.BUILT["meshes"] == before[0].get("meshes", 0) + 1  # the stale entry was a miss
    assert Path(load()).is_file() and cache.LOADED["meshes"] == before[1].get("meshes", 0) + 2  # and a hit again
    shutil.rmtree(disk / "gltf")  # within one process, the in-memory copy too
    assert Path(loaders.load_mesh_file(glb)[0].material.values["base_color_map"]).is_file()


def test_built_s_counts_the_seconds_a_result_took(disk):
    before = cache.BUILT_S["timed"]
    cache.stored("timed", "k", lambda: time.sleep(0.02) or np.zeros(1), count_as="timed")
    assert cache.BUILT_S["timed"] - before >= 0.02
    after = cache.BUILT_S["timed"]
    cache.stored("timed", "k", lambda: pytest.fail("recomputed"), count_as="timed")  # read, not built
    assert cache.BUILT_S["timed"] == after
