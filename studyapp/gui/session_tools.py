"""The console's run sheet, notes and sound: three small tools for the experimenter beside a session.

- **Run sheet…** shows the session's plan before Start (``run_plan``: order
  row, conditions in order, steps, estimated duration) for the participant,
  protocol, results folder, order row and simulated tick of the set-up
  panel, as ``studyapp plan`` prints it; blind (no condition names) while
  the console hides the condition. The dialog saves the Markdown or prints it.
- **Note**: a line of text and "Add note" log a ``note`` event with the time
  (``SessionController.add_note``): in the running session, or after it in
  the latest session's log.
- **Sound**: Mute and a master volume slider (-40 to 0 dB) send the engine's
  own volume and mute commands (``live/master_sound.py``), logged during
  a session. The slider reports only when released, so a drag is one change;
  it follows the preview's volume knob (knob 2), which has the same law.
"""

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSlider,
    QTextBrowser,
    QVBoxLayout,
)

from studyapp.errors import UserError
from studyapp.experiment.run_plan import make_plan, plan_markdown
from studyapp.io.atomic import atomic_open
from studyapp.model.controls import VOLUME_DB


class RunSheetDialog(QDialog):
    """The run sheet, rendered from its Markdown, with Save and Print."""

    def __init__(self, markdown, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Run sheet")
        self.markdown = markdown
        self.view = QTextBrowser()
        self.view.setMarkdown(markdown)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        save = buttons.addButton("Save…", QDialogButtonBox.ButtonRole.ActionRole)
        save.clicked.connect(self._save)
        print_button = buttons.addButton("Print…", QDialogButtonBox.ButtonRole.ActionRole)
        print_button.clicked.connect(self._print)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.view, 1)
        layout.addWidget(buttons)
        self.resize(760, 600)

    def save(self, path):
        with atomic_open(path, encoding="utf-8") as f:
            f.write(self.markdown)

    def _save(self):
        path, _ = QFileDialog.getSaveFileName(self, "Save the run sheet", "run-sheet.md", "Markdown (*.md)")
        if path:
            self.save(path)

    def _print(self):
        from PySide6.QtPrintSupport import QPrintDialog, QPrinter

        printer = QPrinter()
        if QPrintDialog(printer, self).exec() == QDialog.DialogCode.Accepted:
            self.view.document().print_(printer)


class SessionTools(QGroupBox):
    note_added = Signal(str)

    def __init__(self, controller, setup, blinded, parent=None):
        """``setup``: the console's ``SetupPanel``; ``blinded()``: whether the console hides the condition."""
        super().__init__("Run sheet, notes, sound", parent)
        self.controller = controller
        self.setup = setup
        self.blinded = blinded
        self.dialog = None
        self.sheet_button = QPushButton("Run sheet…")
        self.sheet_button.setToolTip("the session's plan: order, conditions, steps, estimated duration")
        self.sheet_button.clicked.connect(self.show_run_sheet)
        self.note = QLineEdit()
        self.note.setPlaceholderText("a note, logged with the time")
        self.note.returnPressed.connect(self.add_note)
        self.note_button = QPushButton("Add note")
        self.note_button.clicked.connect(self.add_note)
        self.mute = QCheckBox("Mute")
        self.mute.toggled.connect(controller.set_mute)
        low, high = VOLUME_DB
        self.volume = QSlider(Qt.Orientation.Horizontal)
        self.volume.setRange(int(low), int(high))
        self.volume.setValue(int(high))
        self.volume.setTracking(False)  # one change per release, not one per pixel dragged
        self.volume.valueChanged.connect(self._volume)
        controller.events.volume.connect(self._volume_applied)
        self.volume.sliderMoved.connect(lambda db: self.volume_label.setText(f"{db} dB"))
        self.volume_label = QLabel(f"{int(high)} dB")
        self.message = QLabel("")
        self.message.setWordWrap(True)

        layout = QVBoxLayout(self)
        layout.addWidget(self.sheet_button)
        row = QHBoxLayout()
        row.addWidget(self.note, 1)
        row.addWidget(self.note_button)
        layout.addLayout(row)
        row = QHBoxLayout()
        row.addWidget(self.mute)
        row.addWidget(QLabel("Volume"))
        row.addWidget(self.volume, 1)
        row.addWidget(self.volume_label)
        layout.addLayout(row)
        layout.addWidget(self.message)

    def run_sheet(self):
        """The run sheet's Markdown for the set-up panel's fields (``UserError`` when they do not allow one)."""
        protocol = self.controller.protocol
        if protocol is None:
            raise UserError("no protocol loaded: choose one first")
        plan = make_plan(protocol, self.setup.participant_id, self.setup.results_folder,
                         order_row=self.setup.session_info.get("order_row"),
                         simulated=self.setup.simulated.isChecked())
        return plan_markdown(plan, blind=self.blinded())

    def show_run_sheet(self):
        try:
            text = self.run_sheet()
        except UserError as exc:
            self.message.setText(f"Run sheet: {exc}")
            return None
        self.message.setText("")
        self.dialog = RunSheetDialog(text, self)
        self.dialog.show()
        return self.dialog

    def add_note(self):
        text = self.note.text()
        try:
            record = self.controller.add_note(text)
        except UserError as exc:
            self.message.setText(f"Note not logged: {exc}")
            return None
        self.note.clear()
        self.message.setText(f"Note logged at {record['wall'][11:19]}.")
        self.note_added.emit(text)
        return record

    def _volume_applied(self, db):
        """A volume knob set the master volume: show it, without sending it again."""
        self.volume.blockSignals(True)
        self.volume.setValue(round(db))
        self.volume.blockSignals(False)
        self.volume_label.setText(f"{db:.0f} dB")

    def _volume(self, db):
        self.volume_label.setText(f"{db} dB")
        self.controller.set_volume(float(db))
