"""The ``trial_health`` record's fields: which of the real-time engine's counters a trial logs, and as what.

At the end of each trial in the GUI the session logs the engine's fault
counters over the trial (the counter now minus at the trial's start) as one
``trial_health`` record; the export sums them per step into the columns of
the same names (export.py). The keys are the engine's status counters, the
values the record's fields and the export's columns (``underruns`` for the
audio underruns, ``limited`` for the output samples the limiter bent: the
stimulus is meant to stay under its knee, engine/signal_chain.py).
"""

HEALTH = {"deadline_misses": "deadline_misses", "audio_underruns": "underruns", "faults": "faults",
          "events_dropped": "events_dropped", "audio_limited": "limited"}
HEALTH_COLUMNS = list(HEALTH.values())
ADDED = {"limited"}  # fields logs made before them lack: exported as 0 for those
