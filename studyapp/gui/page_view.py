"""A page for the participant: its title, its Markdown text, and Continue.

The text is the protocol's Markdown (``studyapp.experiment.pages``), rendered
by Qt's Markdown reader (``QTextBrowser.setMarkdown``): ``**bold**`` is bold,
a single line break (a TOML triple-quoted string's) joins the lines into one
paragraph, a blank line starts another. Large type, to be read from 60 cm.
A page the experimenter confirms (the headphone level check) shows no
Continue button, only a line saying the experimenter will go on. Continue is
clicked, never pressed with a key: it never takes the keyboard focus, so the
space bar (the participant's bow) cannot acknowledge a page.
"""

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QLabel, QPushButton, QTextBrowser, QVBoxLayout, QWidget

TEXT_PT = 18
TITLE_PT = 24
WAIT_FOR_EXPERIMENTER = "The experimenter will continue from here."


class PageView(QWidget):
    """Shows one page; ``continued`` is emitted when the participant presses Continue."""

    continued = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.kind = None
        self.title = QLabel("")
        self.title.setWordWrap(True)
        self.title.setStyleSheet(f"font-size: {TITLE_PT}pt; font-weight: bold;")
        self.text = QTextBrowser()
        self.text.setOpenExternalLinks(False)
        self.text.setFocusPolicy(Qt.FocusPolicy.NoFocus)  # the keys stay the window's (space: the bow)
        self.text.setFrameShape(QTextBrowser.Shape.NoFrame)
        font = self.text.font()
        font.setPointSize(TEXT_PT)
        self.text.setFont(font)
        self.text.document().setDefaultFont(font)
        self.continue_button = QPushButton("Continue")
        self.continue_button.setStyleSheet(f"font-size: {TEXT_PT}pt; padding: 12px 40px;")
        self.continue_button.clicked.connect(self.continued)
        # a click, never a key: a focused Continue would take the space bar, which is the bow (issue 31)
        self.continue_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.continue_button.setAutoDefault(False)
        self.waiting = QLabel(WAIT_FOR_EXPERIMENTER)
        self.waiting.setWordWrap(True)
        self.waiting.setStyleSheet(f"font-size: {TEXT_PT}pt; color: #555;")
        layout = QVBoxLayout(self)
        layout.addWidget(self.title)
        layout.addWidget(self.text, 1)
        layout.addWidget(self.continue_button, 0, Qt.AlignmentFlag.AlignRight)
        layout.addWidget(self.waiting)

    def show_page(self, kind, title, text, by):
        """Show a page: ``text`` in Markdown; ``by`` who acknowledges it (participant or experimenter)."""
        self.kind = kind
        self.title.setText(title)
        self.text.setMarkdown(text)
        participant = by == "participant"
        self.continue_button.setVisible(participant)
        self.continue_button.setEnabled(participant)
        self.waiting.setVisible(not participant)
