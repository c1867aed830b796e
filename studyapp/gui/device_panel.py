"""The Apparatus panel's device: which one the engine runs on, what it said, and what the model predicts on it.

The choice: *simulated* (the engine's own simulated device) or *link* with a
path or URL (a serial port, a pty such as ``studyapp device-emulator``'s, or
``socket://HOST:PORT``); *Use* applies it (``device_chosen``: None or the
link), and both are remembered in the machine's settings (``QSettings``,
``device/kind`` and ``device/link``).

Once the engine reports the device (``show_info``: its ``DeviceInfo``) the
panel shows the handshake, the calibration's source, the link latency and the
round trip measured at open (live/device_words.py); on the simulated device it
says so (latency 0). ``show_health`` shows a trial's frame counts
(``DeviceHealth``).

Below, the rig check (live/rig_check.py): the predicted breakdown F_max of
the protocol's adjustment conditions at the rig's latency, a small table,
largest first, with LVT's margin over the best estimator, in red below 1.5x;
a progress bar while the prediction runs (gui/rig_prediction.py).
"""

from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtWidgets import (
    QComboBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QProgressBar,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from studyapp.live import device_words, rig_check

KINDS = ("simulated", "link")
KIND_KEY, LINK_KEY = "device/kind", "device/link"


def breakable(text):
    """``text`` with a line-break chance after each "/" (a zero-width space): a long link path or calibration
    file wraps at the panel's width instead of running past it, cut mid-line (issue 41, item 11)."""
    return text.replace("/", "/\u200b")


def settings():
    return QSettings("studyapp", "studyapp")


def remembered():
    """The device chosen last on this machine: None (simulated) or a link's path or URL."""
    stored = settings()
    link = str(stored.value(LINK_KEY, "")).strip()
    return link or None if str(stored.value(KIND_KEY, "simulated")) == "link" else None


class DevicePanel(QWidget):
    device_chosen = Signal(object)  # None (simulated) or the link's path or URL

    def __init__(self, parent=None):
        super().__init__(parent)
        self.kind = QComboBox()
        self.kind.addItems(KINDS)
        self.link = QLineEdit()
        self.link.setPlaceholderText("/dev/ttyACM0 or socket://HOST:PORT")
        self.use = QPushButton("Use")
        self.use.setToolTip("run the engine on this device (the preview engine restarts)")
        self.use.clicked.connect(self._use)
        self.kind.currentTextChanged.connect(lambda kind: self.link.setEnabled(kind == "link"))
        stored = settings()
        kind = str(stored.value(KIND_KEY, "simulated"))
        self.kind.setCurrentText(kind if kind in KINDS else "simulated")
        self.link.setText(str(stored.value(LINK_KEY, "")))
        self.link.setEnabled(self.kind.currentText() == "link")

        self.summary = QLabel("")
        self.health = QLabel("")
        self.check = QLabel("")
        for label in (self.summary, self.health, self.check):
            label.setWordWrap(True)
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.progress = QProgressBar()
        self.progress.setVisible(False)
        self.table = QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["condition", "breakdown F_max"])
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Stretch)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.table.setVisible(False)

        choose = QHBoxLayout()
        choose.setContentsMargins(0, 0, 0, 0)
        choose.addWidget(self.kind)
        choose.addWidget(self.link, 1)
        choose.addWidget(self.use)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(choose)
        layout.addWidget(self.summary)
        layout.addWidget(self.health)
        layout.addWidget(self.check)
        layout.addWidget(self.progress)
        layout.addWidget(self.table)

    @property
    def chosen(self):
        """None (simulated) or the link's path or URL as typed."""
        return self.link.text().strip() or None if self.kind.currentText() == "link" else None

    def _use(self):
        stored = settings()
        stored.setValue(KIND_KEY, self.kind.currentText())
        stored.setValue(LINK_KEY, self.link.text().strip())
        self.device_chosen.emit(self.chosen)

    def show_choice(self, device):
        """Show ``device`` (None: simulated) as the choice in force."""
        self.kind.setCurrentText("simulated" if device is None else "link")
        if device is not None:
            self.link.setText(device)

    def set_editable(self, on):
        for widget in (self.kind, self.link, self.use):
            widget.setEnabled(on and (widget is not self.link or self.kind.currentText() == "link"))

    # what the engine reported ----------------------------------------------------------------------
    def show_device(self, device, state):
        """Before the handshake: the simulated device, or the link being opened (``state``: the engine's)."""
        if device is None:
            self.health.setText("")
            self.summary.setText(device_words.SIMULATED)
        elif state == "failed":
            if "waiting for the handshake" in self.summary.text():
                self.summary.setText(breakable(f"link {device}: not opened"))
            self.health.setText("<span style='color:#c00'>the engine on this link failed or stopped: see the "
                                "log</span>")
        else:
            self.health.setText("")
            self.summary.setText(breakable(f"link {device}: waiting for the handshake…"))

    def show_info(self, info):
        lines = [device_words.handshake(info), breakable(f"calibration: {device_words.calibration(info)}"),
                 device_words.latency(info)]
        risk = device_words.late_risk(info)
        text = "<br>".join(lines)
        self.summary.setText(f"{text}<br><span style='color:#a60'>{risk}</span>" if risk else text)

    def show_health(self, trial, health, totals, where=None):
        self.health.setText(device_words.health(where or f"trial {trial}", health))

    # the rig check ---------------------------------------------------------------------------------
    def show_predicting(self, rig):
        self.table.setVisible(False)
        self.check.setText(f"predicting the bowing breakdown at {rig.latency_words} of latency ({rig.words})…")
        self.progress.setRange(0, 0)
        self.progress.setVisible(True)

    def show_progress(self, done, total, condition):
        self.progress.setRange(0, total)
        self.progress.setValue(done)
        self.progress.setFormat(f"{condition}: %v of %m")

    def show_no_check(self, why):
        self.progress.setVisible(False)
        self.table.setVisible(False)
        self.check.setText(why)

    def show_verdict(self, verdict):
        self.progress.setVisible(False)
        rows = rig_check.rows(verdict.prediction)
        self.table.setRowCount(len(rows))
        for row, (name, value) in enumerate(rows):
            self.table.setItem(row, 0, QTableWidgetItem(name))
            self.table.setItem(row, 1, QTableWidgetItem(value))
        height = self.table.horizontalHeader().height() + sum(self.table.rowHeight(r) for r in range(len(rows)))
        self.table.setFixedHeight(height + 2 * self.table.frameWidth())
        self.table.setVisible(True)
        colour = "#c00" if verdict.warns else "#070"
        self.check.setText(f"predicted at {verdict.rig.latency_words} of latency ({verdict.rig.words}): "
                           f"<span style='color:{colour}'>{verdict.text}</span>")
