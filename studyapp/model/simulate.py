"""One simulated recording, as the paper recorded its data set (Sec. 6.1).

``simulate(fmax, ...)`` runs the closed loop (loop.py) with the requested
velocity source in the loop and returns a ``studyapp.io.recording.Recording``
with the columns of the paper's recordings (LVDT position, LVT velocity,
acceleration) plus the simulation's ground truth (true velocity and
acceleration), the force command, the string velocity at the bow and the audio.
The accelerometer is always simulated here, so every estimator can later be
run on the recording. ``Simulation`` runs the same loop a block at a time, for
outputs streamed to disk (``studyapp simulate``). ``link`` (a link.LinkSpec) puts
the simulated device behind a link (latency, packets, jitter, frame loss;
link.py); the metadata's ``link`` says which (seconds and samples), and the
``force`` column is the host's command, before the link.
"""

import numpy as np

from studyapp import __version__
from studyapp.errors import ParameterError
from studyapp.io.recording import COLUMNS, Recording
from studyapp.model import calibration
from studyapp.model.link import IDEAL
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import LVT_SENSOR, is_pseudo

BLOCK = 4096
DURATION_MAX = 3600.0


class Simulation:
    """The closed loop set up for one recording; ``blocks()`` yields its columns a block at a time.

    Memory stays that of one block however long the recording: ``simulate``
    gathers the blocks into a ``Recording``, ``studyapp simulate`` streams them
    to its output (io/recording_writer.py). ``meta()`` describes the run once
    the blocks are consumed (the stability verdict and fault are known only then).
    """

    def __init__(self, fmax, rate=5000.0, duration=7.0, source=LVT_SENSOR, gesture="strokes", f0=None, seed=0,
                 estimators=None, link=None):
        try:
            duration = float(duration)
        except (TypeError, ValueError):
            duration = float("nan")
        if not (0.0 < duration <= DURATION_MAX):
            raise ParameterError(f"duration = {duration!r}: allowed is a number of seconds above 0 and at most "
                                 f"{DURATION_MAX:g}")
        if estimators is None:
            estimators = {}
        elif not isinstance(estimators, dict):
            estimators = {name: {} for name in estimators}
        else:
            estimators = dict(estimators)
        if not is_pseudo(source) and source not in estimators:
            estimators[source] = {}
        self.f0 = calibration.F0 if f0 is None else f0
        self.source, self.gesture, self.seed, self.link = source, gesture, seed, link or IDEAL
        config = LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                            f0=self.f0, seed=seed, audio=True, accelerometer=True, link=link)
        self.loop = ClosedLoop(config)
        self.rate = self.loop.rate
        self.total = int(round(duration * self.loop.rate))
        self.broken = False

    def blocks(self, progress=None):
        """Yield ``{column: array}`` (``recording.COLUMNS``) for blocks of up to ``BLOCK`` samples."""
        done = 0
        while done < self.total:
            n = min(BLOCK, self.total - done)
            block = self.loop.run(n)
            done += n
            self.broken = self.broken or self.loop.monitor.broken
            if progress is not None:
                progress(done, self.total)
            yield {name: block[name] for name in COLUMNS}

    def meta(self):
        loop = self.loop
        return {
            "version": __version__,
            "fmax": loop.fmax, "rate": loop.rate, "source": self.source, "gesture": self.gesture,
            "f0": float(self.f0), "seed": int(self.seed), "duration": self.total / loop.rate,
            "estimators": list(loop.names), "velocity_scale": loop.velocity_scale, "fault": loop.fault,
            "broken": bool(self.broken),  # the stability monitor flagged breakdown at some block
            "model": calibration.describe(),
            "link": self.link.describe(loop.rate),
            "nudge": int(getattr(loop.device, "nudge", 0)),  # rounding steps off rest at the start (model/nudge.py)
        }


def simulate(fmax, rate=5000.0, duration=7.0, source=LVT_SENSOR, gesture="strokes", f0=None, seed=0,
             estimators=None, progress=None, link=None):
    """A ``Recording`` of ``duration`` s of bowing at ``fmax`` N with ``source`` in the loop.

    ``estimators``: the active set (names or name -> params); the source is
    added when it is an estimator. ``progress(done, total)`` is called per block.
    """
    sim = Simulation(fmax, rate, duration, source, gesture, f0, seed, estimators, link)
    parts = {name: [] for name in COLUMNS}
    for block in sim.blocks(progress):
        for name in COLUMNS:
            parts[name].append(block[name])
    columns = {name: np.concatenate(parts[name]) if parts[name] else np.zeros(0) for name in COLUMNS}
    return Recording(sim.rate, columns, sim.meta())
