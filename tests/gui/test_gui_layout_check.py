"""layout_check finds what a screenshot would show cut off: widgets past the window, clipped text."""

import pytest

pytestmark = pytest.mark.gui


def _window(qapp):
    from PySide6.QtWidgets import QWidget

    window = QWidget()
    window.resize(200, 100)
    return window


def test_a_window_that_shows_everything_has_no_problems(qapp):
    from PySide6.QtWidgets import QLabel, QPushButton

    from tests.gui.layout_check import layout_problems

    window = _window(qapp)
    QLabel("short", window).setGeometry(0, 0, 150, 30)
    QPushButton("OK", window).setGeometry(100, 60, 80, 30)
    window.show()
    qapp.processEvents()
    assert layout_problems(window) == []


def test_a_widget_past_the_edge_and_a_clipped_label_are_named(qapp):
    from PySide6.QtWidgets import QLabel, QPushButton

    from tests.gui.layout_check import layout_problems

    window = _window(qapp)
    QLabel("a label far too long for the hundred and fifty pixels it has", window).setGeometry(0, 0, 150, 30)
    QPushButton("Go", window).setGeometry(180, 60, 60, 30)
    window.show()
    qapp.processEvents()
    problems = layout_problems(window)
    assert len(problems) == 2
    assert any("a label far too long" in p and "clipped" in p for p in problems)
    assert any("'Go'" in p and "extends past the window" in p for p in problems)


def test_a_wrapped_label_is_checked_by_the_height_it_needs(qapp):
    from PySide6.QtWidgets import QLabel

    from tests.gui.layout_check import layout_problems

    window = _window(qapp)
    label = QLabel("word " * 60, window)
    label.setWordWrap(True)
    label.setGeometry(0, 0, 190, 20)
    window.show()
    qapp.processEvents()
    assert [p for p in layout_problems(window) if "needs" in p and "height" in p]
    label.setGeometry(0, 0, 190, 20)
    label.setProperty("elide", True)
    assert layout_problems(window) == []
