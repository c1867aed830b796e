"""The smallest F_max a protocol may set: below it, the force fed back is not heard.

In this model the string sounds at any F_max: the hand bows it through the
handle, and F_max scales only the force the string feeds back to the handle
(docs/model.md, "String"; G = F_max / 0.0833). What a participant judges, how
each velocity source changes the string's sound, comes through that force
alone. So as F_max falls, every condition sounds like the string with no
force at all, and a rating, a listen trial or an adjustment knob whose top is
there tells nothing.

The floor is measured from the model (``scripts/audible_fmax.py``, 2026-11-29, with issue 42's LVDT;
``stimulus_level.typical_rms_dbfs``, 5 kHz, strokes, 6 s per source, median of
100 ms RMS): the level of LVT, TRUE, LOWPASS and LEVANT in the loop, in dB
above the same source at F_max = 1e-6 N (where the level is flat: LVT at
-25.97 dBFS from 1e-6 to 1e-3 N in 3 s runs), seeds 0, 1, 2:

    F_max (N)   0.1          0.15         0.2          0.3          0.5          1.0
    largest     0.20 dB      0.34 dB      0.52 dB      0.98 dB      2.19 dB      5.67 dB
    median      0.16-0.17    0.28-0.30    0.40-0.42    0.71-0.74    1.43-1.52    3.65-3.71

(with the white LVDT, 2026-11-27: largest 0.36 dB at 0.1 N, 6.10 dB at 1 N).

A change of level under about 0.5 dB is not heard (the just-noticeable
difference of level is 0.5-1 dB), so ``FMAX_AUDIBLE`` = 0.1 N, where no source
on any seed moves the level by more than 0.20 dB (0.36 with the white LVDT), is the floor: a task's
``fmax`` (rating, listen) or ``ceiling`` (adjustment) below it is refused.
Conservative on purpose: at 0.15-0.3 N some sources are heard and others not.
"""

FMAX_AUDIBLE = 0.1  # N
ALLOWED = f"N; below {FMAX_AUDIBLE:g} N the force fed back is not heard"
