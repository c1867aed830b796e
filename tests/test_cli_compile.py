"""``studyapp compile``: every part runs, and a bad ``--jobs`` is one line and exit code 2."""

import os
import subprocess
import sys

import pytest

from studyapp.cli import main
from studyapp.cli.compile_kernels import PARTS


@pytest.mark.parametrize("jobs", ["0", "9", "-1"])
def test_a_jobs_count_out_of_range_is_refused_in_one_line(jobs, capsys):
    assert main(["compile", "--jobs", jobs]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"studyapp: error: --jobs {jobs}: allowed is an integer from 1 to 8"]


def test_compile_runs_every_part_and_names_its_cache():
    """Into the suite's numba cache (``make test`` fills it first, so this takes seconds)."""
    proc = subprocess.run([sys.executable, "-m", "studyapp", "compile", "--jobs", "2"], capture_output=True,
                          text=True, timeout=900, env=dict(os.environ))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    assert lines[0] == f"compile: {len(PARTS)} parts into {os.environ['NUMBA_CACHE_DIR']}"  # conftest set it
    assert {line.split(" ", 1)[1].rsplit(" ", 5)[0] for line in lines[1:-1]} == set(PARTS)
    counts = [line.rsplit("(", 1)[1] for line in lines[1:-1]]
    assert counts == [f"{k} of {len(PARTS)})" for k in range(1, len(PARTS) + 1)]
    assert lines[-1].startswith("compile: done in ")
