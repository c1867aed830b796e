"""The console's status bar: is the real-time loop keeping up, and is it safe?

From the engine's shared status block (``studyapp.engine.status``): the
achieved loop rate against the nominal one, the load (compute time over the
block period; mean and worst over the last second), deadline misses, audio
underruns, faults (with the latest fault's text while one is latched), the
engine's events dropped (MIDI control events and notices its event ring
overwrote before the console read them), plus telemetry samples the GUI lost
(it fell more than the ring behind), the knob-to-effect latency (a control's
arrival to the first block run with its effect, measured by the worker: the
last and the largest) and the scope's painted frame rate. Trouble shows in red.

The readouts whose text has no fixed length (the engine's state, the latched
fault, the knob latency) and the latest warning (``show_message``, left) are
``ElidedLabel`` widgets: they shrink to a few characters and end in "…"
rather than widen the window; the whole text is in their tooltip. The short
numeric readouts keep their width. The warning keeps at least
``MESSAGE_CHARACTERS`` characters' width (the readouts that elide give way
first): at 1,366 px it read "Em…".
"""

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QLabel, QStatusBar

from studyapp.gui.elided_label import ElidedLabel

RED = "color: #c00; font-weight: bold;"
ELIDED = ("engine", "faults", "knob")
MESSAGE_CHARACTERS = 40


def message_width(label):
    """Room for ``MESSAGE_CHARACTERS`` characters of a warning, the "…" and the label's margins.

    Measured on "n", wider than most lower-case letters: ``averageCharWidth`` is an integer and
    held 39 characters of an ordinary warning.
    """
    margins = label.contentsMargins()
    sample = "n" * MESSAGE_CHARACTERS + "…"
    return label.fontMetrics().horizontalAdvance(sample) + margins.left() + margins.right() + 2


class StatusBar(QStatusBar):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.labels = {}
        self.message = ElidedLabel("")
        self.message.setMinimumWidth(message_width(self.message))
        self.addWidget(self.message, 1)
        self._message_timer = QTimer(self)
        self._message_timer.setSingleShot(True)
        self._message_timer.timeout.connect(lambda: self.message.setText(""))
        for key, tip in (
            ("engine", "the real-time engine"),
            ("rate", "samples per second achieved over the last second / nominal haptic rate"),
            ("load", "compute time per block over the block period: mean (worst) over the last second"),
            ("misses", "blocks finished after their deadline"),
            ("underruns", "audio device periods the engine did not fill in time"),
            ("faults", "safety faults raised (the force is held at zero while one is latched)"),
            ("dropped", "engine events (MIDI controls, notices) overwritten before the console read them"),
            ("lost", "telemetry samples the GUI read too late to see"),
            ("knob", "knob to effect: from a control's arrival to the first block run with it (last, largest)"),
            ("fps", "scope frames painted per second"),
        ):
            label = ElidedLabel("") if key in ELIDED else QLabel("")
            label.setToolTip(tip)
            self.addPermanentWidget(label)
            self.labels[key] = label
        self.show_engine("stopped")

    def show_message(self, text, milliseconds, colour=""):
        """Show ``text`` (elided to the room left) for ``milliseconds``."""
        self.message.setText(text)
        self.message.setStyleSheet(f"color: {colour};" if colour else "")
        self._message_timer.start(milliseconds)

    def show_engine(self, state, info=None):
        info = info or {}
        text = f"Engine: {state}"
        if state == "running" and info:
            text += f" ({info.get('paced', '?')}-paced{', real-time priority' if info.get('realtime') else ''})"
        self.labels["engine"].setText(text)
        self.labels["engine"].setStyleSheet(RED if state == "failed" else "")
        if state != "running":
            for key in ("rate", "load", "misses", "underruns"):
                self.labels[key].setText("")

    def show_status(self, status, lost=0, knob_latency=(None, None)):
        s = status
        self.labels["rate"].setText(f"Loop {s['achieved_rate']:,.0f} / {s['rate']:,.0f} Hz")
        self.labels["load"].setText(f"Load {100 * s['load_mean']:.0f}% ({100 * s['load_max']:.0f}%)")
        self.labels["load"].setStyleSheet(RED if s["load_max"] >= 1.0 else "")
        self.labels["misses"].setText(f"Deadline misses {s['deadline_misses']}")
        self.labels["misses"].setStyleSheet(RED if s["deadline_misses"] else "")
        self.labels["underruns"].setText(f"Audio underruns {s['audio_underruns']}")
        self.labels["underruns"].setStyleSheet(RED if s["audio_underruns"] else "")
        faults = f"Faults {s['faults']}"
        if s["fault_latched"]:
            faults += f" — LATCHED: {s['fault'] or 'force disabled'}"
        self.labels["faults"].setText(faults)
        self.labels["faults"].setStyleSheet(RED if s["fault_latched"] else "")
        dropped = s.get("events_dropped", 0)
        self.labels["dropped"].setText(f"Events dropped {dropped}" if dropped else "")
        self.labels["dropped"].setStyleSheet(RED if dropped else "")
        self.labels["lost"].setText(f"Lost {lost}" if lost else "")
        last, largest = knob_latency
        if last is not None:
            self.labels["knob"].setText(f"Knob → effect {1e3 * last:.1f} ms (max {1e3 * largest:.1f})")

    def show_frame_rate(self, fps):
        self.labels["fps"].setText(f"Scope {fps:.0f} fps" if fps else "")
