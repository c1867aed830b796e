"""A parameter set tuned at one rate, made for another: windows counted in samples keep their duration.

Table 1 was tuned at the paper's rate, TABLE1_RATE = 5 kHz. Its parameters
in samples (``unit == "samples"``: LEASTSQ's and FOAW's windows, the FOAW
hybrids' windows, BDIFF's steps) fix a duration only at that rate: at a rate
r the same count spans TABLE1_RATE / r of the time, so at 48 kHz FOAW's 17
samples span 0.35 ms instead of 3.4 ms and its estimate is about 30 times
noisier (the slope of a line fitted to n samples over n T has a noise of
order sigma / (T n^1.5)). Made for the rate, such a parameter n becomes

    n' = round(n r / r_set),   clipped to the parameter's allowed range,

(``windows="seconds"``, the default), e.g. LEASTSQ's 33 samples at 5 kHz
are 317 at 48 kHz and FOAW's 17 are 163; ``windows="samples"`` keeps the
counts as given. Cut-offs (Hz), covariances and margins are physical
quantities and stay as they are.
"""

from studyapp.errors import ParameterError
from studyapp.estimators.registry import spec

TABLE1_RATE = 5000.0  # Hz, the paper's rate, at which Table 1 was set
WINDOWS = ("seconds", "samples")


def check_windows(windows, label="windows"):
    if windows not in WINDOWS:
        raise ParameterError(f"{label} {windows!r}: allowed are {', '.join(WINDOWS)}")
    return windows


def at_rate(name, values, rate, params_rate=TABLE1_RATE, windows="seconds"):
    """``values`` (estimator ``name``'s parameters set at ``params_rate``) made for ``rate``; unvalidated.

    Only the parameters given are touched: pass the defaults (``table1``) to scale Table 1 itself.
    """
    values = dict(values)
    if check_windows(windows) == "seconds":
        for p in spec(name).params:
            if p.kind == "int" and p.unit == "samples" and p.name in values:
                scaled = int(round(values[p.name] * float(rate) / float(params_rate)))
                values[p.name] = int(min(p.high, max(p.low, scaled)))
    return values


def table1(name, rate, windows="seconds"):
    """Estimator ``name``'s Table 1 (its defaults) made for ``rate``."""
    return at_rate(name, {p.name: p.default for p in spec(name).params}, rate, TABLE1_RATE, windows)
