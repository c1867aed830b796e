"""The experimenter console: one window to set up, run, watch and stop a study session.

Left: session set-up and the apparatus found, the run sheet, notes and
master volume (``SessionTools``), in a scroll area; below them, always in
view, the session's progress (its state, task, trial x of y, the current
condition), the tick that hides the condition (blinding), the page the
participant sees with the headphone level check's confirm (``PageControls``),
the session's buttons (Start, Pause/Resume, Abort, EMERGENCY STOP). Right, in tabs: the live
scope with the on-screen knobs and pads and the bowing pad; the analysis view
(``AnalysisView``) of a results folder; the session's log. Bottom: the status
bar (loop rate, load, deadline misses, audio underruns, faults, scope frame
rate). The two sides share a splitter, and no widget asks for width in
proportion to what it says (long texts wrap or elide, ``ElidedLabel``), so
the console fits a 1,366 x 768 screen.

It opens at ``PREFERRED_SIZE`` or, on a smaller screen, within the
screen's available area, maximised (``fit_screen``). None of its buttons
takes the keyboard focus (``keep_space_for_the_bow``): a focused button
would take the participant's space bar, and a space press would then pause
the session (pause is a deliberate click); a space press that reaches the
console goes to the participant's bow instead, as in the participant's
window.

*File > Quit* (Ctrl+Q) closes the console as its window's close button does.
Abort, and closing the console, while a session runs ask first (``confirm``;
``abort_session(confirm=False)``, the default, is the programmatic abort, and
``shut_down()`` closes without asking).

Its parts: ``ProgressPanel`` (progress_panel.py), ``SessionButtons``
(session_buttons.py), ``LiveTab`` (live_tab.py: scope, knobs and pads, the
bowing pad), ``SessionTools``, ``SetupPanel`` (with the device's ``DevicePanel``), ``RigCheckView`` (the
device's choice and the rig check, which asks before a session on a rig that may not show the effect),
``PageControls``, ``StatusBar``.
Every widget is a view of the ``SessionController`` (``studyapp.live``, no
Qt in it): widgets call its methods, and its events update the widgets.
Messages are coloured by their level (info, warning, error); a device's
latest warning (its ``topic``: audio, midi) is shown beside that device. A ``QTimer`` calls
``controller.poll()`` every ``POLL_PERIOD``; the poll never waits, so the UI
thread never blocks on the engine.
"""

from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction, QGuiApplication, QKeySequence
from PySide6.QtWidgets import (
    QAbstractButton,
    QCheckBox,
    QMainWindow,
    QMessageBox,
    QPlainTextEdit,
    QScrollArea,
    QSplitter,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from studyapp.engine.worker import TIMER_TAKES_OVER
from studyapp.errors import UserError
from studyapp.experiment.tasks import task_type
from studyapp.gui.analysis_view import AnalysisView
from studyapp.gui.gui_thread import GuiThreadCaller
from studyapp.gui.live_tab import LiveTab
from studyapp.gui.page_controls import PageControls
from studyapp.gui.participant_placement import confine
from studyapp.gui.participant_window import ParticipantWindow
from studyapp.gui.progress_panel import ProgressPanel
from studyapp.gui.rig_check_view import RigCheckView
from studyapp.gui.session_buttons import SessionButtons
from studyapp.gui.session_tools import SessionTools
from studyapp.gui.setup_panel import SetupPanel
from studyapp.gui.status_bar import StatusBar
from studyapp.live import rig_check
from studyapp.live.states import REST, State
from studyapp.live.simulated_session import SimulatedSession

POLL_PERIOD_MS = 10
LOG_LINES = 2000
COLOURS = {"error": "#c00", "warning": "#a60"}
MESSAGE_MS = 8000  # how long a warning stays in the status bar
LEFT_WIDTH = 360  # px: the set-up side's share of the splitter at first
PREFERRED_SIZE = (1500, 940)  # px, where the screen has room for it


class Console(QMainWindow):
    def __init__(self, controller, parent=None, predict=rig_check.predict):
        super().__init__(parent)
        self.controller = controller
        self.simulated = None
        self.replay = None  # {step: hand_trace}: the simulated participant's hand replays them (run --replay-gesture)
        self.notices = {}
        self.confirmation = None
        self._typed = None  # the session fields as typed, while a resumed session shows its own
        self._midi_shown = None
        self._engine_info = {}  # the running engine's info, its pacing as it is now
        self.caller = GuiThreadCaller(self)
        self.setWindowTitle("studyapp — experimenter console")

        self.setup = SetupPanel()
        self.setup.protocol_chosen.connect(self.choose_protocol)
        self.device_panel = self.setup.device_panel
        self.rig = RigCheckView(self, predict)  # the device's choice and the rig check (rig_check_view.py)
        self.rig_prediction = self.rig.prediction
        self.buttons = SessionButtons(controller, self.start_session, self.abort_session)
        b = self.buttons
        self.start_button, self.pause_button, self.abort_button = b.start_button, b.pause_button, b.abort_button
        self.stop_button = b.stop_button
        stop_key = QAction("Emergency stop", self)
        stop_key.setShortcut(QKeySequence(Qt.Key.Key_Escape))
        stop_key.setShortcutContext(Qt.ShortcutContext.ApplicationShortcut)
        stop_key.triggered.connect(lambda: controller.emergency_stop("operator"))
        self.addAction(stop_key)

        self.progress = ProgressPanel()  # the state, the step, the condition, the response, a pickup
        p = self.progress
        self.state_label, self.task_label, self.trial_label = p.state_label, p.task_label, p.trial_label
        self.progress_bar, self.condition_label = p.progress_bar, p.condition_label
        self.response_label, self.pickup_label = p.response_label, p.pickup_label
        self.blind = QCheckBox("Hide the condition (blinding)")
        self.blind.toggled.connect(self._blinding)
        self.page_controls = PageControls()  # the page the participant sees; the level check's confirm
        self.page_controls.confirmed.connect(lambda: controller.acknowledge_page("experimenter"))

        details = QWidget()
        dv = QVBoxLayout(details)
        dv.setContentsMargins(0, 0, 0, 0)
        dv.addWidget(self.setup)
        self.tools = SessionTools(controller, self.setup, self.blind.isChecked)  # run sheet, notes, sound
        dv.addWidget(self.tools)
        dv.addStretch(1)
        scroll = QScrollArea()
        scroll.setWidget(details)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        scroll.setMinimumWidth(details.minimumSizeHint().width() + scroll.verticalScrollBar().sizeHint().width())
        left = QWidget()
        self.left_column = left  # the set-up, progress and session buttons: never covered by the participant
        lv = QVBoxLayout(left)
        lv.addWidget(scroll, 1)
        lv.addWidget(self.progress)  # in view without scrolling: a tall rig check above never hides it
        lv.addWidget(self.blind)  # in view without scrolling, at 1,366 x 768 too
        lv.addWidget(self.page_controls)  # the level check's confirm stays in view, as the buttons do
        lv.addWidget(self.buttons)

        live = LiveTab(controller)  # the scope, the knobs and pads, the bowing pad and the hand
        self.live = live
        self.scope, self.knobs, self.bowing_pad = live.scope, live.knobs, live.bowing_pad
        self.gesture, self.bow_button = live.gesture, live.bow_button

        self.analysis = AnalysisView()
        self.log = QPlainTextEdit()
        self.log.setReadOnly(True)
        self.log.setMaximumBlockCount(LOG_LINES)
        self.tabs = QTabWidget()
        self.tabs.addTab(live, "Live")
        self.tabs.addTab(self.analysis, "Analysis")
        self.tabs.addTab(self.log, "Log")

        splitter = QSplitter()
        splitter.addWidget(left)
        splitter.addWidget(self.tabs)
        splitter.setStretchFactor(1, 1)
        splitter.setChildrenCollapsible(False)
        splitter.setSizes([LEFT_WIDTH, 1000])
        self.setCentralWidget(splitter)
        self.status = StatusBar()
        self.setStatusBar(self.status)

        self.participant_window = ParticipantWindow(controller)
        self.participant_window.knobs.knob_turned.connect(controller.knob)
        self.participant_window.knobs.pad_pressed.connect(controller.pad)
        surface = self.participant_window.surface  # the participant's bowing surface: as the bowing pad
        surface.bow_pressed.connect(controller.bow_press)
        surface.bow_moved.connect(controller.bow_move)
        surface.bow_released.connect(controller.bow_release)
        self.participant_window.page_view.continued.connect(lambda: controller.acknowledge_page("participant"))
        self.show_participant = QAction("Participant window", self, checkable=True)
        self.show_participant.toggled.connect(self.participant_window.setVisible)
        analyse = QAction("Analyse the results folder", self)
        analyse.triggered.connect(self.analyse_results)
        self.quit_action = QAction("&Quit", self)  # asks first while a session runs (closeEvent)
        self.quit_action.setShortcut(QKeySequence("Ctrl+Q"))
        self.quit_action.triggered.connect(self.close)
        self.menuBar().addMenu("&File").addAction(self.quit_action)
        view_menu = self.menuBar().addMenu("&View")
        view_menu.addAction(self.show_participant)
        view_menu.addAction(analyse)

        e = controller.events
        e.protocol.connect(self._on_protocol)
        e.engine.connect(self._on_engine)
        e.state.connect(self._on_state)
        e.trial.connect(self._on_trial)
        e.knob.connect(self._on_knob)
        e.selection.connect(self._on_selection)
        e.bowing.connect(self.live.show_bowing)
        e.gesture.connect(self.live.show_gesture)
        e.telemetry.connect(self.live.show_telemetry)
        e.status.connect(self._on_status)
        e.message.connect(self._on_message)
        e.response.connect(self._on_response)
        e.pickup.connect(self._on_pickup)
        e.page.connect(self._on_page)

        self.timer = QTimer(self)
        self.timer.setInterval(POLL_PERIOD_MS)
        self.timer.timeout.connect(self._tick)
        self.timer.start()
        self._on_state(state=controller.state)
        self.keep_space_for_the_bow()
        self.fit_screen()

    def keep_space_for_the_bow(self):
        """No button or gesture box of the console takes the keyboard focus (the set-up fields keep theirs)."""
        for widget in [*self.findChildren(QAbstractButton), self.gesture]:
            if not self.setup.isAncestorOf(widget):
                widget.setFocusPolicy(Qt.FocusPolicy.NoFocus)

    def fit_screen(self, screen=None):
        """``PREFERRED_SIZE``, or the available area of ``screen`` (default: the primary one) if smaller."""
        screen = screen or self.screen() or QGuiApplication.primaryScreen()
        area = screen.availableGeometry()
        width, height = min(PREFERRED_SIZE[0], area.width()), min(PREFERRED_SIZE[1], area.height())
        self.resize(width, height)
        self.move(area.x() + (area.width() - width) // 2, area.y() + (area.height() - height) // 2)
        small = (width, height) != PREFERRED_SIZE
        self.setWindowState(self.windowState() | Qt.WindowState.WindowMaximized if small
                            else self.windowState() & ~Qt.WindowState.WindowMaximized)

    def set_size(self, width, height):
        """``width`` x ``height`` px, not maximised (``studyapp gui --size``: offscreen too, whose screen is smaller)."""
        self.setWindowState(self.windowState() & ~Qt.WindowState.WindowMaximized)
        self.resize(width, height)

    def keyPressEvent(self, event):
        if event.key() == Qt.Key.Key_Space:  # the participant's space bar: the bow, never a button
            self.participant_window.keyPressEvent(event)
            return
        super().keyPressEvent(event)

    # actions --------------------------------------------------------------
    def choose_protocol(self, path):
        try:
            self.controller.load_protocol(path)
        except (UserError, RuntimeError) as exc:
            self.setup.show_error(str(exc))
            return False
        self.setup.select_protocol(path)
        self.setup.show_error("")
        return True

    def start_session(self, seed=None):
        logged = () if self.setup.resume.isChecked() else self.rig.accepted()
        if logged is None:
            self.setup.show_error("not started: the rig check's warning was not accepted")
            return None
        try:
            session = self.controller.start_session(
                self.setup.participant_id, self.setup.results_folder, resume=self.setup.resume.isChecked(),
                seed=seed, apparatus={"participant": "simulated" if self.setup.simulated.isChecked() else "human"},
                details=self.setup.session_info, logged=logged,
                confirm_rig=lambda question: self.confirm("Resume on another rig?", question))
        except (UserError, RuntimeError) as exc:
            self.setup.show_error(str(exc))
            return None
        self.setup.show_error("")
        self.setup.remember_results()
        if self.setup.resume.isChecked():  # the session's own values, not the placeholders (given back at its end)
            self._typed = self.setup.typed_session_info()
            self.setup.fill_session_info(**{key: session.info.get(key) for key in self._typed})
        if self.setup.simulated.isChecked():
            self.simulated = SimulatedSession(self.controller, self, self.caller, session.seed,
                                              replay=self.replay).start()
        return session

    def abort_session(self, confirm=False):
        """Abort the session; ``confirm=True`` (the Abort button) asks first. Returns whether it aborted."""
        if confirm and self.controller.in_session and not self.confirm(
                "Abort the session?", "Abort the session now? The trials done so far are kept; the rest are not run."):
            return False
        self._stop_simulated()
        self.controller.abort()
        return True

    def confirm(self, title, question):
        """Ask the experimenter a yes/no question (No is the default); ``confirmation`` is the open dialog."""
        box = QMessageBox(QMessageBox.Icon.Warning, title, question,
                          QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No, self)
        box.setDefaultButton(QMessageBox.StandardButton.No)
        self.confirmation = box
        try:
            return box.exec() == QMessageBox.StandardButton.Yes
        finally:
            self.confirmation = None
            box.deleteLater()

    def analyse_results(self):
        self.tabs.setCurrentWidget(self.analysis)
        self.analysis.load(self.setup.results_folder)

    # the controls the simulated participant uses (on the GUI thread) --------------
    def turn_knob(self, index, value):
        self.knobs.turn(index, value)

    def press_pad(self, index):
        self.knobs.press(index)

    def set_bowing(self, on):
        if self.bow_button.isChecked() == bool(on):
            self.controller.set_bowing(on)
        else:
            self.bow_button.setChecked(bool(on))

    def move_hand(self, x_m):
        """The hand's target, as the participant's bowing surface moves it."""
        self.controller.bow_move(x_m)

    def set_gesture(self, name):
        index = self.gesture.findText(name)
        self.gesture.setCurrentIndex(index)
        self.gesture.activated.emit(index)

    # the timer --------------------------------------------------------------
    def _tick(self):
        self.controller.poll()
        confine(self.participant_window, self, self.controller.state == State.RUNNING)
        self.status.show_frame_rate(self.scope.frame_rate())
        if self.simulated is not None and self.simulated.end_if_done():
            self.simulated = None

    # views of the controller's events --------------------------------------------
    def _on_protocol(self, protocol):
        self.participant_window.show_title(protocol.participant_title)  # never the aim
        self.setWindowTitle(f"studyapp — experimenter console — {protocol.title}")
        self.knobs.set_captions([])

    def _on_engine(self, state, info, config):
        if state == "starting":
            self.notices = {}
            self._midi_shown = None
        self._engine_info = dict(info) if state == "running" else {}
        self.setup.show_engine(state, info, config, self.notices)
        self.rig.engine_state(state)
        self.status.show_engine(state, info)
        if state == "running":
            self.scope.set_scene(info["rate"], info["names"])
        self._on_state(self.controller.state)

    def _on_state(self, state):
        emergency = state == State.EMERGENCY
        self.progress.show_state(state, self.controller.stop_text)
        active = self.controller.in_session
        self.buttons.show_state(state, active)
        self.setup.set_editable(not active)
        self.live.set_accepting(self.controller.accepting)
        self.participant_window.show_state(state, emergency)
        if state in REST:
            self.knobs.set_captions([])
            self.page_controls.show_none()
            if self._typed is not None:
                self.setup.fill_session_info(**self._typed)
                self._typed = None

    def _on_trial(self, trial, step, total, instructions, phase="trial", number=None, of=None):
        self.progress.show_trial(trial, step, total, phase, number, of)
        self.participant_window.show_trial(step, total, instructions, phase, number, of)
        if phase != "page":
            self.page_controls.show_none()
        self._blinding(self.blind.isChecked())

    def _on_page(self, kind, title, text, by, step, tone_hz, level_dbfs):
        self.participant_window.show_page(kind, title, text, by)
        runner = self.controller.runner
        page = runner.trial.page if runner is not None and runner.trial is not None else None
        self.page_controls.show_page(kind, title, by, tone_hz, level_dbfs, page.note if page is not None else "")

    def _on_knob(self, index, value):
        self.knobs.show_knob(index, value)
        self.participant_window.knobs.show_knob(index, value)

    def _on_selection(self, source, fmax):
        self.progress.show_selection(source, fmax)
        self._blinding(self.blind.isChecked())

    def _blinding(self, hidden):
        self.progress.show_condition(hidden)
        if self.controller.runner is not None and self.controller.runner.trial is not None:
            runner = self.controller.runner
            kind = task_type(runner.trial.task)
            self.knobs.set_captions(kind.knob_captions(runner.trial, runner.task, len(self.knobs.dials), hidden))

    def _on_status(self, status, lost, knob_latency):
        self.status.show_status(status, lost, knob_latency)
        midi = (status.get("midi"), self.notices.get("midi"))
        if midi[0] is not None and midi != self._midi_shown:  # a controller plugged in (or out)
            self._midi_shown = midi
            self.setup.show_midi(*midi)

    def _on_message(self, text, level, topic):
        if topic:
            self.notices[topic] = text
        if TIMER_TAKES_OVER in text and self._engine_info:  # the pacing line follows the clock in charge
            self._engine_info = {**self._engine_info, "paced": "timer"}
            self.setup.show_pacing("timer", text)
            self.status.show_engine("running", self._engine_info)
        self.log.appendPlainText(("[fault] " if level == "error" else "") + text)
        if level in COLOURS:
            self.status.show_message(text, MESSAGE_MS, COLOURS[level])

    def _on_pickup(self, control, index, pending, text):
        self.progress.show_pickup(control, pending, text)
        self.participant_window.show_pickup(text)

    def _on_response(self, response, step):
        self.progress.show_response(response, step)

    # closing ------------------------------------------------------------------
    def _stop_simulated(self):
        if self.simulated is not None:
            self.simulated.stop()
            self.simulated = None

    def shut_down(self):
        """Close without asking: a running session is aborted first (Ctrl-C, unattended runs, scripts)."""
        if self.controller.in_session:
            self.abort_session()
        self.close()

    def closeEvent(self, event):
        if self.controller.in_session and not self.confirm(
                "Close the console?", "A session is running. Abort it and close the console?"):
            event.ignore()
            return
        self.timer.stop()
        self.rig_prediction.cancel()
        self._stop_simulated()
        self.controller.close()
        self.participant_window.close()
        super().closeEvent(event)
