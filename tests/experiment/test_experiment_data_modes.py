"""Participant data is private by default (issue 14, item 10): folders 0700 and files
0600 whatever the umask; STUDYAPP_GROUP_SHARED=1 gives a lab group 0770 / 0660."""

import os
import stat
from pathlib import Path

import pytest

from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.live.test_session_controller import controller  # noqa: F401 - the fixture

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"


@pytest.fixture
def open_umask():
    old = os.umask(0o022)  # the usual umask, which alone would give 0755 and 0644
    yield
    os.umask(old)


def modes(results):
    return {str(p.relative_to(results)) if p != results else ".": stat.S_IMODE(p.stat().st_mode)
            for p in [results, *results.rglob("*")]}


@pytest.mark.parametrize("shared,folder,file", [(None, 0o700, 0o600), ("1", 0o770, 0o660)])
def test_folders_and_files_get_the_modes_of_the_setting(tmp_path, monkeypatch, open_umask, shared, folder, file):
    if shared is None:
        monkeypatch.delenv("STUDYAPP_GROUP_SHARED", raising=False)
    else:
        monkeypatch.setenv("STUDYAPP_GROUP_SHARED", shared)
    results = tmp_path / "results"
    session = Session.create(load_protocol(DEMO), "M01", results)
    session.close()
    events_file = session.folder / "events.jsonl"
    events_file.write_bytes(events_file.read_bytes() + b'{"torn')
    Session.resume(load_protocol(DEMO), "M01", results).close()  # writes a torn-line copy too
    found = modes(results)
    relative = session.folder.relative_to(results)
    expected = {".": folder, "demo": folder, "demo/.lock": file, "demo/M01": folder, "demo/M01/.lock": file,
                str(relative): folder, f"{relative}/session.json": file, f"{relative}/events.jsonl": file}
    torn = [name for name in found if ".torn-" in name]
    assert len(torn) == 1
    assert found == {**expected, torn[0]: file}


@pytest.mark.parametrize("shared,file", [(None, 0o600), ("1", 0o660)])
def test_the_audio_kept_with_a_session_gets_the_mode_of_its_files(tmp_path, monkeypatch, open_umask, shared, file):
    """issue 21, item 16: audio*.wav and audio_cues.csv are participant data too, whatever the umask."""
    import numpy as np

    from studyapp.engine import commands as cmd
    from studyapp.engine.audio.recorder import AudioRecorder
    from studyapp.experiment.data_modes import file_mode

    if shared is None:
        monkeypatch.delenv("STUDYAPP_GROUP_SHARED", raising=False)
    else:
        monkeypatch.setenv("STUDYAPP_GROUP_SHARED", shared)
    # what the session controller sends the engine's worker
    sent = cmd.RecordAudio(str(tmp_path / "audio.wav"), file_mode())
    for _ in range(2):  # audio.wav, then audio-2.wav (a later engine run of the session)
        recorder = AudioRecorder(sent.path, 48000.0, sent.mode)
        recorder.cue(0, "rating", 1, "start")
        recorder.write(np.zeros(480))
        recorder.stop()
        assert recorder.join(10)
    assert {p.name: stat.S_IMODE(p.stat().st_mode) for p in tmp_path.iterdir()} == {
        "audio.wav": file, "audio-2.wav": file, "audio_cues.csv": file}


@pytest.mark.parametrize("shared,file", [(None, 0o600), ("1", 0o660)])
def test_the_session_controller_asks_the_engine_for_that_mode(controller, monkeypatch, shared, file):
    from studyapp.engine import commands as cmd
    from tests.live.test_session_controller import start, up

    if shared is None:
        monkeypatch.delenv("STUDYAPP_GROUP_SHARED", raising=False)
    else:
        monkeypatch.setenv("STUDYAPP_GROUP_SHARED", shared)
    start(controller)
    up(controller)
    (sent,) = controller.host.engine.sent_of(cmd.RecordAudio)
    assert sent.path == str(controller.session.folder / "audio.wav") and sent.mode == file


@pytest.mark.parametrize("shared,file", [(None, 0o600), ("1", 0o660)])
def test_a_headless_session_archives_its_audio_with_that_mode(tmp_path, monkeypatch, open_umask, shared, file):
    """The headless archive (run --simulated-participant --headless --audio wav) writes participant data too."""
    from studyapp.cli import main

    if shared is None:
        monkeypatch.delenv("STUDYAPP_GROUP_SHARED", raising=False)
    else:
        monkeypatch.setenv("STUDYAPP_GROUP_SHARED", shared)
    code = main(["run", "--protocol", str(DEMO), "--participant", "H01", "--simulated-participant", "--headless",
                 "--results", str(tmp_path), "--audio", "wav", "--seed", "3"])
    assert code == 0
    audio = {p.name: stat.S_IMODE(p.stat().st_mode) for p in tmp_path.rglob("audio*")}
    assert audio == {"audio.wav": file, "audio_cues.csv": file}
