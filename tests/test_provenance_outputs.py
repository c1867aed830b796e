"""Every output says where it was made: recordings' metadata, session.json, evaluate's and breakdown's JSON.

Each test reads the real output of the real command (small: 0.2 s recordings, one seed of a 0.5 s
breakdown) and checks ``environment`` against what this process finds by other means: the modules'
own ``__version__``, ``/proc/cpuinfo``, ``git rev-parse`` and, for the BLAS, the kernels asked for with
``OPENBLAS_CORETYPE`` (the build's configuration names the build machine's core, not the one in use).
"""

import json
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

import llvmlite
import numba
import numpy
import pandas
import pytest
import scipy

from studyapp.cli import main
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.io.recording import load
from studyapp.io.recording_blocks import RecordingBlocks
from tests.experiment.demo_protocol import trials_only_demo

ROOT = Path(__file__).resolve().parent.parent


def expected_commit():
    if not (ROOT / ".git").exists():
        return "unknown"
    return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()


def expected_cpu():
    text = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    found = re.search(r"^model name\s*:\s*(.*)$", text, re.M)
    return found.group(1).strip() if found else None


def check_environment(env):
    """``env`` names this process's software and machine."""
    assert env["studyapp_version"] and env["python_version"] == platform.python_version()
    assert env["studyapp_commit"].removesuffix("-dirty") == expected_commit()
    for module in (numpy, scipy, numba, llvmlite, pandas):
        assert env[f"{module.__name__}_version"] == module.__version__, module.__name__
    assert env["machine"] == platform.machine()
    if expected_cpu() is not None:
        assert env["cpu_model"] == expected_cpu()
    for module in (numpy, scipy):  # the BLAS each was built with, by version, and its kernels when known
        version = module.show_config(mode="dicts")["Build Dependencies"]["blas"]["version"]
        assert version in env[f"{module.__name__}_blas"], (module.__name__, env[f"{module.__name__}_blas"])


@pytest.mark.parametrize("suffix", [".npz", ".h5"])
def test_simulate_records_the_environment(tmp_path, suffix):
    out = tmp_path / f"s{suffix}"
    assert main(["simulate", "--duration", "0.2", "-o", str(out)]) == 0
    check_environment(load(out).meta["environment"])
    check_environment(RecordingBlocks(out).meta["environment"])


def test_simulate_set_records_the_environment_in_every_recording(tmp_path):
    assert main(["simulate-set", "--duration", "0.2", "-o", str(tmp_path / "set")]) == 0
    files = sorted((tmp_path / "set").glob("*.npz"))
    assert len(files) == 15
    for path in files:
        check_environment(load(path).meta["environment"])


def has_avx():
    return Path("/proc/cpuinfo").exists() and re.search(r"^flags\s*:.*\bavx\b", Path("/proc/cpuinfo").read_text(), re.M)


@pytest.mark.skipif(platform.machine() != "x86_64" or not has_avx(),
                    reason="OPENBLAS_CORETYPE=Sandybridge names x86-64 kernels that need AVX")
def test_a_recording_names_the_blas_kernels_in_use_not_the_builds(tmp_path):
    """Sandybridge is not the wheels' build target (Haswell), so only the kernels in use can name it."""
    out = tmp_path / "sandybridge.npz"
    done = subprocess.run([sys.executable, "-m", "studyapp", "simulate", "--duration", "0.2", "-o", str(out)],
                          env={**os.environ, "OPENBLAS_CORETYPE": "Sandybridge"}, capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=600)
    assert done.returncode == 0, done.stderr
    env = load(out).meta["environment"]
    for name in ("numpy_blas", "scipy_blas"):
        assert " Sandybridge " in f" {env[name]} ", env[name]
        assert "kernels unknown" not in env[name]


def test_session_json_records_the_environment(tmp_path):
    session = Session.create(load_protocol(trials_only_demo(tmp_path)), "P01", tmp_path / "results")
    try:
        info = json.loads((session.folder / "session.json").read_text())
    finally:
        session.close()
    check_environment(info["environment"])


def test_evaluate_json_records_the_environment(tmp_path, capsys):
    for fmax in (0.5, 2.2):
        assert main(["simulate", "--fmax", str(fmax), "--duration", "0.2", "-o", str(tmp_path / f"r{fmax}.npz")]) == 0
    capsys.readouterr()
    assert main(["evaluate", str(tmp_path / "r0.5.npz"), str(tmp_path / "r2.2.npz"), "--estimators", "LOWPASS,BDIFF",
                 "--json"]) == 0  # -o DIR's evaluation.json is the same document, with figures beside it
    document = json.loads(capsys.readouterr().out)
    assert document["provenance"]["command"] == "studyapp evaluate"
    check_environment(document["provenance"])


def test_breakdown_json_records_the_environment(tmp_path, capsys):
    out = tmp_path / "b.json"
    argv = ["breakdown", "--source", "TRUE", "--seeds", "1", "--duration", "0.5", "--gesture", "hold"]
    assert main([*argv, "--json", "-o", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(out.read_text())
    assert printed["provenance"]["command"].startswith("studyapp breakdown --source TRUE --rate 5000 --seeds 1")
    check_environment(printed["provenance"])
