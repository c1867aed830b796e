"""Checkpoints of a running optimisation: JSON, written whole or not at all.

A checkpoint holds everything the optimiser needs to go on exactly where it
stopped: the iteration, the objective-sum state (retained raw objectives,
memorised offsets and scales), and for every estimator its search state with
its random generator's state. Resuming from it gives the same result as a run
that never stopped. ``fingerprint`` records what the run was for (recordings'
hashes, estimators, tuned dimensions, reference, seed, patience); a checkpoint
is only resumed for the same fingerprint.
"""

import json
from pathlib import Path

from studyapp.io.atomic import atomic_open
from studyapp.errors import UserError
from studyapp.io.small_files import read_json

FORMAT = "studyapp-optimise-checkpoint/1"
LIMIT_BYTES = 1 << 28  # a checkpoint of the thirteen is a few hundred kB


def write(path, state):
    with atomic_open(path, "w", encoding="utf-8") as f:
        json.dump({"format": FORMAT, **state}, f)


def read(path):
    path = Path(path)
    if not path.exists():
        raise UserError(f"{path}: no such checkpoint file")
    state = read_json(path, "checkpoint", LIMIT_BYTES)  # a FIFO, a huge or deeply nested file: one line
    if not isinstance(state, dict) or state.get("format") != FORMAT:
        raise UserError(f"{path}: not a checkpoint of studyapp optimise (expected format {FORMAT})")
    return state
