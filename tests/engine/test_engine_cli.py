"""``studyapp live``: status lines, the JSON summary, a WAV sink, Ctrl-C, and one-line errors."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest
from scipy.io import wavfile

from studyapp.cli import main

KEYS = ["rate", "achieved_rate", "deadline_misses", "audio_underruns", "faults", "midi_messages"]


def _live(args, **kw):
    env = dict(os.environ, JACK_DEFAULT_SERVER=f"nobody-{os.getpid()}")
    return subprocess.Popen([sys.executable, "-m", "studyapp", "live", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **kw)


def test_live_runs_for_the_given_time_and_prints_one_json_object(tmp_path):
    wav = tmp_path / "out.wav"
    proc = _live(["--rate", "8000", "--source", "LOWPASS", "--fmax", "2", "--audio", f"wav:{wav}",
                  "--midi", "none", "--seconds", "2.5", "--json"])
    out, err = proc.communicate(timeout=180)
    assert proc.returncode == 0, err
    result = json.loads(out)
    assert list(result)[:len(KEYS)] == KEYS
    assert result["rate"] == 8000.0 and result["faults"] == [] and result["midi_messages"] == 0
    assert result["events_dropped"] == 0
    assert result["achieved_rate"] == pytest.approx(8000, rel=0.1)
    assert result["audio_underruns"] == 0
    assert result["seconds"] == pytest.approx(2.5, abs=0.5)
    status = [line for line in err.splitlines() if line.startswith("live: ") and " s  rate " in line]
    assert len(status) == 2 and "misses" in status[0] and "load" in status[0]
    fs, pcm = wavfile.read(wav)
    assert fs == 48000 and len(pcm) / fs == pytest.approx(result["seconds"], abs=0.3)


def _ctrl_c_reaches_python():
    # A suite started in the background by a shell without job control (a CI runner, `make test &`)
    # inherits SIGINT ignored, and Python then leaves it ignored; a terminal's Ctrl-C is never ignored.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_stops_cleanly_with_the_summary():
    proc = _live(["--audio", "null", "--midi", "none", "--json"], preexec_fn=_ctrl_c_reaches_python)
    deadline = time.monotonic() + 120
    lines = []
    while time.monotonic() < deadline:
        line = proc.stderr.readline()
        lines.append(line)
        if " s  rate " in line or not line:
            break
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, "".join(lines) + err
    result = json.loads(out)
    assert result["faults"] == [] and result["achieved_rate"] > 0
    assert "live: stopping" in err


@pytest.mark.parametrize("args, words", [
    (["--source", "NOPE"], "source 'NOPE'"),
    (["--audio", "speaker"], "--audio 'speaker'"),
    (["--fmax", "-1"], "fmax"),
    (["--estimators", "KALLEV,XYZ"], "--estimators"),
    (["--seconds", "0"], "--seconds"),
    (["--rate", "5"], "rate"),
])
def test_bad_options_are_one_line_and_exit_code_2(args, words, capsys):
    assert main(["live", "--midi", "none", "--audio", "null", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("studyapp: error:") and words in err[0]
