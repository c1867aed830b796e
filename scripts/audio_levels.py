"""The output levels docs/engine.md quotes: the gain staging, the stimulus, the level check, the audible breakdown.

    PYTHONPATH=. python scripts/audio_levels.py [--protocol protocols/sinclair2014.toml] [--session FOLDER ...]
                                                [--rise]

Prints, for the model as it is now (5 kHz, seed 0, through the engine's
signal chain at volume 0 dB, engine/signal_chain.py):

- the chain's ceiling (peak), its limiter's knee, the fixed stimulus gain and
  the F_max up to which the stimulus is linear (model/stimulus_level.py);
- the bowed string's peak, RMS, typical (median 100 ms) RMS, share of samples
  above the knee (the samples the limiter bends) and level below the pitch
  (model/buzz_level.py) with the protocol's gesture and with the hand
  holding, at F_max 0 to 40 N, for LVT, LOWPASS and KALLEV;
- the protocol's level check: the F_max it is calibrated to, the string's
  typical RMS there (``level_check.stimulus_rms_dbfs``) and the tone's peak;

with ``--rise``, the level below the pitch at 0.5, 0.8 and 1.25 x each
source's breakdown (bowed with the strokes, the knob stepping up, seeds 0-2;
as tests/engine/test_engine_audible_breakdown.py measures it); and with
``--session FOLDER`` (a session folder with audio.wav, e.g. from ``studyapp
run ... --simulated-participant --headless --audio wav``), the archive's
checks (tests/audio_checks.py): its peak, samples above the knee and what the
cues' ``limited`` column counted, the loudest step onset against what
follows, the loudest silence, and the tone's RMS against the rating stimulus's.
"""

import argparse
import math
from pathlib import Path

import numpy as np

from studyapp.engine.audio.sinks import WAV_RATE
from studyapp.engine.signal_chain import CEILING_DBFS, KNEE, SignalChain
from studyapp.experiment.level_check import stimulus_rms_dbfs
from studyapp.experiment.protocol import load_protocol
from studyapp.model import stimulus_level
from studyapp.model.buzz_level import buzz_dbfs
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.stimulus_level import short_term_rms_dbfs, tone_peak_dbfs

from quoted_figures import bowing_breakdowns  # scripts/, beside this one

ROOT = Path(__file__).resolve().parents[1]

FMAX = (0.0, 1.0, 5.0, stimulus_level.LINEAR_UP_TO_N, 20.0, 40.0)
SOURCES = ("LVT", "LOWPASS", "KALLEV")
FACTORS = (0.5, 0.8, 1.25)


def db(x):
    return 20 * math.log10(x) if x > 0 else -math.inf


def heard(protocol, source, fmaxes, gesture, seconds=6.0, seed=0):
    """The chain's output (volume 0 dB, bow on), ``seconds`` at each F_max in turn, each after its first second."""
    params = {} if source == "LVT" else {source: protocol.estimator_params(source)}
    loop = ClosedLoop(LoopConfig(rate=protocol.rate, estimators=params, source=source, fmax=fmaxes[0],
                                 gesture=gesture, seed=seed, audio=True))
    chain = SignalChain(protocol.rate, WAV_RATE)
    block = int(protocol.rate * 0.002)
    parts = []
    for fmax in fmaxes:
        loop.set_fmax(fmax)
        out = [chain.process(loop.run(block)["audio"], sounding=True) for _ in range(int(seconds / 0.002))]
        parts.append(np.concatenate(out)[int(WAV_RATE):])
    return parts


def levels(protocol):
    print("gesture   source    F_max   peak    RMS  typical RMS (dBFS)  above knee  below pitch (dBFS)")
    for gesture in (protocol.gesture, "hold"):
        for source in SOURCES:
            for fmax in FMAX:
                (y,) = heard(protocol, source, (fmax,), gesture)
                print(f"{gesture:9s} {source:8s} {fmax:5.1f} {db(np.max(np.abs(y))):6.1f} "
                      f"{db(np.sqrt(np.mean(y ** 2))):6.1f} {short_term_rms_dbfs(y, WAV_RATE):8.1f} "
                      f"{100 * np.mean(np.abs(y) > KNEE):14.2f} % {buzz_dbfs(y, WAV_RATE):10.1f}")


def rise(protocol):
    breakdown = bowing_breakdowns((ROOT / "docs" / "breakdown.md").read_text(), protocol.rate)  # N
    print("source   seed  below pitch at " + " / ".join(f"{k:g} x" for k in FACTORS) + " breakdown (dBFS)  rise")
    for source in SOURCES:
        for seed in (0, 1, 2):
            parts = heard(protocol, source, [k * breakdown[source] for k in FACTORS], "strokes", 2.0, seed)
            b = [buzz_dbfs(y, WAV_RATE) for y in parts]
            print(f"{source:8s} {seed:4d}  " + " / ".join(f"{v:6.1f}" for v in b)
                  + f"   {b[-1] - b[0]:5.1f} dB from 0.5 x, {b[-1] - b[1]:5.1f} dB from 0.8 x")


def archive_checks(folder):
    from tests import audio_checks as checks

    archive = checks.read_archive(folder)
    onsets = checks.check_start_transients(archive)
    sounding = [(step, onset, rest) for step, onset, rest in onsets if onset > -math.inf]
    worst = max(sounding, key=lambda s: s[1] - s[2]) if sounding else None
    loudest, seconds = checks.check_silences(archive)
    tone, stimulus = checks.check_level_check(archive, tolerance_db=1.0)
    counted = sum(int(row["limited"]) for row in archive.cues)
    print(f"archive {folder}: {archive.x.size / archive.rate:.0f} s; peak {checks.check_peak(archive):.1f} dBFS; "
          f"{int(np.sum(np.abs(archive.x) > KNEE))} samples above the knee ({counted} in the cues); "
          f"loudest onset {max(o for _, o, _ in onsets):.1f} dBFS"
          + (f" (step {worst[0]}: onset {worst[1]:.1f}, then {worst[2]:.1f} dBFS)" if worst else "")
          + f"; silences ({seconds:.1f} s) peak {loudest:.1f} dBFS; tone {tone:.1f} dBFS RMS, "
          f"rating stimulus {stimulus:.1f} dBFS RMS")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--protocol", default="protocols/sinclair2014.toml")
    parser.add_argument("--session", nargs="*", default=[], help="session folders with audio.wav and audio_cues.csv")
    parser.add_argument("--rise", action="store_true", help="the level below the pitch across each breakdown")
    args = parser.parse_args()
    protocol = load_protocol(args.protocol)
    print(f"ceiling {CEILING_DBFS:g} dBFS peak; the limiter bends above {stimulus_level.KNEE_DBFS:g} dBFS; "
          f"stimulus gain {stimulus_level.STIMULUS_GAIN_DB:g} dB, linear up to "
          f"{stimulus_level.LINEAR_UP_TO_N:.1f} N (1.25 x LVT's breakdown)")
    levels(protocol)
    rms, fmax, task = stimulus_rms_dbfs(protocol)
    print(f"level check ({protocol.study}): the string's typical RMS at F_max = {fmax:g} N ({task} task) "
          f"{rms:.1f} dBFS; the tone: RMS {rms:.1f} dBFS, peak {tone_peak_dbfs(rms):.1f} dBFS (before the volume)")
    if args.rise:
        rise(protocol)
    for folder in args.session:
        archive_checks(folder)


if __name__ == "__main__":
    main()
