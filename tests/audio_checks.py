"""Checks of a session's archived audio (audio.wav and audio_cues.csv), for any test that has one.

Made for the headless simulated session (tests/live/test_session_audio.py)
and meant for the GUI end-to-end test too: every function takes the session
folder's ``Archive`` and returns what it measured, raising ``AssertionError``
with the figures when a check fails.

    archive = read_archive(folder)
    check_peak(archive)                 # no sample above the chain's documented ceiling, none at full scale
    check_start_transients(archive)     # no step starts louder than the stimulus that follows it
    check_silences(archive)             # silence while the bow is lifted and on pages without a tone
    check_level_check(archive)          # the level check's tone as loud (RMS) as the bowed string
"""

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.fft
from scipy.io import wavfile

from studyapp.engine.signal_chain import CEILING_DBFS, FADE_S
from studyapp.model.stimulus_level import short_term_rms_dbfs

SILENCE_DBFS = -60.0  # a silence's peak may not exceed this (the fades' last samples, smeared by the resampler)
GUARD_S = 0.004  # s after a boundary where the resampler's filter still carries the sound before it
ONSET_S = 0.05  # s: the start of a step where a thump would be


@dataclass
class Archive:
    rate: float
    x: np.ndarray  # the file's samples, full scale 1.0
    cues: list  # the rows of audio_cues.csv for this file: dicts with int "sample"
    pcm_peak: int  # the largest |sample| in the file, in 16-bit units
    tone_steps: frozenset = frozenset()  # the steps of the level check's pages (they play the reference tone)


def read_archive(folder, name="audio.wav"):
    folder = Path(folder)
    rate, pcm = wavfile.read(folder / name)
    with open(folder / "audio_cues.csv", newline="", encoding="utf-8") as f:
        cues = [{**row, "sample": int(row["sample"])} for row in csv.DictReader(f) if row["file"] == name]
    info = folder / "session.json"
    schedule = json.loads(info.read_text())["schedule"] if info.exists() else []
    tone = frozenset(s["step"] for s in schedule if (s.get("page") or {}).get("kind") == "calibration")
    peak = int(np.max(np.abs(pcm.astype(np.int32)))) if pcm.size else 0
    return Archive(float(rate), pcm / 32767.0, cues, peak, tone)


def dbfs(x):
    return 20.0 * math.log10(x) if x > 0 else -math.inf


def peak_dbfs(x):
    return dbfs(float(np.max(np.abs(x)))) if len(x) else -math.inf


def rms_dbfs(x):
    return dbfs(float(np.sqrt(np.mean(np.square(x))))) if len(x) else -math.inf


def steps(archive):
    """``[(step, task, start, end)]``: each step's span in samples, from its start cue to its end cue."""
    spans, open_ = [], {}
    for row in archive.cues:
        if row["event"] == "start":
            open_[row["step"]] = (row["task"], row["sample"])
        elif row["event"] == "end" and row["step"] in open_:
            task, start = open_.pop(row["step"])
            spans.append((int(row["step"]), task, start, row["sample"]))
    end = archive.x.size
    spans += [(int(step), task, start, end) for step, (task, start) in open_.items()]
    return sorted(spans, key=lambda s: s[2])


def bow_spans(archive, on=False):
    """Spans (start, end) in samples with the bow lifted (``on`` False) or on the string (True), within steps."""
    spans = []
    for step, task, start, end in steps(archive):
        if task == "page":
            continue
        bowing, since = False, start
        marks = [r for r in archive.cues if r["step"] == str(step) and r["event"] in ("bow_on", "bow_off")]
        for row in marks:
            now = row["event"] == "bow_on"
            if now != bowing:
                if bowing == on and row["sample"] > since:
                    spans.append((since, row["sample"]))
                bowing, since = now, row["sample"]
        if bowing == on and end > since:
            spans.append((since, end))
    return spans


def check_peak(archive, ceiling_dbfs=CEILING_DBFS):
    """No sample above the ceiling (one 16-bit step of rounding allowed), none at full scale; returns the peak."""
    top = round(10 ** (ceiling_dbfs / 20) * 32767)
    full = int(np.sum(np.abs(archive.x) >= 1.0))
    assert archive.pcm_peak <= top and full == 0, (
        f"peak {dbfs(archive.pcm_peak / 32767):.2f} dBFS above the ceiling {ceiling_dbfs:g} dBFS "
        f"({full} samples at full scale)")
    return dbfs(archive.pcm_peak / 32767)


def check_start_transients(archive, onset_s=ONSET_S, margin_db=0.0):
    """Each step's first ``onset_s`` no louder (peak) than the rest of the step; returns [(step, onset, rest)].

    The level check's pages (session.json's calibration pages) are left out: their onset is the tone's ramp,
    and the experimenter may confirm the level before the tone has lasted ``onset_s``.
    """
    n = int(round(onset_s * archive.rate))
    found, bad = [], []
    for step, task, start, end in steps(archive):
        if step in archive.tone_steps:
            continue
        onset = peak_dbfs(archive.x[start:min(start + n, end)])
        rest = peak_dbfs(archive.x[start + n:end])
        found.append((step, onset, rest))
        if onset > rest + margin_db and onset > SILENCE_DBFS:
            bad.append(f"step {step} ({task}): onset {onset:.1f} dBFS peak, then {rest:.1f}")
    assert not bad, "start transients louder than the stimulus after them: " + "; ".join(bad)
    return found


def check_silences(archive, silence_dbfs=SILENCE_DBFS, guard_s=GUARD_S):
    """Silence (peak at most ``silence_dbfs``) while the bow is lifted and on pages without a tone.

    Returns ``(loudest peak dBFS, seconds checked)``.
    """
    guard = int(round(guard_s * archive.rate))
    spans = list(bow_spans(archive, on=False))
    # The tone is mixed after the chain's lookahead (FADE_S) while cues count it, so its ramp starts up to
    # FADE_S before its page's start cue (docs/engine.md): the span before a tone page ends that much earlier.
    tone_starts = {start for step, _, start, _ in steps(archive) if step in archive.tone_steps}
    early = int(round(FADE_S * archive.rate))
    for step, task, start, end in steps(archive):
        tone = step in archive.tone_steps or _has_tone(archive.x[start + guard:end - guard], archive.rate)
        if task == "page" and not tone:
            spans.append((start, end - early if any(0 <= s - end <= guard for s in tone_starts) else end))
    loudest, seconds, bad = -math.inf, 0.0, []
    for start, end in spans:
        x = archive.x[start + guard:max(end - guard, start + guard)]
        if not x.size:
            continue
        peak = peak_dbfs(x)
        loudest, seconds = max(loudest, peak), seconds + x.size / archive.rate
        if peak > silence_dbfs:
            bad.append(f"{start / archive.rate:.3f}-{end / archive.rate:.3f} s: {peak:.1f} dBFS")
    assert not bad, f"sound where silence is expected (peak above {silence_dbfs:g} dBFS): " + "; ".join(bad[:10])
    return loudest, seconds


def _has_tone(x, rate):
    """True if ``x`` is mostly one steady sine (the level check's tone)."""
    if x.size < rate * 0.1:
        return False
    # the longest prefix of a length the FFT factors quickly (within a few per cent of the span): an
    # awkward length (a large prime factor) takes seconds on a page minutes long
    x = x[:scipy.fft.prev_fast_len(x.size, real=True)]
    spectrum = np.abs(scipy.fft.rfft(x * np.hanning(x.size))) ** 2
    k = int(np.argmax(spectrum))
    return spectrum[max(k - 3, 0):k + 4].sum() > 0.9 * spectrum.sum()


def tone_rms_dbfs(archive):
    """The RMS of the level check's tone (dBFS), over the calibration page(s) minus their ramps; None if none."""
    levels = []
    for step, task, start, end in steps(archive):
        x = archive.x[start:end]
        if task == "page" and _has_tone(x, archive.rate):
            cut = int(0.05 * archive.rate)
            levels.append(rms_dbfs(x[cut:-cut]))
    return max(levels) if levels else None


def stimulus_rms_dbfs(archive, task="rating"):
    """The typical RMS (median of 100 ms RMS, dBFS) of the string while bowed in ``task``'s steps."""
    x = np.concatenate([archive.x[start:end] for start, end in _task_bow_spans(archive, task)] or [np.zeros(0)])
    return short_term_rms_dbfs(x, archive.rate)


def _task_bow_spans(archive, task):
    """The bow-on spans inside ``task``'s steps, less their first 0.5 s (the string building up)."""
    skip = int(0.5 * archive.rate)
    owned = [(a, b) for _, t, a, b in steps(archive) if t == task]
    return [(start + skip, end) for start, end in bow_spans(archive, on=True)
            if end - start > skip and any(a <= start < b for a, b in owned)]


def check_level_check(archive, task="rating", tolerance_db=2.0):
    """The level check's tone RMS within ``tolerance_db`` of the string's typical RMS in ``task``.

    Returns ``(tone dBFS RMS, stimulus dBFS RMS)``.
    """
    tone = tone_rms_dbfs(archive)
    stimulus = stimulus_rms_dbfs(archive, task)
    assert tone is not None, "no level check's tone in the archive"
    assert abs(tone - stimulus) <= tolerance_db, (
        f"the level check's tone {tone:.1f} dBFS RMS, the {task} stimulus {stimulus:.1f} dBFS RMS")
    return tone, stimulus
