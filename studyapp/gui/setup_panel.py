"""Session set-up: who, which protocol, where results go, and what apparatus was found.

The session's information (experiment/session_info.py) is asked for here too:
the experimenter, the session number (0 shows "none"), notes, and the
Latin-square order row ("auto": from the participant's enrolment). They are
checked when the session starts; a refusal shows in the panel's error line
(below the form, wrapped to its whole height). Resuming takes only the
participant, the protocol and the results folder: with "Resume" ticked the
session's information (set when it started) is greyed and not passed on; once
the session is open the fields show its stored values (the console fills
them from session.json, and gives back what was typed when it ends).

The apparatus lines say what the engine really opened, in words: the device
(device_panel.py: simulated or a link, chosen here; its handshake, health and
the rig check), the audio output
(a PortAudio device, a WAV file, or none, and why: the engine's own notice
when it fell back to the null sink) and the MIDI input (a port, or none and
why, in which case the on-screen knobs are the controls; or none yet, when
the engine waits for a controller to be plugged in: ``show_midi`` follows
the engine's status as it arrives).

The results folder is shown absolute and remembered on this machine
(``QSettings`` "studyapp", key ``results/folder``) when a session starts in
it; a new console starts with it (else with the command line's default,
experiment/results_folder.py), whatever folder it was started from.
"""

from pathlib import Path

from PySide6.QtCore import QSettings, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from studyapp.experiment.results_folder import absolute, default_results
from studyapp.gui.device_panel import DevicePanel

RESULTS_KEY = "results/folder"


def remembered_results():
    """The results folder this machine used last (``QSettings`` key ``results/folder``), else the default."""
    value = QSettings("studyapp", "studyapp").value(RESULTS_KEY)
    return str(absolute(value)) if isinstance(value, str) and value else str(default_results())


def find_protocols(folder="protocols"):
    """The ``.toml`` files in ``folder`` (relative to the working folder), sorted."""
    folder = Path(folder)
    return sorted(str(p) for p in folder.glob("*.toml")) if folder.is_dir() else []


class SetupPanel(QWidget):
    protocol_chosen = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self._editable = True
        self._tips = {}  # a session field -> its own tooltip (while resuming it says why it is greyed)
        self.participant = QLineEdit()
        self.participant.setPlaceholderText("pseudonym, e.g. P07")
        self.protocol = QComboBox()
        self.protocol.setEditable(False)
        self.protocol.setMinimumContentsLength(18)
        # a long path must not widen the console: the list shows it whole, the box elides
        self.protocol.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        for path in find_protocols():
            self.protocol.addItem(path)
        self.protocol.activated.connect(lambda index: self.protocol_chosen.emit(self.protocol.itemText(index)))
        browse = QPushButton("…")
        browse.setToolTip("choose a protocol file")
        browse.setFixedWidth(28)
        browse.clicked.connect(self._browse_protocol)
        self.results = QLineEdit(remembered_results())
        results_browse = QPushButton("…")
        results_browse.setFixedWidth(28)
        results_browse.setToolTip("choose the results folder")
        results_browse.clicked.connect(self._browse_results)
        self.experimenter = QLineEdit()
        self.experimenter.setPlaceholderText("who runs the session")
        self.session_number = QSpinBox()
        self.session_number.setRange(0, 999)
        self.session_number.setSpecialValueText("none")
        self.notes = QLineEdit()
        self.notes.setMaxLength(2000)
        self.notes.setPlaceholderText("notes on this session (optional)")
        self.order_row = QSpinBox()
        self.order_row.setRange(-1, 999)
        self.order_row.setSpecialValueText("auto")
        self.order_row.setValue(-1)
        self.order_row.setToolTip("the Latin-square order row, from 0; auto: from the participant's enrolment")
        self.resume = QCheckBox("Resume the participant's unfinished session")
        self.simulated = QCheckBox("Simulated participant plays")
        self.error = QLabel("")
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #c00;")

        protocol_row = QHBoxLayout()
        protocol_row.addWidget(self.protocol, 1)
        protocol_row.addWidget(browse)
        results_row = QHBoxLayout()
        results_row.addWidget(self.results, 1)
        results_row.addWidget(results_browse)
        session = QGroupBox("Session set-up")
        form = QFormLayout(session)
        form.addRow("Participant ID", self.participant)
        form.addRow("Protocol", protocol_row)
        form.addRow("Results", results_row)
        form.addRow("Experimenter", self.experimenter)
        numbers = QHBoxLayout()
        numbers.addWidget(self.session_number)
        numbers.addWidget(QLabel("Order row"))
        numbers.addWidget(self.order_row)
        numbers.addStretch(1)
        form.addRow("Session no.", numbers)
        form.addRow("Notes", self.notes)
        form.addRow(self.resume)
        form.addRow(self.simulated)
        self.resume.toggled.connect(lambda _: self._grey_for_resume())

        self.device_panel = DevicePanel()  # the choice, the handshake, health and the rig check
        self.device = self.device_panel.summary
        self.audio = QLabel("")
        self.midi = QLabel("")
        self.engine = QLabel("")
        self._engine_words = ""  # rate and block of the running engine (its pacing line, show_pacing)
        for label in (self.audio, self.midi, self.engine):
            label.setWordWrap(True)
        apparatus = QGroupBox("Apparatus")
        found = QFormLayout(apparatus)
        found.addRow("Device", self.device_panel)
        found.addRow("Audio", self.audio)
        found.addRow("MIDI", self.midi)
        found.addRow("Engine", self.engine)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(session)
        layout.addWidget(self.error)  # not a form row: a form clipped a long refusal's wrapped lines
        layout.addWidget(apparatus)

    # what the user set ------------------------------------------------------
    @property
    def participant_id(self):
        return self.participant.text().strip()

    @property
    def protocol_path(self):
        return self.protocol.currentText()

    @property
    def results_folder(self):
        """The results folder, absolute (results_folder.py): never relative to where the console started."""
        return str(absolute(self.results.text().strip() or None))

    def remember_results(self):
        """Show the folder a session started in as an absolute path, and remember it on this machine."""
        folder = self.results_folder
        self.results.setText(folder)
        store = QSettings("studyapp", "studyapp")
        store.setValue(RESULTS_KEY, folder)
        store.sync()

    @property
    def session_info(self):
        """The session's information as ``Session.create`` takes it (None: not given); {} to resume."""
        if self.resume.isChecked():
            return {}
        number, row = self.session_number.value(), self.order_row.value()
        return {"experimenter": self.experimenter.text().strip() or None, "session_number": number or None,
                "notes": self.notes.text().strip(), "order_row": None if row < 0 else row}

    def fill_session_info(self, experimenter=None, session_number=None, notes=None, order_row=None):
        """Show what the command line gave (checked already)."""
        self.experimenter.setText(experimenter or "")
        self.session_number.setValue(int(session_number) if session_number not in (None, "") else 0)
        self.notes.setText(notes or "")
        self.order_row.setValue(int(order_row) if order_row not in (None, "") else -1)

    def typed_session_info(self):
        """What the fields hold now, as ``fill_session_info`` takes it (to give it back after a resumed session)."""
        number, row = self.session_number.value(), self.order_row.value()
        return {"experimenter": self.experimenter.text(), "session_number": number or None,
                "notes": self.notes.text(), "order_row": None if row < 0 else row}

    def select_protocol(self, path):
        """Show ``path`` as the chosen protocol (adding it to the list)."""
        index = self.protocol.findText(str(path))
        if index < 0:
            self.protocol.addItem(str(path))
            index = self.protocol.count() - 1
        self.protocol.setCurrentIndex(index)

    def _browse_protocol(self):
        path, _ = QFileDialog.getOpenFileName(self, "Choose a study protocol", "protocols", "Protocol (*.toml)")
        if path:
            self.select_protocol(path)
            self.protocol_chosen.emit(path)

    def _browse_results(self):
        folder = QFileDialog.getExistingDirectory(self, "Choose the results folder", self.results_folder)
        if folder:
            self.results.setText(folder)

    def set_editable(self, on):
        self._editable = bool(on)
        for widget in (self.participant, self.protocol, self.results, self.resume, self.simulated):
            widget.setEnabled(on)
        self.device_panel.set_editable(on)
        self._grey_for_resume()

    def _session_fields(self):
        return (self.experimenter, self.session_number, self.notes, self.order_row)

    def _grey_for_resume(self):
        """The session's own fields: editable for a new session, greyed to resume (its start set them)."""
        resuming = self.resume.isChecked()
        for widget in self._session_fields():
            widget.setEnabled(self._editable and not resuming)
            self._tips.setdefault(widget, widget.toolTip())
            widget.setToolTip("kept from the session's start when resuming" if resuming else self._tips[widget])

    def show_error(self, text):
        self.error.setText(text)

    # what the engine found ------------------------------------------------------
    def show_engine(self, state, info, config, notices):
        """Fill the apparatus lines from the engine's state, ``info`` (once running) and its notices."""
        device = config.device if config is not None else None
        if state in ("starting", "failed") or device is None:
            self.device_panel.show_device(device, state)
        if state == "running":
            audio = info.get("audio", "?")
            self.audio.setText(_with_notice(_audio_words(audio), notices.get("audio")))
            self.show_midi(info.get("midi", "none"), notices.get("midi"))
            self._engine_words = f"{info['rate']:g} Hz, blocks of {info['block']}"
            self.show_pacing(info["paced"])
        elif state == "starting":
            for label in (self.audio, self.midi):
                label.setText("looking…")
            self.engine.setText("starting…")
        else:
            self.engine.setText(state)


    def show_pacing(self, clock, why=""):
        """The engine line's pacing: ``clock`` (device, audio, timer), with ``why`` it changed (the notice)."""
        words = f"{self._engine_words}, paced by the {clock}"
        self.engine.setText(_with_notice(words, why) if why else words)

    def show_midi(self, description, notice=None):
        """The MIDI line for the engine's ``description`` of its input (and its latest MIDI notice)."""
        if description == "none":
            words = "no MIDI input: on-screen knobs"
        elif description.startswith("none yet"):
            words = f"{description}; the on-screen knobs work meanwhile"
        else:
            words = f"input {description}"
        self.midi.setText(_with_notice(words, notice))


def _audio_words(description):
    if description == "null":
        return "no sound (null sink)"
    return description


def _with_notice(text, notice):
    return f"{text}<br><span style='color:#a60'>{notice}</span>" if notice else text
