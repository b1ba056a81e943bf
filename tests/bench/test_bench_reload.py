"""`skinlab bench reload`: runs quickly with few repeats; its JSON and text structure (timings are
measured, never asserted beyond being positive and ordered)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from skinlab.bench.reload import bench_edit, reload_bench

ROOT = Path(__file__).resolve().parents[2]
FAST = dict(size=(32, 32), shadow_size=64, tsd_size=16)


def cli(*args, timeout=120):
    env = dict(os.environ)
    return subprocess.run(
        [sys.executable, "-m", "skinlab.cli", "bench", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_edit_wraps_main_and_changes_each_time():
    frag = "#version 330 core\nout vec4 f_color;\nvoid main() {\n    f_color = vec4(1.0);\n}\n"
    a, check_a = bench_edit(frag, 0)
    b, _ = bench_edit(frag, 1)
    assert check_a and a != b
    assert "void skinlab_bench_main()" in a and a.count("void main()") == 1
    assert "f_color.rgb *= 0.5;" in a and "f_color.rgb *= 0.75;" in b
    lib, check_lib = bench_edit("float f(float x) { return x; }\n", 3)
    assert not check_lib and lib.startswith("float f(float x)") and "edit 3" in lib


def test_reload_bench_structure(ctx):
    res = reload_bench(repeats=2, settle_s=0.02, **FAST)
    assert res["file"] == "passes/tonemap.frag" and res["programs"] >= 1 and res["mode"] == "on-demand"
    assert res["check"] == "image changed" and res["repeats"] == 2 and res["size"] == [32, 32]
    for key in ("latency_ms", "reload_applied_ms", "recompile_ms", "first_frame_ms"):
        st = res[key]
        assert set(st) == {"median", "max", "min", "samples"} and len(st["samples"]) == 2
        assert 0 < st["min"] <= st["median"] <= st["max"]
    # the frame counted ends after the reload was applied, which comes after the settle time
    assert res["latency_ms"]["min"] > res["reload_applied_ms"]["min"] >= 0.02 * 1e3
    assert all(n >= 1 for n in res["frames_until_new"])


def test_reload_bench_lib_file_counts_every_dependent_program(ctx):
    res = reload_bench(repeats=1, file="lib/brdf.glsl", settle_s=0.02, mode="continuous", **FAST)
    assert res["check"] == "program recompiled" and res["programs"] >= 1 and res["mode"] == "continuous"
    assert res["frames_until_new"][0] >= 1 and res["latency_ms"]["min"] > res["reload_applied_ms"]["min"]


def test_reload_bench_cli_json_and_text(ctx, capsys):
    res = cli("reload", "--repeats", "2", "--size", "32x32", "--shadow-size", "64", "--tsd-size", "16", "--json")
    assert res.returncode == 0, res.stderr
    data = json.loads(res.stdout)
    assert data["repeats"] == 2 and len(data["latency_ms"]["samples"]) == 2 and data["gl"]
    from skinlab.cli import main

    assert (
        main(
            [
                "bench",
                "reload",
                "--repeats",
                "1",
                "--size",
                "32x32",
                "--shadow-size",
                "64",
                "--tsd-size",
                "16",
                "--settle",
                "0.02",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    for line in ("save -> first new frame", "save -> reload applied", "of which recompiling", "the first new frame"):
        assert line in out
    assert (
        "on-demand frames" in out and "1 edits of shaders/passes/tonemap.frag" in out and "check: image changed" in out
    )


@pytest.mark.parametrize(
    "args,needle",
    [
        (("--file", "passes/nope.frag"), "passes/nope.frag"),
        (("--file", "../pyproject.toml"), "../pyproject.toml"),
        (("--repeats", "0"), "--repeats"),
        (("--settle", "-1"), "--settle"),
    ],
)
def test_reload_bench_bad_input_is_one_line(args, needle):
    res = cli("reload", "--size", "16x16", *args, timeout=60)
    assert res.returncode == 2 and needle in res.stderr and "Traceback" not in res.stderr


def test_bench_peer_still_registered():
    res = cli("peer", "--help", timeout=60)
    assert res.returncode == 0 and "--frames" in res.stdout
