"""The live scope: velocities and force as the engine computes them (pyqtgraph).

Three plots share the time axis. The handle's velocity: the LVT sensor, the
selected velocity source (the estimate in the loop), and, when ticked, the
true velocity and every other active estimate. The string's velocity at the
bow (in the handle's m/s, i.e. divided by the loop's velocity scale): its
Helmholtz slips are ten times the bow speed, so it gets its own plot rather
than flattening the estimates. The force on the handle. The ticks above the
plots, in the traces' colours, are the legend. A window of 0.1 to 5 s ends
at the newest sample.

Axes show what the signals can resolve, not the arithmetic's leftovers: after
a stop the string decays towards 1e-33 m/s, and an axis that autoscales to
that read "2e-33" or "pm/s". Each plot's y span is at least ``FLOOR_SIGMAS``
times its noise floor (``NOISE_FLOORS``: the LVT's 0.115 mm/s RMS, SensorSpec,
for both velocity plots, which are in the handle's m/s; for the force one step
of a 16-bit output over the motor's +-200 N, 6.1 mN, as the LVDT's 16 bits),
and an axis's SI prefix is never finer than milli (``ScopeAxis``: mm/s, mN).

The scope is a view: ``add(block)`` takes the telemetry the session
controller announces (its ``telemetry`` event) into a ``ScopeBuffer``; a
timer repaints at most every ``FRAME_PERIOD`` seconds from the buffer's
peak envelope (two points per pixel column, ``scope_buffer.envelope``), so
the work per frame does not grow with the sample rate or the window.
``Freeze`` stops repainting (samples still arrive, so ``Resume`` shows the
present); ``Save PNG`` writes the plots as shown. ``frame_rate()`` is measured
from real paints (``FrameRateMeter``).
"""

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QTimer, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QDoubleSpinBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from studyapp.io.atomic import atomic_path
from studyapp.gui.flow_layout import FlowLayout
from studyapp.gui.frame_rate import FrameRateMeter
from studyapp.model.device import DeviceLimits
from studyapp.model.sensors import SensorSpec
from studyapp.live.scope_buffer import MAX_SECONDS, ScopeBuffer

FRAME_PERIOD = 0.015  # s: aim above 60 fps; the measured rate is what counts
MIN_SECONDS = 0.1
DEFAULT_SECONDS = 1.0

# channel, label, colour, plot ("v" handle velocity, "s" string velocity, "f" force), on by default
BASE_TRACES = (
    ("velocity_lvt", "LVT velocity", "#1f77b4", "v", True),
    ("source_velocity", "selected (in the loop)", "#d62728", "v", True),
    ("velocity_true", "true velocity", "#7f7f7f", "v", False),
)
LAST_TRACES = (
    ("string_velocity", "string velocity", "#2ca02c", "s", True),
    ("force", "force", "#ff7f0e", "f", True),
)
FORCE_BITS = 16
NOISE_FLOORS = {"v": SensorSpec().lvt_noise, "s": SensorSpec().lvt_noise,
                "f": 2 * DeviceLimits().impulsive / 2**FORCE_BITS}
FLOOR_SIGMAS = 8  # a still signal's noise spans about +-4 sigma
FINEST_PREFIX = 1e-3  # milli: no axis reads in micro, nano or pico

ESTIMATE_COLOURS = ("#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf", "#393b79", "#637939", "#8c6d31",
                    "#843c39", "#7b4173")

pg.setConfigOptions(antialias=False, foreground="k", background="w")


class ScopeAxis(pg.AxisItem):
    """An axis whose automatic SI prefix is never finer than ``FINEST_PREFIX``."""

    def updateAutoSIPrefix(self):
        scale, prefix = 1.0, ""
        if self.label.isVisible():
            largest = max(abs(self.range[0]), abs(self.range[1])) * self.scale
            scale, prefix = pg.siScale(max(largest, FINEST_PREFIX), power=self.unitPower)
        self.autoSIPrefixScale = scale
        self.labelUnitPrefix = prefix
        self._updateLabel()


class Scope(QWidget):
    saved = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.buffer = None
        self.traces = {}  # channel -> (curve, checkbox)
        self.frozen = False
        self._dirty = False

        self.seconds = QDoubleSpinBox()
        self.seconds.setRange(MIN_SECONDS, MAX_SECONDS)
        self.seconds.setSingleStep(0.1)
        self.seconds.setDecimals(1)
        self.seconds.setSuffix(" s")
        self.seconds.setValue(DEFAULT_SECONDS)
        self.seconds.setToolTip("time window of the scope (0.1 to 5 s)")
        self.seconds.valueChanged.connect(self._set_window)
        self.freeze_button = QPushButton("Freeze")
        self.freeze_button.setCheckable(True)
        self.freeze_button.toggled.connect(self.set_frozen)
        self.save_button = QPushButton("Save PNG…")
        self.save_button.clicked.connect(self._choose_png)
        self.fps_label = QLabel("")
        # room for the widest reading from the start: the readout never nudges the layout
        self.fps_label.setMinimumWidth(self.fps_label.fontMetrics().horizontalAdvance("999 fps") + 2)
        self.toggle_box = QWidget()
        self.toggles = FlowLayout(self.toggle_box)

        self.view = pg.GraphicsLayoutWidget()
        self.velocity_plot = self.view.addPlot(row=0, col=0, axisItems={"left": ScopeAxis("left")})
        self.string_plot = self.view.addPlot(row=1, col=0, axisItems={"left": ScopeAxis("left")})
        self.force_plot = self.view.addPlot(row=2, col=0, axisItems={"left": ScopeAxis("left")})
        self.plots = {"v": self.velocity_plot, "s": self.string_plot, "f": self.force_plot}
        for row, stretch in enumerate((3, 2, 2)):
            self.view.ci.layout.setRowStretchFactor(row, stretch)
        for where, label, unit in (("v", "handle velocity", "m/s"), ("s", "string velocity", "m/s"),
                                   ("f", "force", "N")):
            plot = self.plots[where]
            plot.setLabel("left", label, units=unit)
            plot.setLimits(minYRange=FLOOR_SIGMAS * NOISE_FLOORS[where])
            plot.setMouseEnabled(x=False, y=True)
            plot.enableAutoRange(axis="y")
            plot.setAutoVisible(y=True)
            plot.hideButtons()
            plot.getAxis("left").setWidth(62)
            if plot is not self.velocity_plot:
                plot.setXLink(self.velocity_plot)
            if plot is not self.force_plot:
                plot.getAxis("bottom").setStyle(showValues=False)
        self.force_plot.setLabel("bottom", "time", units="s")
        self.meter = FrameRateMeter(self.view.viewport())

        top = QHBoxLayout()
        top.addWidget(QLabel("Window"))
        top.addWidget(self.seconds)
        top.addWidget(self.freeze_button)
        top.addWidget(self.save_button)
        top.addStretch(1)
        top.addWidget(self.fps_label)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(top)
        layout.addWidget(self.toggle_box)
        layout.addWidget(self.view, 1)

        self.timer = QTimer(self)
        self.timer.setInterval(int(FRAME_PERIOD * 1000))
        self.timer.timeout.connect(self.redraw)
        self.timer.start()
        self._set_window(self.seconds.value())

    # scene ----------------------------------------------------------------
    def set_scene(self, rate, estimates):
        """Prepare for an engine at ``rate`` Hz with the active estimators ``estimates``."""
        for curve, box, plot in self.traces.values():
            plot.removeItem(curve)
            self.toggles.removeWidget(box)
            box.deleteLater()
        self.traces = {}
        specs = list(BASE_TRACES)
        specs += [(f"estimate:{name}", name, ESTIMATE_COLOURS[i % len(ESTIMATE_COLOURS)], "v", False)
                  for i, name in enumerate(estimates)]
        specs += LAST_TRACES
        for channel, label, colour, where, on in specs:
            plot = self.plots[where]
            curve = pg.PlotCurveItem(pen=pg.mkPen(colour, width=1), skipFiniteCheck=True)
            # the clean LVT on top of the noisier estimates, so neither hides the other
            curve.setZValue(1 if channel == "velocity_lvt" else 0)
            plot.addItem(curve)
            box = QCheckBox(label)
            box.setChecked(on)
            box.setStyleSheet(f"QCheckBox {{ color: {colour}; }}")
            box.toggled.connect(lambda checked, c=curve: self._show_curve(c, checked))
            curve.setVisible(on)
            self.toggles.addWidget(box)
            self.traces[channel] = (curve, box, plot)
        self.buffer = ScopeBuffer(rate, [c for c in self.traces])
        self._dirty = True

    def _show_curve(self, curve, on):
        curve.setVisible(on)
        self._dirty = True

    def show_all(self, on=True):
        """Tick (or untick) every trace's toggle."""
        for _, box, _ in self.traces.values():
            box.setChecked(on)

    # data -----------------------------------------------------------------
    def add(self, block):
        """Take a telemetry block (``Engine.telemetry`` layout) into the buffer."""
        if self.buffer is None:
            return
        rows = []
        for channel in self.buffer.channels:
            if channel.startswith("estimate:"):
                rows.append(block["estimates"][channel[9:]])
            else:
                rows.append(block[channel])
        self.buffer.append(np.vstack(rows), end=block["end"])
        self._dirty = True

    @property
    def samples(self):
        """Samples received since the scene was set (0 before any)."""
        return 0 if self.buffer is None else self.buffer.count

    # drawing ----------------------------------------------------------------
    def _set_window(self, seconds):
        self.velocity_plot.setXRange(-float(seconds), 0.0, padding=0.0)
        self._dirty = True

    def set_frozen(self, on):
        self.frozen = bool(on)
        self.freeze_button.setText("Resume" if self.frozen else "Freeze")
        if self.freeze_button.isChecked() != self.frozen:
            self.freeze_button.setChecked(self.frozen)
        self._dirty = True

    def redraw(self):
        rate = self.meter.rate()
        self.fps_label.setText(f"{rate:.0f} fps" if rate else "")
        if self.frozen or not self._dirty or self.buffer is None or self.buffer.count == 0:
            return
        self._dirty = False
        columns = max(200, int(self.velocity_plot.getViewBox().width()))
        t, y = self.buffer.window(self.seconds.value(), columns)
        for channel, (curve, box, _) in self.traces.items():
            if box.isChecked():
                curve.setData(t, y[channel])

    def frame_rate(self):
        return self.meter.rate()

    # saving ---------------------------------------------------------------
    def save_png(self, path):
        """Write the plots as shown to ``path`` (PNG, atomically); returns the path."""
        image = self.view.grab()
        with atomic_path(path) as tmp:
            if not image.save(str(tmp), "PNG"):
                raise OSError(f"{path}: could not write the PNG")
        self.saved.emit(str(path))
        return path

    def _choose_png(self):
        path, _ = QFileDialog.getSaveFileName(self, "Save the scope as PNG", "scope.png", "PNG image (*.png)")
        if path:
            self.save_png(path)
