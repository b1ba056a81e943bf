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
