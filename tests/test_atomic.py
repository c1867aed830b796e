"""Outputs are written whole or not at all, with the usual permissions; a killed writer leaves no temporary."""

import os
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.io.atomic import atomic_open, atomic_path


def test_complete_write_replaces_target(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with atomic_open(target) as f:
        f.write("new")
    assert target.read_text() == "new"
    assert os.listdir(tmp_path) == ["out.csv"]


def test_failure_leaves_target_and_no_temporary(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_open(target) as f:
            f.write("half")
            raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert os.listdir(tmp_path) == ["out.csv"]


def test_permissions_follow_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        with atomic_open(tmp_path / "out.csv") as f:
            f.write("x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "out.csv").stat().st_mode) == 0o644


# --- issue 21, item 8: a killed writer leaves no visible temporary, or the next write removes it ---

REPO = Path(__file__).resolve().parents[1]

KILLED_WRITER = """import sys, time
from studyapp.io.atomic import atomic_open, atomic_path
if sys.argv[2] == "open":
    with atomic_open(sys.argv[1]) as f:
        f.write("half")
        f.flush()
        print("writing", flush=True)
        time.sleep(60)
else:
    with atomic_path(sys.argv[1]) as tmp:
        tmp.write_text("half")
        print("writing", flush=True)
        time.sleep(60)
"""


def killed_while_writing(target, how):
    writer = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, str(target), how], cwd=REPO,
                              stdout=subprocess.PIPE, text=True)
    assert writer.stdout.readline().strip() == "writing"
    writer.send_signal(signal.SIGKILL)
    writer.wait()


def test_a_killed_export_leaves_no_temporary(tmp_path):
    """``studyapp export`` killed while it writes the CSV (its table written to a blocked pipe)."""
    from studyapp.experiment.protocol import load_protocol
    from studyapp.experiment.session import Session

    session = Session.create(load_protocol(REPO / "protocols" / "demo.toml"), "K01", tmp_path / "results")
    session.log.append({"type": "response", "step": 3, "task": "adjustment", "condition": "LVT", "trial": 1,
                        "fmax": 2.5, "value": 60, "peak_fmax": 3.0, "duration": 4.0})
    session.close()
    out = tmp_path / "out"
    out.mkdir()
    code = ("import sys, time, pandas\n"
            "real = pandas.DataFrame.to_csv\n"
            "def slow(self, f, **kw):\n"
            "    real(self, f, **kw)\n"
            "    f.flush()\n"
            "    print('writing', flush=True)\n"
            "    time.sleep(60)\n"
            "pandas.DataFrame.to_csv = slow\n"
            "from studyapp.cli import main\n"
            "sys.exit(main(sys.argv[1:]))\n")
    export = subprocess.Popen([sys.executable, "-c", code, "export", str(tmp_path / "results"), "-o",
                               str(out / "responses.csv")], cwd=REPO, stdout=subprocess.PIPE, text=True)
    assert export.stdout.readline().strip() == "writing"
    export.send_signal(signal.SIGKILL)
    export.wait()
    assert os.listdir(out) == []


def test_a_writer_killed_before_its_rename_leaves_nothing_visible(tmp_path):
    target = tmp_path / "out.csv"
    killed_while_writing(target, "open")
    assert os.listdir(tmp_path) == []


def test_a_killed_writers_named_temporary_is_removed_by_the_next_write(tmp_path):
    target = tmp_path / "out.h5"
    killed_while_writing(target, "path")  # a writer that needs a path (HDF5, a figure) has a named temporary
    assert len(os.listdir(tmp_path)) == 1
    with atomic_open(target) as f:
        f.write("whole")
    assert os.listdir(tmp_path) == ["out.h5"] and target.read_text() == "whole"
    killed_while_writing(target, "path")
    with atomic_path(target) as tmp:
        tmp.write_text("again")
    assert os.listdir(tmp_path) == ["out.h5"] and target.read_text() == "again"


def test_a_live_writers_temporary_is_left_alone(tmp_path):
    target = tmp_path / "out.csv"
    with atomic_path(target) as first:
        first.write_text("first")
        with atomic_open(target) as f:  # another write of the same target meanwhile
            f.write("second")
        assert first.exists()
    assert target.read_text() == "first" and os.listdir(tmp_path) == ["out.csv"]
