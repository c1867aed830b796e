"""One pointer, two people (issue 31 item 5): the participant's window never covers the console's session
buttons on one screen, and the pointer stays on the participant's screen while a trial runs."""

from PySide6.QtCore import QPoint, QRect

from studyapp.gui.participant_placement import clamped, confine, place


def test_on_the_consoles_screen_the_participant_window_leaves_the_session_buttons_in_view(idle_console, qapp):
    console = idle_console
    place(console, console.screen())
    qapp.processEvents()
    p = console.participant_window
    try:
        assert not p.isFullScreen()
        left = p.frameGeometry().left()
        for button in (console.pause_button, console.stop_button, console.start_button, console.abort_button):
            right = button.mapToGlobal(QPoint(button.width(), 0)).x()
            assert right < left, (button.text(), right, left)
    finally:
        p.hide()


def test_the_pointer_is_moved_back_inside_only_while_a_trial_runs():
    rect = QRect(100, 0, 200, 100)
    assert clamped(QPoint(10, 50), rect) == QPoint(100, 50)
    assert clamped(QPoint(400, 500), rect) == QPoint(299, 99)
    assert clamped(QPoint(150, 50), rect) == QPoint(150, 50)


def test_a_window_not_shown_full_screen_confines_nothing(idle_console):
    assert not confine(idle_console.participant_window, idle_console, running=True)
