"""The paper's data set (Sec. 6.1): 15 recordings of 7 s at 5 kHz, F_max 0..12.1 N, the LVT in the loop.

``write_set(directory)`` writes ``fmax_<value>.npz`` per F_max (``fmax_0.npz``,
``fmax_0.3.npz``, ...) and ``index.json`` listing the files and settings. The
validation set (paper Sec. 7.3: "an independent second set") uses another seed
and the slightly different ``strokes-validation`` gesture. Each file is written
atomically; ``index.json`` last, so a directory with an index is complete.
"""

import json
from pathlib import Path

from studyapp.io.atomic import atomic_open
from studyapp.estimators.spec import validate_rate
from studyapp.model.simulate import simulate
from studyapp.model.sources import LVT_SENSOR
from studyapp.io.recording import save

PAPER_FMAX = [0, 0.3, 0.5, 0.8, 1.1, 1.4, 1.6, 1.9, 2.2, 3.3, 4.4, 5.5, 7.7, 9.9, 12.1]
TRAINING = {"seed": 1, "gesture": "strokes"}
VALIDATION = {"seed": 2, "gesture": "strokes-validation"}


def file_name(fmax):
    return f"fmax_{fmax:g}.npz"


def write_set(directory, validation=False, rate=5000.0, duration=7.0, progress=None):
    """Simulate and write the set; returns the index dict."""
    rate = validate_rate(rate)
    settings = VALIDATION if validation else TRAINING
    directory = Path(directory)
    files = []
    for i, fmax in enumerate(PAPER_FMAX):
        name = file_name(fmax)
        if progress is not None:
            progress(i + 1, len(PAPER_FMAX), name)
        rec = simulate(fmax, rate=rate, duration=duration, source=LVT_SENSOR, gesture=settings["gesture"],
                       seed=settings["seed"] * 1000 + i)
        save(rec, directory / name)
        files.append({"file": name, "fmax": fmax, "seed": rec.meta["seed"], "broken": rec.meta["broken"],
                      "fault": rec.meta["fault"]})
    index = {
        "set": "validation" if validation else "training",
        "rate": rate, "duration": duration, "source": LVT_SENSOR, "gesture": settings["gesture"],
        "fmax": PAPER_FMAX, "files": files,
    }
    with atomic_open(directory / "index.json", "w") as f:
        json.dump(index, f, indent=2)
    return index
