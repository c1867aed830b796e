"""A full disk while writing an output (issue 14, item 7): one line, exit 2, no file and no temporary left.

The child process runs under ``ulimit -f`` (``RLIMIT_FSIZE``) with SIGXFSZ
ignored, so a write past the limit fails with EFBIG as on a full disk.
"""

import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
LIMIT = 16_384  # bytes: each output below is several times larger


def _small_files():
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


@pytest.fixture(scope="module")
def samples(tmp_path_factory):
    path = tmp_path_factory.mktemp("disk") / "in.csv"
    path.write_text("position\n" + "".join(f"{i * 1e-6!r}\n" for i in range(3000)))
    return path


@pytest.mark.parametrize("argv, output", [
    (["estimate", "{in}", "--estimator", "BDIFF", "--rate", "5000", "-o", "{out}/e.csv"], "e.csv"),
    (["simulate", "--duration", "0.2", "-o", "{out}/s.npz"], "s.npz"),
    (["simulate", "--duration", "0.2", "-o", "{out}/s.csv"], "s.csv"),
    # HDF5 writes from its caches, late: h5py's tracebacks, then a crash with the temporary left (issue 30, item 4)
    (["simulate", "--duration", "0.2", "-o", "{out}/s.h5"], "s.h5"),
])
def test_full_disk_is_one_line_and_leaves_nothing(argv, output, samples, tmp_path):
    argv = [a.replace("{in}", str(samples)).replace("{out}", str(tmp_path)) for a in argv]
    proc = subprocess.run([sys.executable, "-m", "studyapp", *argv], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, preexec_fn=_small_files)
    # progress ("\rsimulate:  40%") comes before; the error is the one line after it
    lines = [line.split("\r")[-1] for line in proc.stderr.splitlines()]
    lines = [line for line in lines if line.strip() and not line.startswith("simulate:")]
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert lines == [f"studyapp: error: {tmp_path / output}: File too large: nothing written"], proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_whole_h5_recording_on_a_full_disk_is_one_error_and_leaves_nothing(tmp_path):
    # recording.save, as simulate-set and the others write a recording held in memory
    code = ("import numpy as np\n"
            "from studyapp.io import recording\n"
            "columns = {c: np.arange(20000.0) for c in recording.COLUMNS}\n"
            "try:\n"
            f"    recording.save(recording.Recording(5000.0, columns), {str(tmp_path / 'r.h5')!r})\n"
            "except OSError as exc:\n"
            "    print(exc.errno, exc.filename, exc.strerror)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, preexec_fn=_small_files)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert proc.stdout.strip() == f"27 {tmp_path / 'r.h5'} File too large"
    assert list(tmp_path.iterdir()) == []
