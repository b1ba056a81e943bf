"""`skinlab bench orbit`: frames while the camera orbits, with and without reuse, and the plain frame."""

import json

import numpy as np
import pytest

from skinlab.bench.orbit import orbit_bench, orbit_path
from skinlab.scene.graph import CameraNode
from tests.commands.test_cli import skinlab


def test_orbit_path_circles_the_centre_at_the_camera_distance():
    cam = CameraNode("c")
    cam.look_at((1.0, 2.0, 5.0), (0, 0, 0))
    centre = np.array([0.5, 0.0, 0.0])
    poses = list(orbit_path(cam, centre, 4))
    eyes = np.array([e for e, _ in poses])
    r0 = np.linalg.norm((cam.world_position - centre)[[0, 2]])
    assert np.allclose(np.linalg.norm((eyes - centre)[:, [0, 2]], axis=1), r0)  # same distance...
    assert np.allclose(eyes[:, 1], 2.0)  # ...and height
    assert np.allclose(eyes[0], cam.world_position) and np.allclose(eyes[2] - centre, [-0.5, 2.0, -5.0])


def test_orbit_bench_times_all_modes_and_only_view_dependent_passes_run_while_orbiting():
    res = orbit_bench((32, 32), frames=2, scenes=("head",), progress=False)
    (row,) = res["scenes"]
    for m in ("orbit", "full", "plain", "plain_orbit"):
        assert row[f"{m}_ms"] > 0
    assert row["orbit_over_plain"] == pytest.approx(row["orbit_ms"] / row["plain_ms"])
    assert row["full_over_plain"] == pytest.approx(row["full_ms"] / row["plain_ms"])
    for m in ("orbit", "full", "plain", "plain_orbit"):
        assert row[f"{m}_cpu_ms"] > 0
    assert row["full_over_plain_cpu"] == pytest.approx(row["full_cpu_ms"] / row["plain_cpu_ms"])
    assert set(row["passes_cpu_ms"]["full"]) == set(row["passes_ms"]["full"])
    assert row["passes_run_while_orbiting"] == ["forward", "tonemap"]
    full = row["passes_ms"]["full"]
    assert "shadow[key]" in full and any(n.startswith("tsd_irradiance") for n in full)
    assert set(row["passes_ms"]["plain"]) == {"shadow[key]", "forward", "tonemap"}
    assert len(res["loadavg_start"]) == 3 and res["frames"] == 2


def test_orbit_cli_json_and_bad_input():
    p = skinlab("bench", "orbit", "--size", "24x24", "--frames", "1", "--scenes", "bunny", "--json", "--no-progress")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert [r["scene"] for r in d["scenes"]] == ["bunny"] and d["size"] == [24, 24]
    bad = skinlab("bench", "orbit", "--scenes", "teapot")
    assert bad.returncode == 2 and "--scenes" in bad.stderr and "Traceback" not in bad.stderr
    bad = skinlab("bench", "orbit", "--frames", "0")
    assert bad.returncode == 2 and "--frames" in bad.stderr


def test_peer_bench_reports_the_plain_frame_per_pass_and_the_prepass_in_one_run():
    from skinlab.bench.peer import peer_bench

    res = peer_bench((32, 32), frames=1)
    assert res["skinlab_ms"] > 0 and res["pyrender_ms"] > 0 and res["skinlab_no_prepass_ms"] > 0
    assert res["ratio_skinlab_over_pyrender"] == pytest.approx(res["skinlab_ms"] / res["pyrender_ms"])
    assert res["ratio_no_prepass_over_pyrender"] == pytest.approx(res["skinlab_no_prepass_ms"] / res["pyrender_ms"])
    assert set(res["skinlab_passes_ms"]) == {"forward", "tonemap", "readback"}  # the peer scene casts no shadow
    assert len(res["loadavg"]) == 3


def test_orbit_bench_has_an_environment_scene_whose_map_is_kept_while_orbiting():
    res = orbit_bench((24, 24), frames=1, scenes=("head-studio",), progress=False)
    (row,) = res["scenes"]
    assert row["passes_run_while_orbiting"] == ["forward", "tonemap"]
    full = row["passes_ms"]["full"]
    assert {"environment", "sky_occlusion", "shadow[studio:source1]"} <= set(full)
