"""A session's recording after a kill (issue 41, item 15), with real SIGKILLs of ``run --headless --audio wav``.

On main a kill between ``wave``'s data write and its header patch left a WAV
header counting fewer frames than the file holds (1 of 20 kills at random
sizes), and ``--resume`` left it so. A session killed before its first audio
write had steps answered in events.jsonl with no row in audio_cues.csv. Now a
resume repairs every earlier recording's header from its size and says so, and
a headless session logs a response only once the recording and its cues up to
it are on disk."""

import csv
import json
import os
import random
import signal
import struct
import subprocess
import sys
import time
import wave
from pathlib import Path

import pytest

from studyapp.engine.audio import recorder as recorder_module
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.io.wav_header import repair_wav

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
RUN = ["run", "--protocol", str(DEMO), "--simulated-participant", "--headless", "--audio", "wav"]

# the run, its header patch held back once the file is past 20,000 bytes: a kill lands between the two
HELD = """
import sys, time, wave
from pathlib import Path
patch = wave.Wave_write._patchheader
def held(self):
    if self._datawritten > 20000:
        Path(sys.argv[1]).touch()
        time.sleep(600)
    patch(self)
wave.Wave_write._patchheader = held
from studyapp.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _header_frames(path):
    data = path.read_bytes()
    return struct.unpack("<I", data[40:44])[0] // 2, (len(data) - 44) // 2


def _wait(condition, process, timeout=120.0):
    deadline = time.monotonic() + timeout
    while not condition():
        if process.poll() is not None or time.monotonic() > deadline:
            return False
        time.sleep(0.0005)
    return True


def _kill(process):
    os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)


def _answered_without_cues(folder):
    events = []
    for line in (folder / "events.jsonl").read_bytes().splitlines():
        try:
            events.append(json.loads(line))
        except ValueError:
            continue  # a torn last line
    answered = {e["step"] for e in events if e.get("type") == "response"}
    cues = folder / "audio_cues.csv"
    rows = list(csv.DictReader(cues.open(newline=""))) if cues.exists() else []
    return answered - {int(r["step"]) for r in rows if r["step"]}


def test_a_kill_between_the_data_and_its_header_is_repaired_by_the_resume(tmp_path):
    results, marker = tmp_path / "R", tmp_path / "held"
    process = subprocess.Popen([sys.executable, "-c", HELD, str(marker), *RUN, "--participant", "K1",
                                "--results", str(results)], env=ENV, stdin=subprocess.DEVNULL,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        assert _wait(marker.exists, process)
    finally:
        _kill(process)
    (wav,) = results.glob("demo/K1/*/audio.wav")
    stated, held = _header_frames(wav)
    assert stated < held  # the defect, reproduced: the header counts fewer frames than the file holds
    with wave.open(str(wav)) as f:
        assert f.getnframes() == stated
    done = subprocess.run([sys.executable, "-m", "studyapp", *RUN, "--participant", "K1", "--results", str(results),
                           "--resume"], env=ENV, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stderr
    said = [line for line in done.stderr.splitlines() + done.stdout.splitlines() if "header repaired" in line]
    assert len(said) == 1 and f"{wav}: its header counted {stated} frames, the file holds {held}" in said[0]
    assert _header_frames(wav) == (held, held)
    with wave.open(str(wav)) as f:
        assert f.getnframes() == held
    assert (wav.parent / "audio-2.wav").exists() and repair_wav(wav.parent / "audio-2.wav") is None


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_kills_at_random_sizes_leave_every_answered_step_cued_and_the_resume_repairs_every_header(tmp_path, seed):
    protocol = load_protocol(DEMO)
    results, rng = tmp_path / "R", random.Random(seed)
    for kill in range(3):
        participant = f"S{seed}K{kill}"
        size = 44 if kill == 0 else rng.uniform(44, 600_000)  # the first: as soon as the file is there
        process = subprocess.Popen([sys.executable, "-m", "studyapp", *RUN, "--participant", participant,
                                    "--results", str(results)], env=ENV, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        found = lambda: any(p.stat().st_size >= size for p in results.glob(f"demo/{participant}/*/audio.wav"))  # noqa: E731
        try:
            _wait(found, process)
        finally:
            _kill(process)
        folders = list(results.glob(f"demo/{participant}/*/"))
        if not folders:
            continue  # killed before the session was made
        (folder,) = folders
        assert _answered_without_cues(folder) == set()
        wavs = sorted(folder.glob("audio*.wav"))
        short = {w for w in wavs if _header_frames(w)[0] != _header_frames(w)[1]}
        try:
            session = Session.resume(protocol, participant, results)
        except Exception as exc:  # complete already (killed after its last response): repaired all the same
            assert "already complete" in str(exc)
        else:
            assert sum("header repaired" in note for note in session.notes) == len(short)
            session.close()
        for w in wavs:
            assert _header_frames(w)[0] == _header_frames(w)[1]


def test_a_response_is_logged_only_once_its_step_is_cued(tmp_path, monkeypatch):
    """The writer held back (a loaded machine): the cue rows must still be on disk before each response."""
    from studyapp.cli import main
    from studyapp.experiment import session_log

    append_cue = recorder_module.AudioRecorder._append_cue

    def slow(self, row):
        time.sleep(0.05)
        append_cue(self, row)

    missing = []
    append = session_log.SessionLog.append

    def checked(self, event):
        if event.get("type") == "response":
            missing.extend(sorted(_answered_without_cues(Path(self.path).parent) | {event["step"]}
                                  - _cued(Path(self.path).parent)))
        return append(self, event)

    monkeypatch.setattr(recorder_module.AudioRecorder, "_append_cue", slow)
    monkeypatch.setattr(session_log.SessionLog, "append", checked)
    assert main([*RUN, "--participant", "C1", "--results", str(tmp_path / "R")]) == 0
    assert missing == []


def _cued(folder):
    cues = folder / "audio_cues.csv"
    return {int(r["step"]) for r in csv.DictReader(cues.open(newline=""))} if cues.exists() else set()


def test_repair_wav_counts_the_frames_on_disk_and_leaves_other_files_alone(tmp_path):
    path = tmp_path / "audio.wav"
    with wave.open(str(path), "wb") as f:
        f.setnchannels(1)
        f.setsampwidth(2)
        f.setframerate(48000)
        f.writeframes(struct.pack("<3h", 1, -2, 3))
    assert repair_wav(path) is None
    with open(path, "ab") as f:
        f.write(struct.pack("<2h", 4, -5) + b"\x07")  # two frames past the header's count, and a torn byte
    assert "counted 3 frames, the file holds 5" in repair_wav(path)
    with wave.open(str(path)) as f:
        assert struct.unpack("<5h", f.readframes(10)) == (1, -2, 3, 4, -5)
    assert path.stat().st_size == 44 + 10
    other = tmp_path / "notes.wav"
    other.write_bytes(b"not a wav file at all, but longer than forty-four bytes....")
    link = tmp_path / "link.wav"
    link.symlink_to(path)
    before = other.read_bytes(), path.read_bytes()
    assert repair_wav(other) is None and repair_wav(link) is None
    assert (other.read_bytes(), path.read_bytes()) == before
