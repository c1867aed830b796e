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

FORMAT = "studyapp-optimise-checkpoint/1"


def write(path, state):
    with atomic_open(path, "w", encoding="utf-8") as f:
        json.dump({"format": FORMAT, **state}, f)


def read(path):
    path = Path(path)
    try:
        with open(path, encoding="utf-8") as f:
            state = json.load(f)
    except FileNotFoundError:
        raise UserError(f"{path}: no such checkpoint file") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise UserError(f"{path}: not a checkpoint (invalid JSON: {exc})") from None
    if not isinstance(state, dict) or state.get("format") != FORMAT:
        raise UserError(f"{path}: not a checkpoint of studyapp optimise (expected format {FORMAT})")
    return state
