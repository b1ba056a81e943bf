"""`skinlab profile` and `skinlab mc` command lines."""

import json

import numpy as np
import pytest

from skinlab.cli import main


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_profile_json_preset(capsys):
    rc, out, _ = run(capsys, "profile", "dipole", "--preset", "marble", "--r", "0,0.5,2", "--json")
    assert rc == 0
    d = json.loads(out)
    assert d["model"] == "dipole" and d["r_mm"] == [0.0, 0.5, 2.0]
    assert np.array(d["R"]).shape == (3, 3) and len(d["total"]) == 3
    assert d["medium"]["eta"] == 1.5


def test_profile_albedo_mfp_round_trips_colour(capsys):
    rc, out, _ = run(capsys, "profile", "burley", "--surface-albedo", "0.8,0.5,0.3", "--mfp", "1,0.5,0.2", "--json")
    d = json.loads(out)
    assert rc == 0 and np.allclose(d["total"], [0.8, 0.5, 0.3], atol=1e-3)
    assert np.allclose(d["medium"]["surface_albedo"], [0.8, 0.5, 0.3], atol=1e-3)
    rc, out, _ = run(capsys, "profile", "all", "--surface-albedo", "0.5", "--radius", "3", "--r", "1", "--json")
    assert rc == 0 and set(json.loads(out)["models"]) >= {
        "dipole",
        "burley",
        "blender-burley",
        "gaussians",
        "pbd",
        "none",
    }


@pytest.mark.parametrize(
    "argv,word",
    [
        (["profile", "pbd", "--surface-albedo", "1.5,0.5,0.5", "--mfp", "1"], "albedo"),
        (["profile", "pbd", "--surface-albedo", "0.5", "--mfp", "-1"], "mfp"),
        (["profile", "pbd", "--surface-albedo", "0.5"], "mfp"),
        (["profile", "pbd", "--preset", "jade"], "preset"),
        (["profile", "pbd", "--preset", "skin1", "--eta", "0"], "eta"),
        (["profile", "pbd", "--preset", "skin1", "--r", "1,-2"], "r"),
        (["mc", "--single-albedo", "2", "--photons", "100"], "albedo"),
        (["mc", "--single-albedo", "0.5", "--eta", "-1", "--photons", "100"], "eta"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, argv, word):
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and err.count("\n") == 1 and word in err


def test_mc_json(capsys):
    rc, out, _ = run(
        capsys,
        "mc",
        "--single-albedo",
        "0.9",
        "--eta",
        "1.3",
        "--incidence",
        "diffuse",
        "--photons",
        "3000",
        "--seed",
        "4",
        "--json",
        "--no-progress",
        "--workers",
        "1",
    )
    d = json.loads(out)
    assert rc == 0 and d["photons"] == 3000 and len(d["R"]) == len(d["r"]) == len(d["R_se"])
    assert 0 < d["total"] < 1 and d["total_se"] > 0 and d["params"]["incidence"] == "diffuse"


def test_profile_plot(tmp_path, capsys):
    p = tmp_path / "p.png"
    rc, out, _ = run(capsys, "profile", "pbd", "--preset", "skin2", "--plot", str(p), "--mc-photons", "3000")
    assert rc == 0 and p.stat().st_size > 10_000


def test_mc_table_has_units_echoes_its_parameters_and_omits_empty_outer_bins(capsys):
    rc, out, _ = run(capsys, "mc", "--single-albedo", "0.5", "--photons", "3000", "--seed", "2", "--no-progress")
    assert rc == 0
    lines = out.splitlines()
    assert lines[0].startswith(
        "Monte Carlo: single-scattering albedo 0.5, eta 1.3, g 0, normal incidence, 3000 photons, seed 2"
    )
    assert "mean free paths" in out and "R(r) (1/mfp^2)" in out
    rows = [l.split() for l in lines if l[:1] == " " and l.split()[0][0].isdigit()]
    values = np.array([[float(x) for x in r] for r in rows])
    assert values[-1, 2] > 0  # the last row listed is not a zero row
    assert "outer bins" in lines[-1] and "are zero and not listed" in lines[-1]
    # the rows are the bins' edges and agree with the JSON
    rc, js, _ = run(
        capsys, "mc", "--single-albedo", "0.5", "--photons", "3000", "--seed", "2", "--no-progress", "--json"
    )
    d = json.loads(js)
    n = len(values)
    assert np.allclose(values[:, 0], d["r_edges"][:n], rtol=1e-3) and np.allclose(values[:, 2], d["R"][:n], rtol=1e-5)
    assert all(v == 0 for v in d["R"][n:])


def test_profile_json_is_strict_with_null_and_a_reason(capsys):
    rc, out, _ = run(capsys, "profile", "all", "--surface-albedo", "0.5", "--mfp", "0", "--json")
    assert rc == 0 and "Infinity" not in out and "NaN" not in out

    def refuse(token):
        raise AssertionError(f"non-standard JSON token {token}")

    d = json.loads(out, parse_constant=refuse)
    assert d["medium"]["sigma_s_per_mm"] == [None, None, None]
    assert "medium.sigma_s_per_mm" in d["notes"]["null"] and "mean free path of 0 mm" in d["notes"]["null"]
    assert "delta" in d["notes"]["none"] and "diverges like 1/r" in d["notes"]["burley"]
    rc, out, _ = run(capsys, "profile", "all", "--preset", "skin1", "--json")
    assert "null" not in json.loads(out)["notes"]  # finite numbers: no null note


def test_profile_text_explains_none_and_the_burley_singularity(capsys):
    rc, out, _ = run(capsys, "profile", "all", "--r", "0,1")
    blocks = {b.split(":")[0].strip(): b for b in out.split("\n\n")[1:]}
    assert "note: no subsurface transport" in blocks["none"] and "surface albedo" in blocks["none"]
    assert "note: R(r) diverges like 1/r at r = 0" in blocks["burley"]
    assert "note" not in blocks["dipole"]


def test_one_meaning_per_albedo_name(capsys):
    """`--albedo` meant the single-scattering albedo in mc and the surface albedo in profile: now each
    has its own name, and the bare name is refused naming both."""
    for argv in (["mc", "--albedo", "0.5"], ["profile", "burley", "--albedo", "0.5", "--mfp", "1"]):
        with pytest.raises(SystemExit) as usage:  # a usage error, as argparse's own
            main(argv)
        rc, err = usage.value.code, capsys.readouterr().err
        assert rc == 2 and err.count("\n") == 1 and "--single-albedo" in err and "--surface-albedo" in err, err
    rc, out, _ = run(capsys, "profile", "burley", "--surface-albedo", "0.5", "--mfp", "1", "--r", "1", "--json")
    assert rc == 0 and json.loads(out)["medium"]["name"] == "custom"


def test_mc_takes_a_preset_one_walk_per_channel(capsys):
    rc, out, _ = run(
        capsys, "mc", "--preset", "skin1", "--photons", "2000", "--no-progress", "--workers", "1", "--json"
    )
    d = json.loads(out)
    assert rc == 0 and d["preset"] == "skin1" and [c["channel"] for c in d["channels"]] == ["R", "G", "B"]
    from skinlab.scene.optics.media import preset

    skin = preset("skin1")
    assert [c["params"]["albedo"] for c in d["channels"]] == pytest.approx(list(skin.alpha))
    assert [c["mfp_mm"] for c in d["channels"]] == pytest.approx(list(skin.mfp_mm))
    totals = [c["total"] for c in d["channels"]]
    assert totals[0] > totals[1] > totals[2] > 0  # skin: red reflects most
    rc, out, _ = run(capsys, "mc", "--preset", "skin1", "--photons", "2000", "--no-progress", "--workers", "1")
    assert rc == 0 and out.count("Monte Carlo: single-scattering albedo") == 3 and "channel B of skin1" in out
