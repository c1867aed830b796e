"""The GUI's analysis view (pytest-qt, offscreen): built on a report folder, its figures load."""

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from studyapp.cli import main  # noqa: E402
from tests.analysis.conftest import SYNTHETIC_FMAX, SYNTHETIC_NOISINESS  # noqa: E402

pytestmark = pytest.mark.gui


@pytest.fixture
def view(qtbot):
    from studyapp.gui.analysis_view import AnalysisView

    widget = AnalysisView()
    qtbot.addWidget(widget)
    widget.resize(900, 650)
    widget.show()
    return widget


def _tick_labels(canvas):
    return [t.get_text() for t in canvas.figure.axes[0].get_xticklabels()]


def test_view_shows_the_report_folder_figures(tmp_path, synthetic_csv, view):
    assert main(["analyse", str(synthetic_csv), "--holm", "-o", str(tmp_path / "report")]) == 0
    study = view.load(tmp_path / "report")
    assert study is not None and study.holm  # settings of the report folder are kept
    for canvas in view.canvases.values():
        canvas.draw()
        image = np.asarray(canvas.buffer_rgba())
        assert image.shape[0] > 100 and image.shape[1] > 100
        assert len(np.unique(image.reshape(-1, 4), axis=0)) > 10  # something was drawn
    fig7, fig8, fig9 = (view.canvases[n] for n in ("fig7_adjustment", "fig8_rating", "fig9_scatter"))
    assert _tick_labels(fig7) == list(study.adjustment.conditions)
    assert set(_tick_labels(fig7)) == set(SYNTHETIC_FMAX)
    assert set(_tick_labels(fig8)) == set(SYNTHETIC_NOISINESS)
    annotated = {t.get_text() for t in fig9.figure.axes[0].texts}
    assert annotated == set(SYNTHETIC_NOISINESS)  # the conditions in both tasks
    assert "P03" in view.status_label.text() and "FOAW" in view.status_label.text()
    assert "Holm-corrected" in view.tables.toHtml()


def test_view_takes_a_responses_file_and_reports_bad_input(tmp_path, synthetic_csv, view):
    assert view.load(synthetic_csv) is not None
    assert view.study.adjustment.conditions[0] == "LVT"
    (tmp_path / "bad.csv").write_text("participant,task\nP1,rating\n")
    assert view.load(tmp_path / "bad.csv") is None
    assert "missing column" in view.status_label.text()
    assert view.study.adjustment.conditions[0] == "LVT"  # the previous study stays shown
