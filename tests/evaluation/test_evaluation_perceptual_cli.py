"""``evaluate --perceptual`` and ``optimise --objective perceptual`` on the command line."""

import json
import math
import tomllib

import pytest

from studyapp.cli import main
from studyapp.evaluation import perceptual_scores as ps
from tests.evaluation.conftest import fails_with_one_line

SHORT = ["--perceptual-fmax", "1", "--perceptual-seeds", "3", "--perceptual-duration", "0.5"]




def test_evaluate_adds_the_audio_distance(short_recording, tmp_path, capsys):
    out = tmp_path / "eval"
    assert main(["evaluate", str(short_recording), "--estimators", "LOWPASS,LEVANT", "--json", "-o", str(out),
                 "--perceptual", *SHORT]) == 0
    document = json.loads(capsys.readouterr().out)
    cases = ps.Cases(5000.0, (1.0,), (3,), 0.5)
    for name in ("LOWPASS", "LEVANT"):
        entry = document["estimators"][name]
        assert {"error", "delay", "error_pct_lowpass", "delay_pct_lowpass", "objective"} <= set(entry)
        assert entry["audio_distance"] == pytest.approx(ps.estimator_score(cases, name, {})["audio_distance"])
    section = document["perceptual"]
    assert section["fmax"] == [1.0] and section["seeds"] == [3] and section["duration"] == 0.5
    assert section["reference"] == "TRUE" and section["gesture"] == "strokes"
    assert json.loads((out / "evaluation.json").read_text()) == document
    for name in ("perceptual.png", "perceptual.svg", "perceptual.csv"):
        assert (out / name).is_file()
    rows = (out / "perceptual.csv").read_text().splitlines()
    assert rows[0] == "estimator,fmax,seed,audio_distance,broken,fault"
    assert len(rows) == 3


def test_evaluate_prints_the_distances(short_recording, capsys):
    assert main(["evaluate", str(short_recording), "--estimators", "LOWPASS,LEVANT,FOAW", "--perceptual", *SHORT]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("audio distance to TRUE"))
    cases = ps.Cases(5000.0, (1.0,), (3,), 0.5)
    expected = {name: ps.estimator_score(cases, name, {})["audio_distance"] for name in ("LOWPASS", "LEVANT", "FOAW")}
    table = [line.split() for line in lines[start + 1:start + 4]]
    assert [row[0] for row in table] == sorted(expected, key=expected.get)
    assert [float(row[1]) for row in table] == pytest.approx([expected[row[0]] for row in table], rel=1e-3)
    assert lines[start + 4].startswith("Spearman rho")
    assert "perceptual: FOAW (3/3)" in captured.err


def test_evaluate_without_the_option_is_unchanged(short_recording, capsys):
    assert main(["evaluate", str(short_recording), "--estimators", "LOWPASS", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert "perceptual" not in document and "audio_distance" not in document["estimators"]["LOWPASS"]


def test_optimise_for_the_audio_distance(tmp_path, capsys):
    out = tmp_path / "P.toml"
    assert main(["optimise", "--objective", "perceptual", "--estimators", "LOWPASS", "--patience", "3",
                 "--workers", "1", "-o", str(out), *SHORT]) == 0
    assert "LOWPASS" in capsys.readouterr().err  # progress
    data = tomllib.loads(out.read_text())
    assert data["provenance"]["objective"] == "perceptual"
    assert data["provenance"]["patience"] == 3 and data["provenance"]["perceptual_fmax"] == [1.0]
    cutoff = data["LOWPASS"]["cutoff_hz"]
    default = ps.estimator_score(ps.Cases(5000.0, (1.0,), (3,), 0.5), "LOWPASS", {})["audio_distance"]
    assert data["objective"]["LOWPASS"] <= default
    tuned = ps.estimator_score(ps.Cases(5000.0, (1.0,), (3,), 0.5), "LOWPASS", {"cutoff_hz": cutoff})
    assert math.isclose(data["objective"]["LOWPASS"], tuned["audio_distance"], rel_tol=1e-12)


def test_a_checkpoint_of_other_cases_is_refused(tmp_path, capsys):
    out = tmp_path / "P.toml"
    run = ["optimise", "--objective", "perceptual", "--estimators", "LOWPASS", "--patience", "2", "--workers", "1",
           "--quiet", "-o", str(out), "--perceptual-fmax", "1", "--perceptual-seeds", "3"]
    assert main([*run, "--perceptual-duration", "0.5"]) == 0
    assert main([*run, "--perceptual-duration", "0.5", "--resume"]) == 0
    fails_with_one_line(capsys, [*run, "--perceptual-duration", "0.6", "--resume"], "differs in: perceptual")


def test_the_default_patience_depends_on_the_objective():
    from studyapp.cli import build_parser
    from studyapp.cli.optimise import PAPER_PATIENCE, PERCEPTUAL_PATIENCE
    from studyapp.cli.perceptual_options import HELP_DEFAULTS

    assert PAPER_PATIENCE == 1000 and PERCEPTUAL_PATIENCE < PAPER_PATIENCE
    # The --help text repeats the library's defaults (argparse must start without numpy).
    assert HELP_DEFAULTS["fmax"].split() == [f"{f:g}" for f in ps.DEFAULT_FMAX]
    assert HELP_DEFAULTS["seeds"].split() == [str(s) for s in ps.DEFAULT_SEEDS]
    assert float(HELP_DEFAULTS["duration"]) == ps.DEFAULT_DURATION
    args = build_parser().parse_args(["optimise", "-o", "P.toml"])
    assert args.objective == "paper" and args.patience is None




def test_bad_input(short_recording, tmp_path, capsys):
    out = tmp_path / "P.toml"
    perceptual = ["optimise", "--objective", "perceptual", "-o", str(out)]
    fails_with_one_line(capsys, [*perceptual, str(short_recording)], "reads no recordings")
    fails_with_one_line(capsys, [*perceptual, "--perceptual-fmax", "-1"], "--perceptual-fmax")
    fails_with_one_line(capsys, [*perceptual, "--perceptual-fmax", "500"], "--perceptual-fmax")
    fails_with_one_line(capsys, [*perceptual, "--perceptual-seeds", "-3"], "--perceptual-seeds")
    fails_with_one_line(capsys, [*perceptual, "--perceptual-duration", "0"], "--perceptual-duration")
    fails_with_one_line(capsys, [*perceptual, "--rate", "10"], "--rate")
    fails_with_one_line(capsys, ["optimise", "-o", str(out)], "no recordings given")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--rate", "5000"], "--rate")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--perceptual-seeds", "1"],
                        "--objective perceptual")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--perceptual-fmax", "1"], "--perceptual")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--perceptual", "--perceptual-duration", "-2",
                    "-o", str(tmp_path / "eval")], "--perceptual-duration")
    assert not out.exists() and not (tmp_path / "eval").exists()
