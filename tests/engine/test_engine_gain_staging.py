"""Gain staging (issue 31): the stimulus stays linear, under the limiter's knee, at every F_max a protocol's knob
reaches below 1.25 x LVT's breakdown; the limiter counts every sample it bends; the level check is heard at the
stimulus level with the volume in force (within 1 dB at 0 and -10 dB).

Before: the rating task's 1 N had its peaks at the -12 dBFS ceiling and 9-21 % of its samples above the knee.
"""

import math

import numpy as np
import pytest

from studyapp.engine.audio.sinks import WAV_RATE
from studyapp.engine.signal_chain import CEILING_DBFS, KNEE, KNEE_DB, SignalChain
from studyapp.experiment import level_check
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.schedule import build_schedule
from studyapp.model import stimulus_level
from studyapp.model.controls import FmaxKnob
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.stimulus_level import LINEAR_UP_TO_N, short_term_rms_dbfs
from tests.experiment.test_experiment_cli import ROOT

SINCLAIR = load_protocol(ROOT / "protocols" / "sinclair2014.toml")
RATE = SINCLAIR.rate
BLOCK = 10  # 2 ms


def _loop(source, fmax, seed=0, gesture="strokes"):
    estimators = {} if source == "LVT" else {source: SINCLAIR.estimator_params(source)}
    return ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                                 seed=seed, audio=True))


def _heard(loop, chain, seconds):
    return np.concatenate([chain.process(loop.run(BLOCK)["audio"]) for _ in range(int(seconds * RATE / BLOCK))])


def test_the_gain_puts_the_loudest_bowing_below_the_knee_with_the_documented_headroom():
    assert CEILING_DBFS - KNEE_DB == stimulus_level.KNEE_DBFS == pytest.approx(20 * math.log10(KNEE))
    assert stimulus_level.STIMULUS_GAIN_DB == pytest.approx(
        stimulus_level.KNEE_DBFS - stimulus_level.HEADROOM_DB - stimulus_level.LOUDEST_DB)
    assert LINEAR_UP_TO_N == pytest.approx(1.25 * 8.29)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("source", ["LVT", "LOWPASS", "KALLEV"])
def test_a_hand_turning_the_knob_up_to_1_25_x_lvts_breakdown_is_never_limited(source, seed):
    adjustment = SINCLAIR.task("adjustment")
    law = FmaxKnob(adjustment.ceiling, adjustment.decades)
    loop, chain = _loop(source, 0.0, seed), SignalChain(RATE, WAV_RATE)
    peak, step = 0.0, 1
    while (fmax := law.fmax(step)) <= LINEAR_UP_TO_N:
        loop.set_fmax(fmax)
        peak = max(peak, float(np.max(np.abs(_heard(loop, chain, 0.1)))))  # a step every 0.1 s, as a hand turns
        step += 1
    assert fmax > LINEAR_UP_TO_N > law.fmax(step - 1)  # every step the knob reaches below it
    assert chain.limited == 0 and 20 * math.log10(peak) < stimulus_level.KNEE_DBFS - 1.0


@pytest.mark.parametrize("source", SINCLAIR.task("adjustment").conditions)
def test_every_condition_at_1_25_x_lvts_breakdown_stays_under_the_knee(source):
    chain = SignalChain(RATE, WAV_RATE)
    y = _heard(_loop(source, LINEAR_UP_TO_N), chain, 3.0)
    assert chain.limited == 0 and np.max(np.abs(y)) < KNEE


def test_the_limiter_counts_every_sample_it_bends_and_only_those():
    chain = SignalChain(RATE, WAV_RATE, gain=1.0)
    t = np.arange(5000) / RATE
    x = 0.2 * np.sin(2 * np.pi * 196 * t) * np.linspace(0, 1, t.size)  # from silence to 6 dB over the knee
    y = np.concatenate([chain.process(x[k:k + BLOCK]) for k in range(0, x.size, BLOCK)] + [chain.flush()])
    above = int(np.sum(np.abs(y) > KNEE))
    assert above > 1000 and chain.limited == above
    assert np.max(np.abs(y)) < 10 ** (CEILING_DBFS / 20)


@pytest.mark.parametrize("volume_db", [0.0, -10.0])
def test_the_level_check_is_heard_within_1_db_of_the_rating_stimulus_at_the_volume_in_force(volume_db):
    steps, _ = build_schedule(SINCLAIR, 0)
    (page,) = [s.page for s in steps if s.page is not None and s.page.kind == "calibration"]
    gain = 10 ** (volume_db / 20)
    chain = SignalChain(RATE, WAV_RATE)
    chain.gain.set_volume(gain)
    chain.tone.set(page.tone_hz, page.level_dbfs)
    tone = np.concatenate([chain.silence(BLOCK) for _ in range(500)])[int(0.1 * WAV_RATE):]
    levels = []
    for source in SINCLAIR.task("rating").conditions:  # the string as the participant hears it, each knob
        chain = SignalChain(RATE, WAV_RATE)
        chain.gain.set_volume(gain)
        heard = _heard(_loop(source, SINCLAIR.task("rating").fmax, SINCLAIR.seed), chain, 4.0)
        levels.append(short_term_rms_dbfs(heard[int(1.0 * WAV_RATE):], WAV_RATE))
    stimulus = float(np.median(levels))
    tone_rms = 20 * math.log10(np.sqrt(np.mean(tone**2)))
    assert abs(tone_rms - stimulus) <= 1.0, (tone_rms, stimulus)
    assert tone_rms == pytest.approx(page.level_dbfs - 3.01 + volume_db, abs=0.05)  # the page's level, x volume


def test_the_engine_reports_every_sample_its_limiter_bent(tmp_path):
    import time

    from scipy.io import wavfile

    from studyapp.engine import commands as cmd
    from studyapp.engine.config import EngineConfig
    from studyapp.engine.engine import Engine

    path = tmp_path / "loud.wav"
    config = EngineConfig(rate=RATE, estimators={}, source="LVT", fmax=40.0, audio=f"wav:{path}", midi="none",
                          realtime=False)  # 40 N: far above 1.25 x LVT's breakdown, bent by the limiter
    with Engine(config) as engine:
        engine.send(cmd.SetBowing(True))
        time.sleep(1.5)
        status = engine.status()
    summary = engine.summary
    _, pcm = wavfile.read(path)
    above = int(np.sum(np.abs(pcm / 32767.0) > KNEE))
    assert status["audio_limited"] > 0 and summary["audio_limited"] >= status["audio_limited"]
    assert abs(summary["audio_limited"] - above) <= 2 + above // 1000  # the file's rounding
