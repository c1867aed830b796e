"""The worker's telemetry: one row per channel, one column per sample, written to the shared ring each block.

Besides the loop's signals, each block publishes what a study session needs
(push, not pull): the friction (the string's normalised force, paper eq. 2),
the loop's stability monitor's verdict (``broken``, 0 or 1) and ``score``
(model/stability.py: the one judgement of breakdown), the tag of the mapping
in force (``trial``) and the trial clock (seconds since the last
``ResetString``, which starts a trial). The active estimators' estimates follow,
one channel each (``estimate:NAME``).
"""

import numpy as np

# telemetry channels before the estimates ("estimate:NAME")
CHANNELS = (
    "t", "position", "velocity_lvt", "velocity_true", "source_velocity", "string_velocity",
    "force", "fmax", "force_scale", "friction", "broken", "stability_score", "trial", "trial_clock",
)
WITHHELD = ("force", "force_scale")  # the channels zeroed in a block whose force is withheld (engine/safety.py)
# rows with one value per block, and the rest, copied from the loop's output
_FMAX, _FORCE_SCALE, _BROKEN, _SCORE, _TRIAL, _CLOCK = (
    CHANNELS.index(c) for c in ("fmax", "force_scale", "broken", "stability_score", "trial", "trial_clock"))
_SAMPLED = tuple((i, c) for i, c in enumerate(CHANNELS)
                 if i not in (_FMAX, _FORCE_SCALE, _BROKEN, _SCORE, _TRIAL, _CLOCK))


def channels_for(names):
    return CHANNELS + tuple(f"estimate:{n}" for n in names)


class Rows:
    """The telemetry of one block of ``block`` samples over ``channels``, filled in place (no allocation)."""

    def __init__(self, channels, block):
        self.rows = np.empty((len(channels), block))

    def fill(self, out, loop, trial, trial_start):
        """The rows of the loop's block ``out``, tagged ``trial``, its clock counted from ``trial_start`` (s)."""
        rows = self.rows
        for i, name in _SAMPLED:
            rows[i] = out[name]
        monitor = loop.monitor
        rows[_FMAX] = loop.fmax
        rows[_FORCE_SCALE] = loop.force_scale
        rows[_BROKEN] = monitor.broken
        rows[_SCORE] = monitor.score
        rows[_TRIAL] = trial
        np.subtract(out["t"], trial_start, out=rows[_CLOCK])
        rows[len(CHANNELS):] = out["estimates"]
        return rows
