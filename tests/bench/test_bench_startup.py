"""`skinlab bench startup` (skinlab/bench/startup.py): a fresh, a cold and a warm start, each a fresh
process, phase by phase, with what each computed and read. Its figures are printed, never asserted."""

import json

import pytest

from skinlab.cli import main


@pytest.mark.slow
def test_startup_bench_counts_what_each_start_builds_and_reads(capsys, monkeypatch):
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    assert main(["bench", "startup", "reference/slab-edge-skin1", "--size", "16x16", "--rounds", "1", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["rounds"] == 1 and res["size"] == [16, 16] and res["bytecode_cached"] is False
    for kind in ("fresh", "cold", "warm"):
        r = res[kind]
        assert r["wall_ms"] > 0 and set(r["phases_ms"]) == {
            "imports", "scene", "gl", "plan", "frame", "write"
        }  # fmt: skip
    # an empty cache builds the tables; the warm start reads what the cold one stored and builds none of them
    assert res["fresh"]["built"] and not res["fresh"]["loaded"]
    assert res["cold"]["built"] and not res["cold"]["loaded"]
    # with the time each computed name took, one entry per name (not asserted: figures)
    assert set(res["cold"]["built_ms"]) == set(res["cold"]["built"])
    assert all(v >= 0.0 for v in res["cold"]["built_ms"].values())
    assert res["warm"]["loaded"] and not set(res["warm"]["built"]) & set(res["warm"]["loaded"])


def test_startup_bench_refuses_a_bad_round_count(capsys):
    assert main(["bench", "startup", "--rounds", "0"]) == 2
    assert "--rounds" in capsys.readouterr().err


def test_the_load_average_every_benchmark_reports(monkeypatch):
    import os

    from skinlab.bench.machine_load import load_average

    got = load_average()
    assert got is not None and len(got) == 3 and all(x >= 0 and round(x, 2) == x for x in got)

    def no_load():
        raise OSError("no load average here")

    monkeypatch.setattr(os, "getloadavg", no_load)
    assert load_average() is None
