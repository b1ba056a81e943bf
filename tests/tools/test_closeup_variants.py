"""tools/closeup_variants.py: a variant's text names render settings (lower case) and shader defines (capitals)."""

import pytest

from tools.closeup_variants import parse_variant


def test_a_variant_splits_into_settings_and_defines():
    name, settings, defines = parse_variant(
        "flat=single_through:false,through_kernel:TRUE,size:256,MEASURE_BULGE_CHORD:0.5,MEASURE_X"
    )
    assert name == "flat"
    assert settings == {"single_through": False, "through_kernel": True, "size": 256}
    assert defines == {"MEASURE_BULGE_CHORD": 0.5, "MEASURE_X": 1}
    assert parse_variant("base=") == ("base", {}, {})


@pytest.mark.parametrize("text", ["flat", "=size:2"])
def test_a_variant_without_a_name_is_refused(text):
    with pytest.raises(SystemExit, match="expected NAME=KEY:VALUE"):
        parse_variant(text)


def test_without_cached_truths_it_says_how_to_render_them(tmp_path, monkeypatch, capsys):
    from tools import closeup_variants

    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path))  # an empty cache
    assert closeup_variants.main(["ball-backlit-skin1", "tsd", "base="]) == 0
    out = capsys.readouterr().out
    assert "ball-backlit-skin1: no cached reference; render it with" in out and "skinlab reference" in out
    with pytest.raises(SystemExit, match="no close-up head-skin1-matched"):
        closeup_variants.main(["head-skin1-matched", "tsd", "base="])  # not a close-up, and no --truth
