"""The output levels docs/engine.md quotes: the limiter's ceiling, the stimulus, the level check's tone.

    PYTHONPATH=. python scripts/audio_levels.py [--protocol protocols/sinclair2014.toml] [--session FOLDER]

Prints, for the model as it is now (5 kHz, seed 0, through the engine's
signal chain at volume 1, engine/signal_chain.py):

- the chain's documented ceiling (peak) and its limiter's knee;
- the bowed string's peak, RMS and typical (median 100 ms) RMS with the
  protocol's gesture and with the hand holding, at F_max 0 to 40 N, for LVT,
  LOWPASS and KALLEV, and how many samples reach full scale (none can);
- the protocol's level check: the F_max it is calibrated to, the string's
  typical RMS there (``level_check.stimulus_rms_dbfs``) and the tone's peak;

and with ``--session FOLDER`` (a session folder with audio.wav, e.g. from
``studyapp run ... --simulated-participant --headless --audio wav``), the
archive's checks (tests/audio_checks.py): its peak, the loudest step onset
against what follows, the loudest silence, and the tone's RMS against the
rating stimulus's.
"""

import argparse
import math

import numpy as np

from studyapp.engine.audio.sinks import WAV_RATE
from studyapp.engine.signal_chain import CEILING_DBFS, KNEE_DB, SignalChain
from studyapp.experiment.level_check import stimulus_rms_dbfs
from studyapp.experiment.protocol import load_protocol
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.stimulus_level import short_term_rms_dbfs, tone_peak_dbfs

FMAX = (0.0, 1.0, 5.0, 10.0, 20.0, 40.0)
SOURCES = ("LVT", "LOWPASS", "KALLEV")


def db(x):
    return 20 * math.log10(x) if x > 0 else -math.inf


def heard(protocol, source, fmax, gesture, seconds=6.0):
    """The chain's output (volume 1, bow on) for ``seconds`` of the loop, after its first second."""
    params = {} if source == "LVT" else {source: protocol.estimator_params(source)}
    loop = ClosedLoop(LoopConfig(rate=protocol.rate, estimators=params, source=source, fmax=fmax,
                                 gesture=gesture, seed=0, audio=True))
    chain = SignalChain(protocol.rate, WAV_RATE)
    block = int(protocol.rate * 0.002)
    out = [chain.process(loop.run(block)["audio"], sounding=True) for _ in range(int(seconds / 0.002))]
    return np.concatenate(out)[int(WAV_RATE):]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--protocol", default="protocols/sinclair2014.toml")
    parser.add_argument("--session", help="a session folder with audio.wav and audio_cues.csv")
    args = parser.parse_args()
    protocol = load_protocol(args.protocol)
    print(f"ceiling {CEILING_DBFS:g} dBFS peak; the limiter bends above {CEILING_DBFS - KNEE_DB:g} dBFS")
    print("gesture   source    F_max   peak    RMS   typical RMS  (dBFS)  full-scale samples")
    for gesture in (protocol.gesture, "hold"):
        for source in SOURCES:
            for fmax in FMAX:
                y = heard(protocol, source, fmax, gesture)
                print(f"{gesture:9s} {source:8s} {fmax:5.1f} {db(np.max(np.abs(y))):6.1f} "
                      f"{db(np.sqrt(np.mean(y ** 2))):6.1f} {short_term_rms_dbfs(y, WAV_RATE):8.1f} "
                      f"{int(np.sum(np.abs(y) >= 1.0)):12d}")
    rms, fmax, task = stimulus_rms_dbfs(protocol)
    print(f"level check ({protocol.study}): the string's typical RMS at F_max = {fmax:g} N ({task} task) "
          f"{rms:.1f} dBFS; the tone: RMS {rms:.1f} dBFS, peak {tone_peak_dbfs(rms):.1f} dBFS")
    if args.session:
        from tests import audio_checks as checks

        archive = checks.read_archive(args.session)
        onsets = checks.check_start_transients(archive)
        sounding = [(step, onset, rest) for step, onset, rest in onsets if onset > -math.inf]
        worst = max(sounding, key=lambda s: s[1] - s[2]) if sounding else None
        loudest, seconds = checks.check_silences(archive)
        tone, stimulus = checks.check_level_check(archive)
        print(f"archive {args.session}: {archive.x.size / archive.rate:.0f} s; peak {checks.check_peak(archive):.1f} dBFS; "
              f"loudest onset {max(o for _, o, _ in onsets):.1f} dBFS"
              + (f" (step {worst[0]}: onset {worst[1]:.1f}, then {worst[2]:.1f} dBFS)" if worst else "")
              + f"; silences ({seconds:.1f} s) peak {loudest:.1f} dBFS; tone {tone:.1f} dBFS RMS, "
              f"rating stimulus {stimulus:.1f} dBFS RMS")


if __name__ == "__main__":
    main()
