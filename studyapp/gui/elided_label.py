"""A label that never asks for more width than a few characters: it elides its text instead.

A plain ``QLabel``'s minimum width is its text's width, so a long status or
fault text widened the whole window (the console's minimum width grew with
what it said). ``ElidedLabel`` shows as much of the text as its width allows,
ending in "…" (``QFontMetrics.elidedText``, redone on every resize and font
change); while elided, the whole text leads its tooltip; ``text()`` returns
the whole text. It prefers its text's width and shrinks to ``MIN_CHARACTERS``. It sets
the widget property ``elide`` so ``layout_check`` does not count the elision
as clipped text.
"""

from PySide6.QtCore import QEvent, QSize, Qt
from PySide6.QtWidgets import QLabel, QSizePolicy

MIN_CHARACTERS = 6  # the narrowest an elided label gets: enough to tell what it is about


class ElidedLabel(QLabel):
    def __init__(self, text="", parent=None):
        super().__init__(parent)
        self._full = ""
        self._tip = ""
        self.setProperty("elide", True)
        self.setTextFormat(Qt.TextFormat.PlainText)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Preferred)
        self.setText(text)

    def text(self):
        return self._full

    def setText(self, text):
        self._full = str(text)
        self._elide()
        self.updateGeometry()

    def setToolTip(self, tip):
        self._tip = str(tip)
        self._elide()

    def shown_text(self):
        """What the label shows now (the text, elided to its width)."""
        return super().text()

    def _elide(self):
        width = self.contentsRect().width()
        shown = self.fontMetrics().elidedText(self._full, Qt.TextElideMode.ElideRight, max(width, 0))
        super().setText(shown)
        whole = self._full if shown != self._full else ""
        super().setToolTip("\n".join(t for t in (whole, self._tip) if t))

    def resizeEvent(self, event):
        super().resizeEvent(event)
        self._elide()

    def changeEvent(self, event):
        super().changeEvent(event)
        if event.type() in (QEvent.Type.FontChange, QEvent.Type.StyleChange):
            self._elide()
            self.updateGeometry()

    def sizeHint(self):
        margins = self.contentsMargins()
        width = self.fontMetrics().horizontalAdvance(self._full) + margins.left() + margins.right() + 2
        return QSize(width, super().sizeHint().height())

    def minimumSizeHint(self):
        width = self.fontMetrics().averageCharWidth() * MIN_CHARACTERS
        return QSize(min(width, self.sizeHint().width()), super().minimumSizeHint().height())
