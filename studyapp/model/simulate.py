"""One simulated recording, as the paper recorded its data set (Sec. 6.1).

``simulate(fmax, ...)`` runs the closed loop (loop.py) with the requested
velocity source in the loop and returns a ``studyapp.io.recording.Recording``
with the columns of the paper's recordings (LVDT position, LVT velocity,
acceleration) plus the simulation's ground truth (true velocity and
acceleration), the force command, the string velocity at the bow and the audio.
The accelerometer is always simulated here, so every estimator can later be
run on the recording. ``link`` (a link.LinkSpec) puts the simulated device
behind a link (latency, packets, jitter, frame loss; link.py); the metadata's
``link`` says which (seconds and samples), and the ``force`` column is the
host's command, before the link.
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


def simulate(fmax, rate=5000.0, duration=7.0, source=LVT_SENSOR, gesture="strokes", f0=None, seed=0,
             estimators=None, progress=None, link=None):
    """A ``Recording`` of ``duration`` s of bowing at ``fmax`` N with ``source`` in the loop.

    ``estimators``: the active set (names or name -> params); the source is
    added when it is an estimator. ``progress(done, total)`` is called per block.
    """
    try:
        duration = float(duration)
    except (TypeError, ValueError):
        duration = float("nan")
    if not (0.0 < duration <= DURATION_MAX):
        raise ParameterError(f"duration = {duration!r}: allowed is a number of seconds above 0 and at most {DURATION_MAX:g}")
    if estimators is None:
        estimators = {}
    elif not isinstance(estimators, dict):
        estimators = {name: {} for name in estimators}
    else:
        estimators = dict(estimators)
    if not is_pseudo(source) and source not in estimators:
        estimators[source] = {}
    f0 = calibration.F0 if f0 is None else f0
    config = LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                        f0=f0, seed=seed, audio=True, accelerometer=True, link=link)
    loop = ClosedLoop(config)
    total = int(round(duration * loop.rate))
    parts = {name: [] for name in COLUMNS}
    done = 0
    broken = False
    while done < total:
        n = min(BLOCK, total - done)
        block = loop.run(n)
        for name in COLUMNS:
            parts[name].append(block[name])
        done += n
        broken = broken or loop.monitor.broken
        if progress is not None:
            progress(done, total)
    columns = {name: np.concatenate(parts[name]) if parts[name] else np.zeros(0) for name in COLUMNS}

    meta = {
        "version": __version__,
        "fmax": loop.fmax, "rate": loop.rate, "source": source, "gesture": gesture, "f0": float(f0),
        "seed": int(seed), "duration": total / loop.rate, "estimators": list(loop.names),
        "velocity_scale": loop.velocity_scale, "fault": loop.fault,
        "broken": bool(broken),  # the stability monitor flagged breakdown at some block
        "model": calibration.describe(),
        "link": (link or IDEAL).describe(loop.rate),
    }
    return Recording(loop.rate, columns, meta)
