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


def check_cues(folder):
    assert (folder / "audio.wav").exists() and (folder / "audio_cues.csv").exists()
    info = json.loads((folder / "session.json").read_text())
    with open(folder / "audio_cues.csv", newline="") as f:
        cues = list(csv.DictReader(f))
    steps = len(info["schedule"])
    assert sorted(int(c["step"]) for c in cues if c["event"] == "start") == list(range(steps))
    assert sorted(int(c["step"]) for c in cues if c["event"] == "end") == list(range(steps))
    assert {"bow_on", "bow_off"} <= {c["event"] for c in cues}


def check_level_check(folder, archive):
    tone, stimulus = checks.check_level_check(archive, tolerance_db=1.0)
    info = json.loads((folder / "session.json").read_text())
    (page,) = [s["page"] for s in info["schedule"] if s.get("page") and s["page"]["kind"] == "calibration"]
    assert page["level_dbfs"] == pytest.approx(tone + 3.01, abs=0.1)  # the tone played is the page's
    stated = float(re.search(r"(-?[0-9.]+) dBFS RMS", page["note"]).group(1))
    assert stated == pytest.approx(tone, abs=0.1)  # and the experimenter's note says so (to its 0.1 dB)
    assert "dBFS" not in page["text"]  # the participant's page does not (issue 31 item 10)


def check_knee(folder, archive):
    """The stimulus stays under the knee below 1.25 x LVT's breakdown, and the cues count the limiter."""
    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    peak = {e["step"]: e["peak_fmax"] for e in events if e.get("type") == "response" and "peak_fmax" in e}
    knee = round(KNEE * 32767) / 32767  # one 16-bit step: the file's rounding
    for step, task, start, end in checks.steps(archive):
        if peak.get(step, 0.0) <= LINEAR_UP_TO_N:  # pages, the rating task, and adjustments below it
            assert np.sum(np.abs(archive.x[start:end]) > knee) == 0, (step, task, peak.get(step))
    above = int(np.sum(np.abs(archive.x) > KNEE))
    counted = sum(int(row["limited"]) for row in archive.cues)
    assert abs(counted - above) <= 2 + above // 1000  # the cues count what the limiter bent


# One test per seed, so that each session runs once whichever worker takes it (a module fixture runs again
# on every worker that takes one of its tests).
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_sinclair2014_sessions_archived_audio_is_safe_to_hear(tmp_path, seed):
    folder = _run(tmp_path, SINCLAIR, "--audio", "wav", "--seed", str(seed))
    check_cues(folder)
    archive = checks.read_archive(folder)
    checks.check_peak(archive)  # at most the ceiling, one 16-bit step of rounding allowed
    assert len(checks.check_start_transients(archive)) > 60  # no step starts louder than what follows it
    loudest, seconds = checks.check_silences(archive)  # the bow lifted is silent
    assert seconds > 1.0 and loudest <= checks.SILENCE_DBFS
    check_level_check(folder, archive)  # the level check's tone is as loud as the bowed string
    check_knee(folder, archive)


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
