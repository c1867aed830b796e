"""One rounding step of the initial state: the probe behind the reproducibility contract (issue 39, docs/reproducibility.md).

Every simulated device starts at rest, its end-effector at x[0] = 0. With a
nudge of n steps it starts at

    x[0] = n * spacing(travel)    (travel = the end stop, 11 mm; spacing(0.011) = 1.7e-18 m)

that is n units in the last place of a position on the handle's scale: the
size of one rounding of the device's arithmetic, as another BLAS kernel,
libm or compiler gives it. A nudge of 0 is the plain model, bit for bit.
(np.nextafter(0, 1), 5e-324 m, would be no probe: it is lost in the first
step's products.) The stick-slip loop amplifies the nudge, as it does any
rounding: at F_max near a source's breakdown the handle's velocity differs
by tens of per cent within a second, so a figure's move under one nudge
measures how much of it is a fact about the model and how much about one
machine's last bits (scripts/sensitivity.py).

One owner, one setting: ``SimulatedDevice(nudge=n)``; when not given, the
environment variable ``STUDYAPP_NUDGE`` (a whole number, default 0), so that
every command whose figures docs/ quotes (``breakdown``, ``simulate``,
``simulate-set`` and hence ``optimise`` and ``evaluate`` on its recordings,
``run --simulated-participant`` and scripts/pilot.py) runs nudged without an
option of its own. Recordings made nudged say so (their metadata's ``nudge``).
"""

import os

import numpy as np

from studyapp.errors import ParameterError

VARIABLE = "STUDYAPP_NUDGE"
MAX_STEPS = 1_000_000  # far beyond a rounding probe; keeps x[0] below a nanometre


def check_steps(n, label="nudge"):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not -MAX_STEPS <= n <= MAX_STEPS:
        raise ParameterError(f"{label} {n!r}: allowed is a whole number of rounding steps from "
                             f"{-MAX_STEPS} to {MAX_STEPS} (0: the plain model)")
    return int(n)


def steps_from_environment():
    """The nudge ``STUDYAPP_NUDGE`` asks for (0 when unset or empty)."""
    text = os.environ.get(VARIABLE, "").strip()
    if not text:
        return 0
    try:
        value = int(text)
    except ValueError:
        value = text
    return check_steps(value, f"environment variable {VARIABLE}")


def initial_position(travel, n):
    """The end-effector's position at rest (m) under a nudge of ``n`` rounding steps: n * spacing(travel)."""
    return float(n) * float(np.spacing(float(travel)))
