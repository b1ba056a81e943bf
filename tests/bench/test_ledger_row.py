"""The ledger's typed row (skinlab/bench/ledger_row.py): every column declared once, written to ledger.csv
and read back equal, and listed in ledger.md and ledger.html from that one declaration."""

import math

import numpy as np
import pytest

from skinlab.bench.ledger_csv import csv_columns, csv_text, parse_csv, read_csv
from skinlab.bench.ledger_row import NUMERIC_COLUMNS, LedgerRow, columns, row_columns


def made_up_rows() -> list[LedgerRow]:
    ok = LedgerRow(
        scene="head", setting="tsd K6 512 auto", technique="tsd", model="burley",
        params={"K": 6, "tsd_size": 512, "taps": "auto", "ssss_taps": ""}, width=64, height=64, blur_levels=3,
        frames=np.int64(5), frame_ms_median=np.float64(123.456789012345), frame_ms_p10=0.1 + 0.2, frame_ms_p90=1e-300,
        clock="cpu-synchronised", image_rel_l1=float("nan"), pixels=1705, truth_rel_l1_block=0.0523,
        truth_rel_l1_block_sigma=0.0114, truth_blocks8_over=0, truth_blocks8_judged=3, ties_best="best",
        passes_ms={"shadow[key]": 37.7, "tsd_blur[0]": np.float32(1.5)},
        jackknife={"truth_rel_l1": [0.1, 0.2, float("nan")], "truth_flip": np.array([0.3, 0.4])},
    )  # fmt: skip
    failed = LedgerRow(scene="head", setting="ssss 4", technique="ssss", params={"ssss_taps": 4}, status="error",
                       error='ValueError: ssss setting taps: expected odd, got 4, "even"')  # fmt: skip
    peer = LedgerRow(scene="bunny", setting="cycles rw 4 spp", technique="blender-cycles", peer=True, samples=4,
                     first_frame_ms=math.inf, same_image_as="x, y")  # fmt: skip
    return [ok, failed, peer]


def test_a_written_csv_reads_back_equal_rows():
    rows = made_up_rows()
    text = csv_text(rows)
    back = parse_csv(text)
    assert back == rows
    assert csv_text(back) == text  # and writes the same file again
    assert math.isnan(back[1].frame_ms_median) and back[1].frames is None and back[0].param("ssss_taps") == ""
    assert back[0].param("taps") == "auto" and back[0].param("K") == 6 and back[2].peer is True
    assert back[0].jackknife["truth_flip"] == [0.3, 0.4] and back[0].passes_ms["tsd_blur[0]"] == 1.5


def test_every_column_is_declared_once_and_in_the_header():
    names = [c.name for c in columns()]
    assert len(names) == len(set(names)) and csv_columns() == names
    fields = [c.name for c in row_columns() if c.kind != "params"]
    assert set(fields) <= set(names) and "K" in names and "params" not in names
    assert all(c.doc and c.kind for c in columns())
    header = csv_text([]).splitlines()[0].split(",")
    assert header == names
    assert "frames" in NUMERIC_COLUMNS and "truth_rel_l1_block" in NUMERIC_COLUMNS and "width" not in NUMERIC_COLUMNS
    # the tables show the columns that declare a header, in their declared order
    md = [c.md for c in columns() if c.md]
    assert md[:4] == ["setting", "technique", "model", "K"] and md[-2:] == ["same image as", "status"]
    assert len([c for c in columns() if c.html]) <= 10


def test_a_row_reads_its_columns_by_name():
    ok = made_up_rows()[0]
    assert ok["frame_ms_median"] == ok.frame_ms_median and ok["K"] == 6 and ok["disk_samples"] == ""
    assert ok.get("no_such_column", "x") == "x"
    with pytest.raises(KeyError, match="no_such_column"):
        ok["no_such_column"]
    with pytest.raises(TypeError):
        LedgerRow(no_such_column=1)
    d = ok.as_dict()
    assert d["K"] == 6 and d["disk_samples"] == "" and d["passes_ms"]["shadow[key]"] == 37.7 and "params" not in d


def test_an_older_ledger_reads_and_a_wrong_file_says_so(tmp_path):
    """A ledger.csv written before the typed row (floats to 6 digits, counts as floats, no peer or jackknife
    column) still reads; a CSV that is not a ledger, or a cell that does not parse, is one line naming it."""
    old = tmp_path / "ledger.csv"
    old.write_text(
        "scene,setting,technique,model,K,tsd_size,width,frames,frame_ms_median,pixels,status,error,passes_ms\n"
        "head,tsd K6 256 auto,tsd,burley,6,256,64,5,123.457,1.70500e+03,ok,,shadow=1.234;tsd_blur=2.000\n"
        "head,none,none,none,,,64,nan,nan,nan,error,boom,\n"
    )
    a, b = read_csv(old)
    assert a.frame_ms_median == 123.457 and a.pixels == 1705 and a.param("K") == 6 and a.passes_ms["tsd_blur"] == 2.0
    assert not a.peer and a.jackknife == {} and b.frames is None and b.status == "error" and b.error == "boom"
    bad = tmp_path / "other.csv"
    bad.write_text("a,b\n1,2\n")
    with pytest.raises(ValueError, match=r"other\.csv: not a ledger \(no scene, setting, technique, status column\)"):
        read_csv(bad)
    bad.write_text("scene,setting,technique,status,frames\nhead,none,none,ok,three\n")
    with pytest.raises(ValueError, match=r"other\.csv: line 2, column frames: "):
        read_csv(bad)


def test_the_run_loops_pieces_on_made_up_frames():
    """The image reference is the exact setting where it rendered, else the proxy; every row gets its
    reference and its image error against that frame, a tsd setting also against the exact frame of its own
    irradiance size; bit-identical frames are one image (``same_image_as``)."""
    from skinlab.bench.accuracy import image_reference, same_images, with_image_errors
    from skinlab.bench.sweep import Setting

    exact, exact512 = Setting.of("exact", size=256), Setting.of("exact", size=512)
    tsd, tsd512, none = Setting.of("tsd", size=256), Setting.of("tsd", size=512, gaussians=6), Setting.of("none")
    settings = [exact, exact512, tsd, tsd512, none]
    frame = np.zeros((8, 8, 4), np.float32)
    frame[2:6, 2:6] = 1.0
    hdrs = {st: frame * (1.0 + 0.01 * i) for i, st in enumerate(settings)}
    for st in (exact, exact512):
        hdrs[st][..., 3] = 1.0
    measured = {st: LedgerRow(scene="s", setting=st.label, technique=st.technique) for st in settings}
    assert image_reference(settings, measured) == exact
    rows = with_image_errors(measured, hdrs, exact, "exact")
    by = {r.setting: r for r in rows}
    assert all(r.reference == exact.label for r in rows) and by[exact.label].image_rel_l1 == 0.0
    assert by[tsd.label].image_rel_l1 == pytest.approx(0.02, rel=1e-5)  # 1.02 against 1.00
    assert by[tsd.label].image_rel_l1_same_size == pytest.approx(0.02, rel=1e-5)  # against exact 256 itself
    assert by[tsd512.label].image_rel_l1_same_size == pytest.approx(0.02 / 1.01, rel=1e-5)  # against exact 512
    assert math.isnan(by[none.label].image_rel_l1_same_size)  # none shows no irradiance size
    failed = {**measured, exact: measured[exact].but(status="error")}
    assert image_reference(settings, failed) == tsd512  # the proxy: largest size and K
    gone = {st: r.but(status="error") for st, r in measured.items()}
    assert image_reference(settings, gone) is None
    same = same_images(rows, {exact.label: "a", tsd.label: "b", none.label: "a", tsd512.label: "b"})
    assert [r.same_image_as for r in same] == ["", "", "", tsd.label, exact.label]


def test_the_markdown_sections_say_what_the_scene_was_measured_against():
    from skinlab.bench.ledger_markdown import ranking_lines, reference_lines, scene_table

    exact = LedgerRow(
        scene="s", setting="exact 256", technique="exact", params={"tsd_size": 256}, reference="exact 256"
    )
    fine = LedgerRow(scene="s", setting="tsd K6 512 auto", technique="tsd", params={"tsd_size": 512},
                     reference="exact 256", frame_ms_median=2.0, truth_rel_l1_block=0.1, ties_best="best")  # fmt: skip
    tie = fine.but(setting="tsd K6 1024 auto", same_image_as="tsd K6 512 auto", ties_best="tie")
    text = "\n".join(reference_lines([exact, fine]))
    assert "Reference image: `exact 256`." in text and "finer irradiance texture than the reference's 256" in text
    proxy = [fine.but(reference="tsd K6 512 auto")]
    assert "**Proxy reference**" in reference_lines(proxy)[0]
    assert "**No reference image**" in reference_lines([fine.but(reference="")])[0]
    ranks = "\n".join(ranking_lines([fine, tie], [fine], "truth_rel_l1_block"))
    assert "Pareto front (time, error vs path-traced truth" in ranks and "`tsd K6 512 auto` (2.0 ms, 10.00 %)" in ranks
    assert "`tsd K6 1024 auto` = `tsd K6 512 auto`" in ranks and "cannot tell it from `tsd K6 1024 auto`" in ranks
    table = scene_table([exact, fine.but(status="error", error="a | b")])
    header = [h.strip() for h in table[0].strip("|").split("|")]
    assert header == [c.md for c in columns() if c.md] and len(table) == 4
    cells = [c.strip() for c in table[3].strip("|").split("|")]
    assert cells[0] == "tsd K6 512 auto" and cells[header.index("tsd_size")] == "512"
    assert cells[header.index("truth 4x4")] == "10.00 %" and cells[-1] == "error: a / b"


def test_the_truth_tables_skip_rows_without_a_truth():
    """A setting that failed before its truth was measured (nan) neither gives the scene's noise floor nor
    a cell; the block target table counts over / judged."""
    from skinlab.bench.truth_ledger import truth_markdown

    failed = LedgerRow(scene="a", setting="ssss 4", technique="ssss", status="error")
    ok = LedgerRow(scene="a", setting="none", technique="none", truth_rel_l1_block=0.1, truth_rel_l1_block_sigma=0.01,
                   truth_noise_block=0.02, frame_ms_median=2.0, ties_best="best", truth_blocks8_over=1,
                   truth_blocks8_judged=4)  # fmt: skip
    text = "\n".join(truth_markdown([failed, ok], {"truth": {"size": [32, 32], "spp": 16, "passes": 2}}))
    assert "| setting | a (noise 2.0 %) | mean ms (timed, 1 spp) |" in text
    assert "| ssss 4 |  |  |" in text and "| none | = 10.0 +- 1.0 % | 2.0 |" in text and "| none | 1 / 4 |" in text
