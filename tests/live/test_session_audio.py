"""A headless simulated sinclair2014 session archives its audio through the live signal chain (``studyapp run
... --simulated-participant --headless --audio wav``), and the archive passes the hearing-safety checks of
tests/audio_checks.py: no sample above the documented peak, no step starting louder than what follows, silence
with the bow lifted, and the level check's tone as loud as the bowed string."""

import csv
import re
import json
from pathlib import Path

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.engine.signal_chain import KNEE
from studyapp.model.stimulus_level import LINEAR_UP_TO_N
from tests import audio_checks as checks

ROOT = Path(__file__).resolve().parents[2]
SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"
DEMO = ROOT / "protocols" / "demo.toml"


def _run(results, protocol, *extra):
    code = main(["run", "--protocol", str(protocol), "--participant", "P01", "--simulated-participant", "--headless",
                 "--results", str(results), *extra])
    assert code == 0
    (folder,) = {p.parent for p in Path(results).glob("*/*/*/session.json")}
    return folder


@pytest.fixture(scope="module", params=[1, 2, 3])
def sinclair(request, tmp_path_factory):
    return _run(tmp_path_factory.mktemp("results"), SINCLAIR, "--audio", "wav", "--seed", str(request.param))


def test_the_session_folder_holds_the_audio_and_a_cue_for_every_step(sinclair):
    assert (sinclair / "audio.wav").exists() and (sinclair / "audio_cues.csv").exists()
    info = json.loads((sinclair / "session.json").read_text())
    with open(sinclair / "audio_cues.csv", newline="") as f:
        cues = list(csv.DictReader(f))
    steps = len(info["schedule"])
    assert sorted(int(c["step"]) for c in cues if c["event"] == "start") == list(range(steps))
    assert sorted(int(c["step"]) for c in cues if c["event"] == "end") == list(range(steps))
    assert {"bow_on", "bow_off"} <= {c["event"] for c in cues}


def test_no_sample_above_the_documented_peak(sinclair):
    checks.check_peak(checks.read_archive(sinclair))  # at most the ceiling, one 16-bit step of rounding allowed


def test_no_step_starts_louder_than_the_stimulus_that_follows_it(sinclair):
    onsets = checks.check_start_transients(checks.read_archive(sinclair))
    assert len(onsets) > 60


def test_the_bow_lifted_is_silent(sinclair):
    loudest, seconds = checks.check_silences(checks.read_archive(sinclair))
    assert seconds > 1.0 and loudest <= checks.SILENCE_DBFS


def test_the_level_check_is_as_loud_as_the_bowed_string(sinclair):
    tone, stimulus = checks.check_level_check(checks.read_archive(sinclair), tolerance_db=1.0)
    info = json.loads((sinclair / "session.json").read_text())
    (page,) = [s["page"] for s in info["schedule"] if s.get("page") and s["page"]["kind"] == "calibration"]
    assert page["level_dbfs"] == pytest.approx(tone + 3.01, abs=0.1)  # the tone played is the page's
    stated = float(re.search(r"(-?[0-9.]+) dBFS RMS", page["note"]).group(1))
    assert stated == pytest.approx(tone, abs=0.1)  # and the experimenter's note says so (to its 0.1 dB)
    assert "dBFS" not in page["text"]  # the participant's page does not (issue 31 item 10)


def test_the_stimulus_stays_under_the_knee_below_1_25_x_lvts_breakdown_and_the_cues_count_the_limiter(sinclair):
    archive = checks.read_archive(sinclair)
    events = [json.loads(line) for line in (sinclair / "events.jsonl").read_text().splitlines()]
    peak = {e["step"]: e["peak_fmax"] for e in events if e.get("type") == "response" and "peak_fmax" in e}
    knee = round(KNEE * 32767) / 32767  # one 16-bit step: the file's rounding
    for step, task, start, end in checks.steps(archive):
        if peak.get(step, 0.0) <= LINEAR_UP_TO_N:  # pages, the rating task, and adjustments below it
            assert np.sum(np.abs(archive.x[start:end]) > knee) == 0, (step, task, peak.get(step))
    above = int(np.sum(np.abs(archive.x) > KNEE))
    counted = sum(int(row["limited"]) for row in archive.cues)
    assert abs(counted - above) <= 2 + above // 1000  # the cues count what the limiter bent


def test_without_audio_nothing_is_archived(tmp_path):
    folder = _run(tmp_path, DEMO)
    assert not (folder / "audio.wav").exists() and not (folder / "audio_cues.csv").exists()


@pytest.mark.parametrize("value", ["device", "wav:x.wav", "loud"])
def test_a_bad_audio_option_is_one_line_and_writes_nothing(tmp_path, capsys, value):
    code = main(["run", "--protocol", str(DEMO), "--participant", "P01", "--simulated-participant", "--headless",
                 "--results", str(tmp_path), "--audio", value])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and f"--audio {value}" in err and "wav" in err
    assert not any(tmp_path.iterdir())
