"""Participant data is private by default (issue 14, item 10): folders 0700 and files
0600 whatever the umask; STUDYAPP_GROUP_SHARED=1 gives a lab group 0770 / 0660."""

import os
import stat
from pathlib import Path

import pytest

from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session

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
