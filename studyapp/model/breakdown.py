"""Breakdown F_max: the largest friction gain at which a velocity source keeps the loop stable.

The paper's adjustment task (Sec. 8.2-8.3, Fig. 7) asks for "the maximum
displayable friction gain F_max such that the display remains stable". This
is the simulated world's answer, judged as the participants judged it: while
bowing with the protocol's gesture (``strokes`` by default; ``hold`` kept).

One trial, ``is_broken(source, f)``: the closed loop (loop.py) runs for
``duration`` s at F_max = f with ``source`` as the velocity in the loop.
- Bowing (``strokes``): broken if the loop faults, if the handle's velocity in
  the band stability.BAND, or in the upper band stability.hiss_band(rate)
  (2.5 kHz up to min(16 kHz, 0.45 x rate), none at 5 kHz), RMS over
  [SETTLE, duration], is more than stability.RISE (6 dB) above TRUE's in the
  same band on the same gesture at the same F_max and seed (TRUE's runs are
  cached) and above the band's perception floor (stability.band_floor,
  stability.hiss_floor: what a person could feel or hear), or if the
  string's pitch (the largest spectral peak of the string's velocity at the
  bow above 100 Hz, over the same span) is more than
  stability.PITCH_TOLERANCE off f0. docs/model.md justifies it.
- Holding (``hold``): broken if the loop faults or the stability monitor's hold
  criterion flags breakdown once its SETTLE = 0.25 s window has filled
  (checked every BLOCK = 0.05 s).

The source runs with its parameters from ``estimators`` or, when not given
there, with Table 1 made for the rate (estimators/at_rate.py; ``windows``
"seconds": windows counted in samples keep their 5 kHz duration, "samples":
the counts as printed).

The search, ``breakdown_fmax``, assumes broken(f) is monotonic in f and
bisects log f. It starts from the bracket [LOW, HIGH] = [0.05, 200] N (200 N:
the loop's F_max limit, the motors' impulsive limit): with lo stable and hi
broken it tries the geometric midpoint sqrt(lo hi) and keeps the half that
still brackets the edge, until hi / lo <= 1 + tolerance, and returns
sqrt(lo hi), within a factor sqrt(1 + tolerance) of the edge. That takes
2 + ceil(log2(ln(HIGH / LOW) / ln(1 + tolerance))) trials (11 at tolerance
0.02). It returns LOW when LOW already breaks and inf when HIGH does not.

Behind a link (``link``, a link.LinkSpec: latency, packets, jitter, frame
loss; issue 29): the simulated device applies the newest command that has
arrived (link.py). The reference stays TRUE on an ideal link: a rig's delay
is judged against the world without it, as the participant would judge it.
The link's draws are seeded by the trial's seed.

Over seeds, ``breakdown_over_seeds``: seed k (k = K..K+N-1, K = 0 unless
``first_seed`` says otherwise) draws the sensors' noise and the hand's tremor,
so each seed is one run of the same world, like one trial of the paper's six
per participant; a seed's value does not depend on K or N. The result gives every seed's
F_max and their median (for even N the mean of the middle two, numpy.median),
minimum and maximum; inf (stable to 200 N) counts as the largest value.
It also says how Table 1 was made for the rate (``windows``) and the link it ran with (``LINK_KEYS``, seconds).
"""

import functools
import math

import numpy as np

from studyapp.errors import ParameterError
from studyapp.estimators import names
from studyapp.estimators.at_rate import check_windows, table1
from studyapp.estimators.spec import validate_rate
from studyapp.model import bowing_reference, stability
from studyapp.model.calibration import F0
from studyapp.model.limits import BREAKDOWN_GESTURES, FMAX_LIMIT
from studyapp.model.link import IDEAL, NAMES as LINK_KEYS
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import is_pseudo, with_pseudo_sources

SETTLE = 0.25  # s before the monitor's verdict counts (its window)
BLOCK = 0.05  # s
LOW = 0.05  # N, the search's lowest F_max
HIGH = FMAX_LIMIT  # N, the search's highest F_max
MAX_SEEDS = 100  # a source's search takes about 0.3 s per seed at 5 kHz; --all with 100 seeds about 10 min
DURATION_RANGE = (0.5, 60.0)  # s per trial; below about 2 s a late onset is missed (the verdict lags ~1 s)
DURATION = 5.0  # s per trial by default: about ten strokes
MAX_SEED_END = 1_000_000  # K + N at most this: seeds stay small whole numbers wherever they are derived from
KEYS = ("source", "rate", "gesture", "seeds", "fmax", "fmax_median", "fmax_min", "fmax_max", "first_seed",
        "seeds_used", "windows") + LINK_KEYS


def sources():
    """Every velocity source the loop can run: each estimator name, then the pseudo-sources (model/sources.py)."""
    return with_pseudo_sources(names())


def check_source(name, label="source"):
    allowed = sources()
    if name not in allowed:
        raise ParameterError(f"{label} {name!r}: allowed are {', '.join(allowed)}")
    return name


def check_seeds(n, label="seeds"):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_SEEDS:
        raise ParameterError(f"{label} {n!r}: allowed is a whole number from 1 to {MAX_SEEDS}")
    return int(n)


def check_first_seed(k, n, label="first seed"):
    """``k`` if seeds ``k``..``k`` + ``n`` - 1 are allowed: ``k`` a whole number >= 0, ``k`` + ``n`` <= MAX_SEED_END."""
    if (isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k
            or k + check_seeds(n) > MAX_SEED_END):
        raise ParameterError(f"{label} {k!r}: allowed is a whole number from 0 to {MAX_SEED_END - n} "
                             f"(first seed + seeds at most {MAX_SEED_END})")
    return int(k)


def check_gesture(name, label="gesture"):
    if name not in BREAKDOWN_GESTURES:
        raise ParameterError(f"{label} {name!r}: allowed are {', '.join(BREAKDOWN_GESTURES)}")
    return name


def check_duration(seconds, label="duration"):
    lo, hi = DURATION_RANGE
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = float("nan")
    if not lo <= value <= hi:
        raise ParameterError(f"{label} {seconds!r}: allowed is a number of seconds from {lo:g} to {hi:g}")
    return value


def is_broken(source, fmax, rate=5000.0, gesture="strokes", duration=DURATION, seed=0, estimators=None, f0=None,
              link=None, windows="seconds", make_loop=None):
    """Whether ``source`` at ``fmax`` N breaks down within ``duration`` s of ``gesture`` (the module's criteria),
    the device behind ``link`` (a link.LinkSpec; None: ideal); or, with ``make_loop(source, fmax, rate, gesture,
    seed)`` (a context manager giving a ``ClosedLoop``), on that loop's device (device/emulated_loop.py: a device
    that runs the loop itself, its own estimators with Table 1's parameters, at F0)."""
    if make_loop is not None:
        with make_loop(source, fmax, rate, gesture, seed) as loop:
            return _broken(loop, gesture, duration, fmax, seed)
    estimators = dict(estimators or {})
    if not is_pseudo(source) and source not in estimators:
        estimators[source] = table1(source, rate, windows)
    f0 = F0 if f0 is None else f0
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                                 f0=f0, seed=seed, audio=False, link=link), judge=False)
    return _broken(loop, gesture, duration, fmax, seed)


def _broken(loop, gesture, duration, fmax, seed):
    if gesture == "hold":
        return _broken_holding(loop, duration)
    total = int(round(duration * loop.rate))
    block = loop.run(total)
    if loop.fault is not None:
        return True
    level, hiss, pitch = _bowing_measures(block, loop.rate)
    ref_level, ref_hiss, _ = _true_bowing(float(loop.rate), float(loop.string.f0), gesture, float(fmax), total,
                                          int(seed))
    floors = (stability.band_floor(loop.rate), stability.hiss_floor(loop.rate))
    return (stability.bowing_over(level, ref_level, hiss, ref_hiss, stability.RISE, floors)
            or not abs(pitch / loop.string.f0 - 1.0) <= stability.PITCH_TOLERANCE)


def _broken_holding(loop, duration):
    block = max(1, int(round(BLOCK * loop.rate)))
    settle = int(round(SETTLE * loop.rate))
    done = 0
    total = int(round(duration * loop.rate))
    while done < total:
        loop.run(block)
        done += block
        if loop.fault is not None or (done >= settle and loop.monitor.broken):
            return True
    return False


def _bowing_measures(block, rate):
    """(band level m/s, upper band level m/s or None, pitch Hz) of a bowing trial over [SETTLE, end].

    The handle's velocity is the true one; on a device, whose true motion the host cannot know, its LVT's."""
    velocity = block["velocity_true"]
    if not np.isfinite(velocity).any():
        velocity = block["velocity_lvt"]
    return bowing_reference.measures(velocity, block["string_velocity"], rate, int(round(SETTLE * rate)))


@functools.lru_cache(maxsize=4096)
def _true_bowing(rate, f0, gesture, fmax, total, seed):
    loop = ClosedLoop(LoopConfig(rate=rate, estimators={}, source="TRUE", fmax=fmax, gesture=gesture, f0=f0,
                                 seed=seed, audio=False), judge=False)
    return _bowing_measures(loop.run(total), loop.rate)


def breakdown_fmax(source, rate=5000.0, gesture="strokes", duration=DURATION, low=LOW, high=HIGH, tolerance=0.02,
                   seed=0, estimators=None, f0=None, progress=None, link=None, windows="seconds", make_loop=None):
    """The largest F_max (N) at which ``source`` stays stable, by bisection on a log scale.

    Stable means: ``is_broken`` is False (bowing ``strokes`` by default;
    ``gesture="hold"``: the hand holding the handle, with tremor). Returns ``low`` if even ``low`` breaks down and ``inf`` if
    ``high`` does not; otherwise the geometric midpoint of the final bracket,
    whose width is at most ``tolerance`` (relative). ``progress(fmax, broken)``
    is called after each trial. ``link``: the device's link (None: ideal); ``make_loop``: each trial's loop
    on a device of its own (``is_broken``). ``windows``: how Table 1 is made for the rate when ``estimators`` does not give the source (module doc).
    """
    kwargs = dict(rate=rate, gesture=gesture, duration=duration, seed=seed, estimators=estimators, f0=f0, link=link,
                  windows=windows, make_loop=make_loop)

    def trial(fmax):
        broken = is_broken(source, fmax, **kwargs)
        if progress is not None:
            progress(fmax, broken)
        return broken

    if trial(low):
        return low
    if not trial(high):
        return math.inf
    lo, hi = low, high
    while hi / lo > 1.0 + tolerance:
        mid = math.sqrt(lo * hi)
        if trial(mid):
            hi = mid
        else:
            lo = mid
    return math.sqrt(lo * hi)


def breakdown_over_seeds(source, rate=5000.0, seeds=5, gesture="strokes", duration=DURATION, tolerance=0.02, progress=None,
                         link=None, estimators=None, first_seed=0, windows="seconds"):
    """Breakdown F_max for seeds ``first_seed``..``first_seed`` + ``seeds`` - 1: a dict with exactly the keys ``KEYS``.

    ``fmax`` lists the seeds' values (N; inf when stable up to 200 N), in the
    order of ``seeds_used``; ``fmax_median``, ``fmax_min`` and ``fmax_max``
    summarise them.
    ``progress(seed, trial, fmax, verdict)`` is called after each trial with
    verdict "stable" or "broken" (trial counts from 1 within the seed), and
    once per seed with verdict "result", ``fmax`` the seed's breakdown F_max
    and ``trial`` the number of trials it took. ``link`` (a link.LinkSpec; None:
    ideal) is the device's link, ``latency``, ``packet`` and ``jitter`` its
    times (s); ``estimators``: name -> params of the estimators in the loop
    (the source's Table 1 made for the rate when not given, ``windows`` saying how: the module's doc).
    """
    check_source(source)
    rate = validate_rate(rate)
    seeds = check_seeds(seeds)
    first_seed = check_first_seed(first_seed, seeds)
    check_gesture(gesture)
    duration = check_duration(duration)
    check_windows(windows)
    used = list(range(first_seed, first_seed + seeds))
    values = []
    for seed in used:
        trials = []

        def on_trial(fmax, broken, seed=seed, trials=trials):
            trials.append(fmax)
            if progress is not None:
                progress(seed, len(trials), fmax, "broken" if broken else "stable")

        value = breakdown_fmax(source, rate=rate, gesture=gesture, duration=duration, tolerance=tolerance,
                               seed=seed, progress=on_trial, link=link, estimators=estimators, windows=windows)
        values.append(float(value))
        if progress is not None:
            progress(seed, len(trials), value, "result")
    return {"source": source, "rate": rate, "gesture": gesture, "seeds": seeds, "fmax": values,
            "fmax_median": float(np.median(values)), "fmax_min": min(values), "fmax_max": max(values),
            "first_seed": first_seed, "seeds_used": used, "windows": windows,
            **{name: getattr(link or IDEAL, name) for name in LINK_KEYS}}
