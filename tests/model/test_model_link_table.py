"""docs/devices.md's tables are scripts/link_delay_table.py's, from its CSV (issue 29 item 1)."""

from pathlib import Path

import pytest

from tests.model.test_model_scripts import load

DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_the_docs_tables_are_the_scripts_from_its_csv():
    script = load("link_delay_table")
    rows = script.read_csv(DOCS / "link_delay_table.csv")
    assert {r["source"] for r in rows} == {"LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALLEV",
                                          "KALFOAW", "LVT", "TRUE"}
    assert all(len(r["fmax_per_seed"]) == 5 for r in rows)  # seeds 0-4
    page = (DOCS / "devices.md").read_text()
    for line in script.tables(rows).splitlines():
        if line.startswith("| link") or line.startswith("|" + " --- |"):
            continue
        assert line in page, line
    assert "![" in page and "(link_delay.png)" in page and (DOCS / "link_delay.png").exists()


def test_lvt_margin_in_the_table_is_the_prediction_functions():
    from studyapp.model.link_prediction import lvt_margin

    script = load("link_delay_table")
    rows = script.read_csv(DOCS / "link_delay_table.csv")
    ideal = {r["source"]: r["fmax_median"] for r in rows if (r["latency"], r["packet"], r["jitter"]) == (0, 0, 0)}
    assert lvt_margin(ideal) == pytest.approx(script.margin(ideal)[0])
    assert lvt_margin(ideal) >= 1.5  # the paper's effect on the ideal link
