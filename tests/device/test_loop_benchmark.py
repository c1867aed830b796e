"""``studyapp bench loop --core``: which cores run, bad values in one line, and both cores' loops agree.

Speed itself is measured by the command, never asserted here (docs/model.md quotes its figures)."""

import json

import pytest

from studyapp.cli import main
from studyapp.errors import ParameterError

loop_benchmark = pytest.importorskip("studyapp.device.loop_benchmark")


@pytest.mark.parametrize("given, cores", [(["c"], ["c"]), (["numba"], ["numba"]), (["c,numba"], ["c", "numba"]),
                                          (["numba", "c"], ["c", "numba"]), (["c", "c,numba"], ["c", "numba"])])
def test_core_values(given, cores):
    assert loop_benchmark.parse_cores(given) == cores


@pytest.mark.parametrize("bad", ["C", "cc", "c,", "python", ""])
def test_a_core_that_is_none_is_refused_in_one_line(bad, capsys):
    with pytest.raises(ParameterError):
        loop_benchmark.parse_cores([bad])
    assert main(["bench", "loop", "--core", bad]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"studyapp: error: --core {bad!r}: allowed are c, numba or c,numba"]


def test_both_cores_run_in_one_run_and_give_the_same_bits(monkeypatch, capsys):
    monkeypatch.setattr(loop_benchmark, "REPEATS", 1)
    monkeypatch.setattr(loop_benchmark, "SAMPLES_MIN", 2000)
    assert main(["bench", "loop", "--core", "c", "--core", "numba", "--rate", "5000", "--json"]) == 0
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert result["same_bits"] is True
    assert result["samples"] == 5000 and len(result["bank"]) == 14
    for core in ("c", "numba"):
        assert set(result["cores"][core]) == {"loop_ns_per_sample", "bank_ns_per_sample"}
        assert all(value > 0.0 for value in result["cores"][core].values())
    assert "bench loop: repeat 1 of 1" in captured.err
