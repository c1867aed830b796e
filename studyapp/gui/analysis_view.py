"""The analysis view: Figs. 7-9 and the report's tables for a study, inside the GUI.

A plain ``QWidget`` for the experimenter console to embed. ``load(path)``
takes a report folder written by ``studyapp analyse`` (same settings, so the
same figures), a results folder, or an exported responses .csv; simulated
participants are left out of the latter two unless "Include simulated
participants" is ticked (as ``analyse --include-simulated``). The figures
are drawn by ``studyapp.analysis.figures`` on matplotlib Qt canvases, so they
are the report's figures, with zoom and pan from matplotlib's toolbar. Bad
input is shown in the view's status line, never raised to the event loop.
"""

from pathlib import Path

from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg, NavigationToolbar2QT
from matplotlib.figure import Figure
from PySide6.QtWidgets import (
    QCheckBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QTabWidget,
    QTextBrowser,
    QVBoxLayout,
    QWidget,
)

from studyapp.analysis.figures import FIGURES
from studyapp.analysis.report import tables_html
from studyapp.analysis.report_folder import open_study
from studyapp.errors import UserError

TAB_TITLES = {
    "fig7_adjustment": "Fig. 7: max F_max",
    "fig8_rating": "Fig. 8: noisiness",
    "fig9_scatter": "Fig. 9: scatter",
}


class AnalysisView(QWidget):
    """Tabs with Figs. 7-9 and the tables of one study; ``load(path)`` fills them."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.study = None
        self.path = None
        self.canvases = {}
        self.include_simulated = QCheckBox("Include simulated participants")
        self.include_simulated.toggled.connect(lambda _: self.path is not None and self.load(self.path))
        self.open_button = QPushButton("Open results…")
        self.open_button.clicked.connect(self._choose_folder)
        self.source_label = QLabel("No study loaded.")
        self.status_label = QLabel("")
        self.status_label.setWordWrap(True)
        self.tabs = QTabWidget()
        for name in FIGURES:
            canvas = FigureCanvasQTAgg(Figure(figsize=(7.5, 4.8), layout="constrained"))
            page = QWidget()
            layout = QVBoxLayout(page)
            layout.addWidget(NavigationToolbar2QT(canvas, page))
            layout.addWidget(canvas)
            self.canvases[name] = canvas
            self.tabs.addTab(page, TAB_TITLES[name])
        self.tables = QTextBrowser()
        self.tabs.addTab(self.tables, "Tables")

        top = QHBoxLayout()
        top.addWidget(self.open_button)
        top.addWidget(self.source_label, 1)
        top.addWidget(self.include_simulated)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.status_label)
        layout.addWidget(self.tabs, 1)

    def load(self, path):
        """Analyse ``path`` and show it; returns the ``StudyAnalysis``, or None after showing the error."""
        self.path = path
        try:
            study = open_study(Path(path), include_simulated=self.include_simulated.isChecked())
        except UserError as exc:
            self.status_label.setText(f"Cannot analyse {path}: {exc}")
            return None
        self.study = study
        self.source_label.setText(f"{study.source}: {len(study.participants)} participants")
        warnings = study.warnings()
        self.status_label.setText(
            "Warning: " + "; ".join(warnings) if warnings else "Every participant has every expected response."
        )
        for name, canvas in self.canvases.items():
            canvas.figure.clear()
            FIGURES[name](canvas.figure, study)
            canvas.draw_idle()
        self.tables.setHtml(tables_html(study))
        return study

    def _choose_folder(self):
        folder = QFileDialog.getExistingDirectory(self, "Open a results or report folder")
        if folder:
            self.load(folder)
