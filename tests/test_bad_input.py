"""Every command against a table of bad inputs: one line on stderr, exit 2, nothing written (issue 14, item 7).

Each case runs ``studyapp ARGV`` in this process (``studyapp.cli.main``, so a
traceback fails the test with its exception) in a fresh output folder, next to
a folder of prepared inputs. Both folders must be as they were afterwards: no
output file, no folder, no temporary file. A few cases (``/dev/zero``, the
real entry point) run as a child process under a memory and time limit.

Not covered: ``gui`` (needs a display; its options are those of ``run``) and
``estimators`` (takes no input but ``--json``). ``live`` runs with
``--audio null --midi none``, so it needs no hardware; each of its cases is
refused before the engine starts.
"""

import contextlib
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from studyapp.cli import main

REPO = Path(__file__).resolve().parents[1]
UNWRITABLE = "/sys/studyapp-bad-input"  # not writable even by root
RATE = 5000.0


def _recording(path, drop=()):
    from studyapp.io.recording import Recording, save
    from studyapp.synthetic import stick_slip

    sig = stick_slip(RATE, 0.1, seed=1)
    save(Recording(RATE, {k: v for k, v in sig.items() if k not in drop}, {"fmax": 1.0}), path)


def _results(folder, event=None, raw_line=None):
    """A results folder with one session holding one good adjustment response and ``event`` or ``raw_line``."""
    from studyapp.experiment.protocol import load_protocol
    from studyapp.experiment.session import Session

    session = Session.create(load_protocol(REPO / "protocols" / "demo.toml"), "p1", folder)
    good = {"type": "response", "step": 3, "task": "adjustment", "condition": "LVT", "trial": 1, "fmax": 2.5,
            "value": 60, "peak_fmax": 3.0, "duration": 4.0}
    session.log.append(good)
    if event is not None:
        session.log.append({**good, "step": 4, **event})
    session.close()
    if raw_line is not None:
        with open(session.folder / "events.jsonl", "ab") as f:
            f.write(raw_line)
    return folder


MALFORMED_EVENTS = {
    "no_fmax": {"fmax": None},
    "fmax_text": {"fmax": "lots"},
    "trial_text": {"trial": "first"},
    "unknown_task": {"task": "dance"},
    "rating_responses_5": {"task": "rating", "responses": 5},
    "rating_response_no_condition": {"task": "rating", "responses": [{"value": 3, "knob": 0}]},
    "no_condition": {"condition": None},
    "step_text": {"step": "x"},
}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    rng = np.random.default_rng(14)
    (d / "good.csv").write_text("position,acceleration,velocity\n" + "".join(
        f"{0.001 * i!r},0.0,0.0\n" for i in range(50)))
    (d / "wrong.csv").write_text("speed,force\n1,2\n3,4\n")
    (d / "responses_wrong.csv").write_text("a,b\n1,2\n")
    _recording(d / "rec.npz")
    _recording(d / "nopos.npz", drop=("position",))
    for name in ("empty.csv", "empty.npz", "empty.toml"):
        (d / name).write_bytes(b"")
    for name in ("binary.csv", "binary.npz", "binary.toml"):
        (d / name).write_bytes(rng.integers(0, 256, 4096, dtype=np.uint8).tobytes())
    (d / "nested.toml").write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    (d / "nested_table.toml").write_text("x = " + "{a = " * 5000 + "1" + "}" * 5000 + "\n")
    with open(d / "huge.toml", "w") as f:  # 2 MB of valid TOML
        f.write("[provenance]\n")
        f.writelines(f"k{i} = {i}\n" for i in range(180_000))
    (d / "prov5.toml").write_text("provenance = 5\n")
    (d / "objective_list.toml").write_text("objective = [1, 2]\n")
    (d / "adir").mkdir()
    (d / "adir.npz").mkdir()
    (d / "adir.csv").mkdir()
    (d / "adir.toml").mkdir()
    _results(d / "results_good")
    for name, event in MALFORMED_EVENTS.items():
        _results(d / f"results_{name}", event=event)
    _results(d / f"results_not_object", raw_line=b"[1, 2]\n")
    os.chmod(d, 0o555)  # a command that writes into the inputs folder fails loudly (unless root)
    yield d
    os.chmod(d, 0o755)


ESTIMATE = ["--estimator", "LOWPASS", "--rate", "5000", "-o", "{out}/e.csv"]
SIMULATE = ["simulate", "--duration", "0.05"]
SET = ["simulate-set", "--duration", "0.05"]
BREAKDOWN = ["breakdown", "--source", "LVT", "--seeds", "1", "--duration", "0.5"]
OPTIMISE = ["optimise", "--max-sets", "1", "--workers", "1", "--estimators", "LOWPASS", "--quiet"]
TRADEOFF = ["tradeoff", "--rates", "5000", "--fmax", "1", "--duration", "0.2", "--estimators", "LOWPASS"]
RUN = ["run", "--participant", "p1", "--simulated-participant", "--headless"]
PROTOCOL = str(REPO / "protocols" / "demo.toml")
LIVE = ["live", "--audio", "null", "--midi", "none", "--seconds", "0.2"]

CASES = {
    # estimate: inputs
    "estimate-missing": ["estimate", "{in}/none.csv", *ESTIMATE],
    "estimate-dir": ["estimate", "{in}/adir", *ESTIMATE],
    "estimate-dir-csv": ["estimate", "{in}/adir.csv", *ESTIMATE],
    "estimate-dir-npz": ["estimate", "{in}/adir.npz", *ESTIMATE],
    "estimate-empty-csv": ["estimate", "{in}/empty.csv", *ESTIMATE],
    "estimate-empty-npz": ["estimate", "{in}/empty.npz", *ESTIMATE],
    "estimate-binary-csv": ["estimate", "{in}/binary.csv", *ESTIMATE],
    "estimate-binary-npz": ["estimate", "{in}/binary.npz", *ESTIMATE],
    "estimate-wrong-columns": ["estimate", "{in}/wrong.csv", *ESTIMATE],
    "estimate-no-position": ["estimate", "{in}/nopos.npz", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    "estimate-rate-differs": ["estimate", "{in}/rec.npz", *ESTIMATE[:2], "--rate", "10000", "-o", "{out}/e.csv"],
    "estimate-csv-without-rate": ["estimate", "{in}/good.csv", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    # estimate: numbers and outputs
    "estimate-rate-nan": ["estimate", "{in}/good.csv", *ESTIMATE[:2], "--rate", "nan", "-o", "{out}/e.csv"],
    "estimate-rate-negative": ["estimate", "{in}/good.csv", *ESTIMATE[:2], "--rate", "-1", "-o", "{out}/e.csv"],
    "estimate-set-nan": ["estimate", "{in}/good.csv", *ESTIMATE, "--set", "cutoff_hz=nan"],
    "estimate-block-zero": ["estimate", "{in}/good.csv", *ESTIMATE, "--block", "0"],
    "estimate-out-dir": ["estimate", "{in}/good.csv", *ESTIMATE[:4], "-o", "{in}/adir"],
    "estimate-out-dir-csv": ["estimate", "{in}/good.csv", *ESTIMATE[:4], "-o", "{in}/adir.csv"],
    "estimate-out-unwritable": ["estimate", "{in}/good.csv", *ESTIMATE[:4], "-o", UNWRITABLE + "/e.csv"],
    "estimate-out-under-file": ["estimate", "{in}/good.csv", *ESTIMATE[:4], "-o", "{in}/good.csv/e.csv"],
    "estimate-out-is-input": ["estimate", "{in}/good.csv", *ESTIMATE[:4], "-o", "{in}/good.csv"],
    # simulate
    "simulate-seed-negative": [*SIMULATE, "--seed", "-1", "-o", "{out}/s.npz"],
    "simulate-duration-nan": [*SIMULATE, "--duration", "nan", "-o", "{out}/s.npz"],
    "simulate-duration-negative": [*SIMULATE, "--duration", "-1", "-o", "{out}/s.npz"],
    "simulate-duration-inf": [*SIMULATE, "--duration", "inf", "-o", "{out}/s.npz"],
    "simulate-fmax-nan": [*SIMULATE, "--fmax", "nan", "-o", "{out}/s.npz"],
    "simulate-rate-nan": [*SIMULATE, "--rate", "nan", "-o", "{out}/s.npz"],
    "simulate-f0-nan": [*SIMULATE, "--f0", "nan", "-o", "{out}/s.npz"],
    "simulate-f0-negative": [*SIMULATE, "--f0", "-5", "-o", "{out}/s.npz"],
    "simulate-out-dir": [*SIMULATE, "-o", "{in}/adir.npz"],
    "simulate-out-unwritable": [*SIMULATE, "-o", UNWRITABLE + "/s.npz"],
    "simulate-out-under-file": [*SIMULATE, "-o", "{in}/good.csv/s.npz"],
    # simulate-set
    "simulate-set-out-file": [*SET, "-o", "{in}/good.csv"],
    "simulate-set-out-unwritable": [*SET, "-o", UNWRITABLE],
    "simulate-set-out-under-file": [*SET, "-o", "{in}/good.csv/set"],
    "simulate-set-rate-nan": [*SET, "--rate", "nan", "-o", "{out}/set"],
    "simulate-set-duration-negative": [*SET, "--duration", "-1", "-o", "{out}/set"],
    "simulate-set-duration-nan": [*SET, "--duration", "nan", "-o", "{out}/set"],
    # breakdown
    "breakdown-seeds-negative": [*BREAKDOWN, "--seeds", "-1"],
    "breakdown-first-seed-negative": [*BREAKDOWN, "--first-seed", "-1"],
    "breakdown-first-seed-fraction": [*BREAKDOWN, "--first-seed", "0.5"],
    "breakdown-first-seed-past-the-end": [*BREAKDOWN, "--first-seed", "999999", "--seeds", "2"],
    "breakdown-rate-nan": [*BREAKDOWN, "--rate", "nan"],
    "breakdown-duration-nan": [*BREAKDOWN, "--duration", "nan"],
    "breakdown-out-dir": [*BREAKDOWN, "-o", "{in}/adir.csv"],
    "breakdown-out-unwritable": [*BREAKDOWN, "-o", UNWRITABLE + "/b.csv"],
    "breakdown-out-under-file": [*BREAKDOWN, "-o", "{in}/good.csv/b.csv"],
    # evaluate
    "evaluate-missing": ["evaluate", "{in}/none.npz"],
    "evaluate-empty-dir": ["evaluate", "{in}/adir"],
    "evaluate-empty": ["evaluate", "{in}/empty.npz"],
    "evaluate-binary": ["evaluate", "{in}/binary.npz"],
    "evaluate-binary-csv": ["evaluate", "{in}/binary.csv"],
    "evaluate-no-position": ["evaluate", "{in}/nopos.npz"],
    "evaluate-wrong-columns": ["evaluate", "{in}/wrong.csv"],
    "evaluate-max-lag-nan": ["evaluate", "{in}/rec.npz", "--max-lag", "nan"],
    "evaluate-max-lag-negative": ["evaluate", "{in}/rec.npz", "--max-lag", "-1"],
    "evaluate-params-provenance-5": ["evaluate", "{in}/rec.npz", "--params", "{in}/prov5.toml"],
    "evaluate-params-objective-list": ["evaluate", "{in}/rec.npz", "--params", "{in}/objective_list.toml"],
    "evaluate-params-nested": ["evaluate", "{in}/rec.npz", "--params", "{in}/nested.toml"],
    "evaluate-params-nested-table": ["evaluate", "{in}/rec.npz", "--params", "{in}/nested_table.toml"],
    "evaluate-params-huge": ["evaluate", "{in}/rec.npz", "--params", "{in}/huge.toml"],
    "evaluate-params-empty": ["evaluate", "{in}/rec.npz", "--params", "{in}/empty.toml"],
    "evaluate-params-binary": ["evaluate", "{in}/rec.npz", "--params", "{in}/binary.toml"],
    "evaluate-params-dir": ["evaluate", "{in}/rec.npz", "--params", "{in}/adir.toml"],
    "evaluate-out-file": ["evaluate", "{in}/rec.npz", "-o", "{in}/good.csv"],
    "evaluate-out-unwritable": ["evaluate", "{in}/rec.npz", "-o", UNWRITABLE],
    "evaluate-out-under-file": ["evaluate", "{in}/rec.npz", "-o", "{in}/good.csv/ev"],
    # optimise
    "optimise-restarts-huge": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--restarts", "1000000"],
    "optimise-workers-beyond-the-machine": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--workers", "100000"],
    "tradeoff-workers-beyond-the-machine": [*TRADEOFF, "-o", "{out}/t", "--tune", "--workers", "100000"],
    "optimise-seed-negative": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--seed", "-1"],
    "optimise-max-lag-nan": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--max-lag", "nan"],
    "optimise-binary": [*OPTIMISE, "{in}/binary.npz", "-o", "{out}/p.toml"],
    "optimise-no-position": [*OPTIMISE, "{in}/nopos.npz", "-o", "{out}/p.toml"],
    "optimise-out-dir": [*OPTIMISE, "{in}/rec.npz", "-o", "{in}/adir.toml"],
    "optimise-out-unwritable": [*OPTIMISE, "{in}/rec.npz", "-o", UNWRITABLE + "/p.toml"],
    "optimise-out-under-file": [*OPTIMISE, "{in}/rec.npz", "-o", "{in}/good.csv/p.toml"],
    "optimise-range-nan": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--range", "LOWPASS.cutoff_hz=nan:300"],
    # demo
    "demo-seed-negative": ["demo", "--seconds", "0.2", "--seed", "-1"],
    "demo-rate-nan": ["demo", "--seconds", "0.2", "--rate", "nan"],
    "demo-seconds-nan": ["demo", "--seconds", "nan"],
    # tradeoff
    "tradeoff-rates-nan": [*TRADEOFF, "-o", "{out}/t", "--rates", "nan"],
    "tradeoff-fmax-nan": [*TRADEOFF, "-o", "{out}/t", "--fmax", "nan"],
    "tradeoff-duration-nan": [*TRADEOFF, "-o", "{out}/t", "--duration", "nan"],
    "tradeoff-duration-negative": [*TRADEOFF, "-o", "{out}/t", "--duration", "-1"],
    "tradeoff-seed-negative": [*TRADEOFF, "-o", "{out}/t", "--seed", "-1"],
    "tradeoff-params-provenance-5": [*TRADEOFF, "-o", "{out}/t", "--params", "{in}/prov5.toml"],
    "tradeoff-params-nested": [*TRADEOFF, "-o", "{out}/t", "--params", "{in}/nested.toml"],
    "tradeoff-out-file": [*TRADEOFF, "-o", "{in}/good.csv"],
    "tradeoff-out-unwritable": [*TRADEOFF, "-o", UNWRITABLE],
    "tradeoff-out-under-file": [*TRADEOFF, "-o", "{in}/good.csv/t"],
    # run
    "run-protocol-missing": [*RUN, "--results", "{out}/r", "--protocol", "{in}/none.toml"],
    "run-protocol-dir": [*RUN, "--results", "{out}/r", "--protocol", "{in}/adir.toml"],
    "run-protocol-empty": [*RUN, "--results", "{out}/r", "--protocol", "{in}/empty.toml"],
    "run-protocol-binary": [*RUN, "--results", "{out}/r", "--protocol", "{in}/binary.toml"],
    "run-protocol-nested": [*RUN, "--results", "{out}/r", "--protocol", "{in}/nested.toml"],
    "run-protocol-nested-table": [*RUN, "--results", "{out}/r", "--protocol", "{in}/nested_table.toml"],
    "run-protocol-huge": [*RUN, "--results", "{out}/r", "--protocol", "{in}/huge.toml"],
    "run-seed-negative": [*RUN, "--results", "{out}/r", "--protocol", PROTOCOL, "--seed", "-1"],
    "run-results-file": [*RUN, "--results", "{in}/good.csv", "--protocol", PROTOCOL],
    "run-results-unwritable": [*RUN, "--results", UNWRITABLE, "--protocol", PROTOCOL],
    "run-results-under-file": [*RUN, "--results", "{in}/good.csv/r", "--protocol", PROTOCOL],
    # export
    "export-missing": ["export", "{in}/none", "-o", "{out}/x.csv"],
    "export-file": ["export", "{in}/good.csv", "-o", "{out}/x.csv"],
    "export-out-dir": ["export", "{in}/results_good", "-o", "{in}/adir.csv"],
    "export-out-unwritable": ["export", "{in}/results_good", "-o", UNWRITABLE + "/x.csv"],
    "export-out-under-file": ["export", "{in}/results_good", "-o", "{in}/good.csv/x.csv"],
    **{f"export-event-{name}": ["export", f"{{in}}/results_{name}", "-o", "{out}/x.csv"]
       for name in [*MALFORMED_EVENTS, "not_object"]},
    # analyse
    "analyse-missing": ["analyse", "{in}/none", "-o", "{out}/rep"],
    "analyse-wrong-columns": ["analyse", "{in}/responses_wrong.csv", "-o", "{out}/rep"],
    "analyse-empty": ["analyse", "{in}/empty.csv", "-o", "{out}/rep"],
    "analyse-binary": ["analyse", "{in}/binary.csv", "-o", "{out}/rep"],
    "analyse-dir-csv": ["analyse", "{in}/adir.csv", "-o", "{out}/rep"],
    "analyse-alpha-nan": ["analyse", "{in}/results_good", "-o", "{out}/rep", "--alpha", "nan"],
    "analyse-evaluation-missing": ["analyse", "{in}/results_good", "-o", "{out}/rep", "--evaluation", "{in}/none"],
    "analyse-evaluation-binary": ["analyse", "{in}/results_good", "-o", "{out}/rep", "--evaluation",
                                  "{in}/binary.csv"],
    "analyse-out-file": ["analyse", "{in}/results_good", "-o", "{in}/good.csv"],
    "analyse-out-unwritable": ["analyse", "{in}/results_good", "-o", UNWRITABLE],
    "analyse-out-under-file": ["analyse", "{in}/results_good", "-o", "{in}/good.csv/rep"],
    **{f"analyse-event-{name}": ["analyse", f"{{in}}/results_{name}", "-o", "{out}/rep"]
       for name in [*MALFORMED_EVENTS, "not_object"]},
    # bench
    "bench-estimators-rate-nan": ["bench", "estimators", "--rate", "nan"],
    "bench-estimators-samples-negative": ["bench", "estimators", "--samples", "-1"],
    "bench-loop-rate-nan": ["bench", "loop", "--rate", "nan"],
    "bench-live-seconds-nan": ["bench", "live", "--seconds", "nan"],
    "bench-live-block-negative": ["bench", "live", "--block-ms", "-1"],
    "bench-memory-rows-negative": ["bench", "memory", "--rows", "-1"],
    "bench-memory-block-zero": ["bench", "memory", "--rows", "1000", "--block", "0"],
    # live
    "live-rate-nan": [*LIVE, "--rate", "nan"],
    "live-fmax-nan": [*LIVE, "--fmax", "nan"],
    "live-fmax-negative": [*LIVE, "--fmax", "-1"],
    "live-seconds-nan": [*LIVE, "--seconds", "nan"],
    "live-seed-negative": [*LIVE, "--seed", "-1"],
    "live-block-negative": [*LIVE, "--block", "-1"],
}


def _tree(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*"))


def _argv(template, inputs, out):
    return [a.replace("{in}", str(inputs)).replace("{out}", str(out)) for a in template]


def assert_refused(code, err, before, after):
    lines = err.strip().splitlines()
    assert "Traceback" not in err, err
    assert code == 2 and len(lines) == 1 and lines[0].startswith("studyapp: error: "), (code, err)
    assert after == before, "left behind: " + ", ".join(sorted(set(after[1]) - set(before[1])))


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_is_refused_in_one_line(case, inputs, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    before = (_tree(inputs), _tree(out))
    code = main(_argv(CASES[case], inputs, out))
    err = capsys.readouterr().err
    assert_refused(code, err, before, (_tree(inputs), _tree(out)))


SUBPROCESS_CASES = {
    "estimate-dev-zero": ["estimate", "/dev/zero", *ESTIMATE],
    "estimate-dev-zero-csv-link": ["estimate", "{out}/zero.csv", *ESTIMATE],
    "evaluate-params-dev-zero": ["evaluate", "{in}/rec.npz", "--params", "/dev/zero"],
    "run-protocol-dev-zero": [*RUN, "--results", "{out}/r", "--protocol", "/dev/zero"],
}


def _limit_memory():
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


@pytest.mark.parametrize("case", list(SUBPROCESS_CASES))
def test_bad_input_is_refused_by_the_command(case, inputs, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "zero.csv").symlink_to("/dev/zero")
    before = (_tree(inputs), _tree(out))
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.run([sys.executable, "-m", "studyapp", *_argv(SUBPROCESS_CASES[case], inputs, out)],
                          capture_output=True, text=True, timeout=120, env=env, cwd=out,
                          preexec_fn=_limit_memory)
    assert_refused(proc.returncode, proc.stderr, before, (_tree(inputs), _tree(out)))


def test_a_recording_csv_with_a_byte_order_mark_is_accepted(tmp_path):
    from studyapp.io.recording import COLUMNS, Recording, load, save

    rec = Recording(1000.0, {name: np.arange(5.0) * (i + 1) / 1000 for i, name in enumerate(COLUMNS)})
    save(rec, tmp_path / "plain.csv")
    (tmp_path / "excel.csv").write_bytes(b"\xef\xbb\xbf" + (tmp_path / "plain.csv").read_bytes())
    loaded = load(tmp_path / "excel.csv")
    assert loaded.rate == 1000.0 and list(loaded.columns) == list(COLUMNS)
    np.testing.assert_array_equal(loaded["position"], rec["position"])


# ---- studyapp plan and studyapp notes (issue 22 item 16) ------------------------------------------
PLAN = ["plan", "--participant", "P07", "--results", "{in}/results_good", "--protocol"]
PLAN_CASES = {
    "plan-protocol-missing": [*PLAN, "{in}/none.toml"],
    "plan-protocol-empty": [*PLAN, "{in}/empty.toml"],
    "plan-protocol-binary": [*PLAN, "{in}/binary.toml"],
    "plan-protocol-dir": [*PLAN, "{in}/adir.toml"],
    "plan-protocol-nested": [*PLAN, "{in}/nested.toml"],
    "plan-protocol-huge": [*PLAN, "{in}/huge.toml"],
    "plan-participant-bad": ["plan", "--participant", "P 07!", "--protocol", PROTOCOL],
    "plan-participant-empty": ["plan", "--participant", "", "--protocol", PROTOCOL],
    "plan-order-row-high": [*PLAN, PROTOCOL, "--order-row", "999"],
    "plan-order-row-negative": [*PLAN, PROTOCOL, "--order-row", "-1"],
    "plan-order-row-text": [*PLAN, PROTOCOL, "--order-row", "first"],
    "plan-results-file": ["plan", "--participant", "P07", "--protocol", PROTOCOL, "--results", "{in}/good.csv"],
    "plan-out-dir": [*PLAN, PROTOCOL, "-o", "{in}/adir"],
    "plan-out-unwritable": [*PLAN, PROTOCOL, "-o", UNWRITABLE + "/sheet.md"],
    "plan-out-under-file": [*PLAN, PROTOCOL, "-o", "{in}/good.csv/sheet.md"],
    "plan-out-is-protocol": [*PLAN, "{out}/p.toml", "-o", "{out}/p.toml"],
    # p1 has a demo session: its stored order row is 0
    "plan-stored-order-row-differs": ["plan", "--participant", "p1", "--results", "{in}/results_good",
                                      "--protocol", PROTOCOL, "--order-row", "2"],
    "notes-missing": ["notes", "{in}/none"],
    "notes-file": ["notes", "{in}/good.csv"],
    "notes-add-not-a-session": ["notes", "{in}/adir", "--add", "text"],
    "notes-add-empty": ["notes", "{in}/results_good", "--add", " "],
    "notes-add-control-character": ["notes", "{in}/results_good", "--add", "bell\x07"],
    "notes-add-with-out": ["notes", "{in}/results_good", "--add", "text", "-o", "{out}/n.csv"],
    "notes-out-dir": ["notes", "{in}/results_good", "-o", "{in}/adir"],
}


@pytest.mark.parametrize("case", list(PLAN_CASES))
def test_plan_and_notes_bad_input_is_refused_in_one_line(case, inputs, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "p.toml").write_text(Path(PROTOCOL).read_text())
    monkeypatch.chdir(out)
    before = (_tree(inputs), _tree(out), (out / "p.toml").read_bytes())
    code = main(_argv(PLAN_CASES[case], inputs, out))
    err = capsys.readouterr().err
    assert_refused(code, err, before[:2], (_tree(inputs), _tree(out)))
    assert (out / "p.toml").read_bytes() == before[2]


# ---------------------------------------------------------------------------------------------------
# Issue 21, items 11-15 (force safety and bad input; wt-forcesafe). Items 9-10 are in
# tests/engine/test_engine_ceiling.py, tests/engine/test_engine_guard.py and
# tests/experiment/test_experiment_validation.py. Inputs of their own, so this block stands alone.
# ---------------------------------------------------------------------------------------------------

RESPONSE_HEADER = "participant,session,task,condition,trial,fmax,rating,time,protocol_hash\n"


def _npz(path, columns, meta):
    import json

    np.savez(path, __meta__=np.array(json.dumps(meta)), **columns)


def _signal():
    from studyapp.synthetic import stick_slip

    return stick_slip(RATE, 0.1, seed=1)


@pytest.fixture(scope="module")
def inputs21(tmp_path_factory):
    import h5py

    d = tmp_path_factory.mktemp("inputs21")
    sig = _signal()
    _npz(d / "rate_abc.npz", sig, {"rate": "abc"})
    _npz(d / "rate_list.npz", sig, {"rate": [1, 2]})
    _npz(d / "fmax_abc.npz", sig, {"rate": RATE, "fmax": "abc"})
    _npz(d / "zero.npz", {k: np.zeros(0) for k in sig}, {"rate": RATE})
    _npz(d / "nan.npz", {k: np.full_like(v, np.nan) for k, v in sig.items()}, {"rate": RATE})
    _npz(d / "nan_position.npz", {k: (np.full_like(v, np.nan) if k == "position" else v) for k, v in sig.items()},
         {"rate": RATE})
    with h5py.File(d / "zero.h5", "w") as f:
        f.attrs["meta"] = '{"rate": 5000.0}'
        for k in sig:
            f.create_dataset(k, data=np.zeros(0))
    with h5py.File(d / "compound.h5", "w") as f:
        f.attrs["meta"] = '{"rate": 5000.0}'
        f.create_dataset("position", data=np.zeros(10, dtype=[("a", "f8"), ("b", "i4")]))
    (d / "cell_1_0.csv").write_text("position\n" + "".join(f"{0.001 * i!r}\n" for i in range(20)) + "1_0\n")
    (d / "trial_1e12.csv").write_text(RESPONSE_HEADER + "p1,1,adjustment,LVT,1000000000000,2.5,,1.0,abc\n"
                                      "p1,1,adjustment,LOWPASS,1,2.0,,1.0,abc\n")
    (d / "fmax_1e308.csv").write_text(RESPONSE_HEADER + "p1,1,adjustment,LVT,1,1e308,,1.0,abc\n"
                                      "p1,1,adjustment,LOWPASS,1,2.0,,1.0,abc\n")
    (d / "cell_1_0_responses.csv").write_text(RESPONSE_HEADER + "p1,1,adjustment,LVT,1,1_0,,1.0,abc\n")
    _results(d / "results_step_1e30", event={"step": 10**30})
    _results(d / "results_step_1e30_float", event={"step": 1e30})
    _results(d / "results_fmax_1e308", event={"fmax": 1e308})
    _results(d / "results_trial_1e12", event={"trial": 10**12})
    os.mkfifo(d / "fifo.toml")
    os.mkfifo(d / "fifo.csv")
    for name, file in (("session_fifo", "session.json"), ("events_fifo", "events.jsonl"),
                       ("events_urandom", "events.jsonl")):
        folder = next(p.parent for p in _results(d / f"results_{name}").rglob("events.jsonl"))
        (folder / file).unlink()
        if name == "events_urandom":
            (folder / file).symlink_to("/dev/urandom")
        else:
            os.mkfifo(folder / file)
    yield d


SIMULATE21 = ["simulate", "--duration", "0.05", "-o", "{out}/s.npz"]
ANALYSE21 = ["-o", "{out}/rep"]

CASES_21 = {
    # item 11: sizes bounded before any allocation
    "live-block-1e9": [*LIVE, "--block", "1000000000"],
    "live-block-above-half-the-watchdog": [*LIVE, "--block", "1000"],  # above half of any load-scaled bound (<= 250 ms)
    "estimate-block-1e12": ["estimate", "{in}/good.csv", *ESTIMATE, "--block", "1000000000000"],
    "bench-estimators-samples-1e12": ["bench", "estimators", "--samples", "1000000000000"],
    "bench-memory-rows-1e12": ["bench", "memory", "--rows", "1000000000000"],
    "bench-memory-block-1e12": ["bench", "memory", "--rows", "1000", "--block", "1000000000000"],
    "tradeoff-cost-samples-1e12": [*TRADEOFF, "-o", "{out}/t", "--cost-samples", "1000000000000"],
    # item 12: live refuses before the worker starts
    "live-gesture-nope": [*LIVE, "--gesture", "NOPE"],
    "live-gesture-playback": [*LIVE, "--gesture", "playback"],
    "live-audio-wav-unwritable-folder": [*LIVE, "--audio", "wav:/sys/a.wav"],
    "live-audio-wav-proc": [*LIVE, "--audio", "wav:/proc/a.wav"],
    # item 14: tracebacks
    "evaluate-meta-rate-abc": ["evaluate", "{in21}/rate_abc.npz"],
    "evaluate-meta-rate-list": ["evaluate", "{in21}/rate_list.npz"],
    "evaluate-meta-fmax-abc": ["evaluate", "{in21}/fmax_abc.npz"],
    "optimise-meta-rate-abc": [*OPTIMISE, "{in21}/rate_abc.npz", "-o", "{out}/p.toml"],
    "optimise-meta-rate-list": [*OPTIMISE, "{in21}/rate_list.npz", "-o", "{out}/p.toml"],
    "estimate-h5-compound": ["estimate", "{in21}/compound.h5", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    "evaluate-h5-compound": ["evaluate", "{in21}/compound.h5"],
    "optimise-max-lag-1e308": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--max-lag", "1e308"],
    "evaluate-max-lag-1e308": ["evaluate", "{in}/rec.npz", "--max-lag", "1e308"],
    "export-step-1e30": ["export", "{in21}/results_step_1e30", "-o", "{out}/x.csv"],
    "export-step-1e30-float": ["export", "{in21}/results_step_1e30_float", "-o", "{out}/x.csv"],
    "analyse-step-1e30": ["analyse", "{in21}/results_step_1e30", *ANALYSE21],
    "analyse-trial-1e12-event": ["analyse", "{in21}/results_trial_1e12", *ANALYSE21],
    "analyse-csv-trial-1e12": ["analyse", "{in21}/trial_1e12.csv", *ANALYSE21],
    "analyse-trials-1e20": ["analyse", "{in}/results_good", *ANALYSE21, "--trials", "99999999999999999999"],
    "analyse-csv-fmax-1e308": ["analyse", "{in21}/fmax_1e308.csv", *ANALYSE21],
    "analyse-fmax-1e308": ["analyse", "{in21}/results_fmax_1e308", *ANALYSE21],
    # item 15: too lenient
    "simulate-rate-5_000": [*SIMULATE21, "--rate", "5_000"],
    "simulate-seed-1_0": [*SIMULATE21, "--seed", "1_0"],
    "estimate-rate-5_000": ["estimate", "{in}/good.csv", "--estimator", "LOWPASS", "--rate", "5_000",
                            "-o", "{out}/e.csv"],
    "estimate-set-1_0": ["estimate", "{in}/good.csv", *ESTIMATE, "--set", "cutoff_hz=25_0"],
    "estimate-csv-cell-1_0": ["estimate", "{in21}/cell_1_0.csv", *ESTIMATE],
    "analyse-csv-cell-1_0": ["analyse", "{in21}/cell_1_0_responses.csv", *ANALYSE21],
    "estimate-zero-row-npz": ["estimate", "{in21}/zero.npz", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    "estimate-zero-row-h5": ["estimate", "{in21}/zero.h5", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    "evaluate-zero-row-npz": ["evaluate", "{in21}/zero.npz"],
    "simulate-duration-1e-300": ["simulate", "--duration", "1e-300", "-o", "{out}/s.npz"],
    "evaluate-all-nan": ["evaluate", "{in21}/nan.npz"],
    "optimise-all-nan": [*OPTIMISE, "{in21}/nan.npz", "-o", "{out}/p.toml"],
    "evaluate-position-nan-reference-true": ["evaluate", "{in21}/nan_position.npz", "--reference", "true"],
    "optimise-position-nan-reference-true": [*OPTIMISE, "{in21}/nan_position.npz", "--reference", "true",
                                             "-o", "{out}/p.toml"],
    "export-strict-fmax-1e308": ["export", "{in21}/results_fmax_1e308", "-o", "{out}/x.csv", "--strict"],
    "estimate-path-with-newline": ["estimate", "{in21}/no\nsuch.csv", *ESTIMATE],
    "estimate-value-with-newline": ["estimate", "{in}/good.csv", "--estimator", "LOW\nPASS", "--rate", "5000",
                                    "-o", "{out}/e.csv"],
    "run-participant-with-newline": ["run", "--participant", "p\n1", "--simulated-participant", "--headless",
                                     "--results", "{out}/r", "--protocol", PROTOCOL],
}


def _argv21(template, inputs, inputs21, out):
    return [a.replace("{in21}", str(inputs21)) for a in _argv(template, inputs, out)]


@pytest.mark.parametrize("case", list(CASES_21))
def test_issue21_bad_input_is_refused_in_one_line(case, inputs, inputs21, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    before = ((_tree(inputs), _tree(inputs21)), _tree(out))
    code = main(_argv21(CASES_21[case], inputs, inputs21, out))
    err = capsys.readouterr().err
    assert_refused(code, err, before, ((_tree(inputs), _tree(inputs21)), _tree(out)))


# item 13: each in a child process, so that a FIFO that blocks fails the test (timeout) instead of hanging it
FIFO_CASES = {
    "run-protocol-fifo": [*RUN, "--results", "{out}/r", "--protocol", "{in21}/fifo.toml"],
    "gui-protocol-fifo": ["gui", "--protocol", "{in21}/fifo.toml"],
    "estimate-csv-fifo": ["estimate", "{in21}/fifo.csv", *ESTIMATE],
    "evaluate-params-fifo": ["evaluate", "{in}/rec.npz", "--params", "{in21}/fifo.toml"],
    "tradeoff-params-fifo": [*TRADEOFF, "-o", "{out}/t", "--params", "{in21}/fifo.toml"],
    "export-events-fifo": ["export", "{in21}/results_events_fifo", "-o", "{out}/x.csv"],
    "analyse-events-fifo": ["analyse", "{in21}/results_events_fifo", *ANALYSE21],
    "export-events-urandom": ["export", "{in21}/results_events_urandom", "-o", "{out}/x.csv"],
    "analyse-events-urandom": ["analyse", "{in21}/results_events_urandom", *ANALYSE21],
}


def _child(argv, out):
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop("DISPLAY", None)
    env.pop("WAYLAND_DISPLAY", None)
    return subprocess.run([sys.executable, "-m", "studyapp", *argv], capture_output=True, text=True, timeout=120,
                          env=env, cwd=out, preexec_fn=_limit_memory)


@pytest.mark.parametrize("case", list(FIFO_CASES))
def test_issue21_a_fifo_or_device_is_refused_without_blocking(case, inputs, inputs21, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    before = ((_tree(inputs), _tree(inputs21)), _tree(out))
    proc = _child(_argv21(FIFO_CASES[case], inputs, inputs21, out), out)
    if case.startswith("export-events"):
        # issue 33: the unreadable session is skipped with a warning naming its log; the study then has no
        # response, which is the refusal (exit 2, nothing written)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and "Traceback" not in proc.stderr and "events.jsonl" in lines[0], proc.stderr
        assert lines[-1].startswith("studyapp: error: ") and len(lines) == 2, proc.stderr
        assert ((_tree(inputs), _tree(inputs21)), _tree(out)) == before
        return
    assert_refused(proc.returncode, proc.stderr, before, ((_tree(inputs), _tree(inputs21)), _tree(out)))


def test_issue21_a_session_json_fifo_is_read_as_damaged_with_a_warning(inputs, inputs21, tmp_path):
    # Without --strict a damaged session.json is a warning and its content comes from events.jsonl: a FIFO is
    # such damage, reported at once (never waited on).
    out = tmp_path / "out"
    out.mkdir()
    proc = _child(["export", str(inputs21 / "results_session_fifo"), "-o", str(out / "x.csv")], out)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr
    assert "session.json" in proc.stderr and "not a regular file" in proc.stderr
    assert (out / "x.csv").read_text().count("\n") == 2  # the header and the one response
    for argv in (["export", str(inputs21 / "results_session_fifo"), "-o", str(out / "y.csv"), "--strict"],
                 ["analyse", str(inputs21 / "results_session_fifo"), "-o", str(out / "rep"), "--strict"]):
        proc = _child(argv, out)  # --strict: the warning, then the refusal; nothing written
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and "Traceback" not in proc.stderr and "not a regular file" in lines[0]
        assert lines[-1].startswith("studyapp: error: ") and "--strict" in lines[-1]
        assert not (out / "y.csv").exists() and not (out / "rep").exists()


# ---------------------------------------------------------------------------------------------------
# Issue 32 (bad input, round three): writes over participant data, hangs, tracebacks, inputs accepted
# that should be refused, misleading messages. Inputs of their own; the generated cases of the same
# families are in tests/test_bad_input_generated.py.
# ---------------------------------------------------------------------------------------------------

def _npy(array):
    import io

    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def write_bomb(path, samples, meta=None):
    """An .npz whose ``position`` member unpacks to ``samples`` float64 zeros from 8 kB per 8 MB (deflate)."""
    import io
    import json
    import zipfile

    header = io.BytesIO()  # the .npy header (magic included) of the full shape, then the zeros
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (samples,)})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("__meta__.npy", _npy(np.array(json.dumps(meta or {"rate": RATE}))))
        with z.open("position.npy", "w", force_zip64=True) as member:
            member.write(header.getvalue())
            block = bytes(1 << 23)
            for _ in range(samples * 8 // len(block)):
                member.write(block)
        for name in ("acceleration", "velocity_lvt", "velocity_true"):
            z.writestr(f"{name}.npy", _npy(np.zeros(10)))


def _session_of(results):
    return next(Path(results).rglob("events.jsonl")).parent


@pytest.fixture(scope="module")
def inputs32(tmp_path_factory):
    import json

    d = tmp_path_factory.mktemp("inputs32")
    sig = _signal()
    _results(d / "results")
    session = _session_of(d / "results")
    (session / "audio.wav").write_bytes(b"RIFF....WAVE")
    (d / "link").symlink_to(session)
    os.mkfifo(d / "fifo.wav")
    _recording(d / "rec.npz")
    with open(d / "sparse.csv", "wb") as f:  # 3 GB, all but the header a hole
        f.write(b"position\n0.1\n")
        f.truncate(3 << 30)
    write_bomb(d / "bomb.npz", 50_000_000)  # 400 MB of zeros in 400 kB
    (d / "dup.csv").write_text("position,position\n0.1,0.2\n0.2,0.3\n")
    _npz(d / "bool.npz", {**sig, "position": sig["position"] > 0}, {"rate": RATE})
    _npz(d / "complex.npz", {**sig, "position": sig["position"] + 1j}, {"rate": RATE})
    for tag, rate in (("1e9", 1e9), ("500", 500), ("1e-300", 1e-300), ("true", True)):
        _npz(d / f"rate_{tag}.npz", sig, {"rate": rate})
    (d / "good.csv").write_text("position\n" + "".join(f"{0.001 * i!r}\n" for i in range(50)))
    for name in ("nested_line", "nested_session"):
        _results(d / name)
    with open(_session_of(d / "nested_line") / "events.jsonl", "ab") as f:
        f.write(b"[" * 100_000 + b"]" * 100_000 + b"\n")
    (_session_of(d / "nested_session") / "session.json").write_text("[" * 100_000 + "]" * 100_000)
    for name in ("binary", "folder", "zero", "sparse", "fifo"):  # events.jsonl that notes --add refuses
        events = _session_of(_results(d / f"events_{name}")) / "events.jsonl"
        if name == "binary":
            events.write_bytes(np.random.default_rng(32).integers(0, 256, 5000, dtype=np.uint8).tobytes())
        elif name == "sparse":
            with open(events, "ab") as f:
                f.truncate(2 << 30)
        else:
            events.unlink()
            {"folder": events.mkdir, "zero": lambda: events.symlink_to("/dev/zero"),
             "fifo": lambda: os.mkfifo(events)}[name]()
    wrong = _session_of(_results(d / "wrong_types"))
    info = json.loads((wrong / "session.json").read_text())
    (wrong / "session.json").write_text(json.dumps({**info, "seed": "abc", "schedule": "x", "participant": 5}))
    (wrong / "events.jsonl").unlink()  # nothing to rebuild the description from: resume is refused
    demo = Path(PROTOCOL).read_text()
    for name, old, new in (("break0", "break_every = 2", "break_every = 0"),
                           ("rating_inaudible", "fmax = 1.0", "fmax = 0.001"),
                           ("ceiling_inaudible", "ceiling = 40.0", "ceiling = 0.05")):
        assert old in demo
        (d / f"{name}.toml").write_text(demo.replace(old, new))
    yield d


S32 = "{in32}/results/demo/p1/{session}"
NOTES_ADD = "{in32}/events_{name}/demo/p1"  # the participant folder: its latest session
RUN32 = [*RUN, "--results", "{out}/r", "--protocol"]
OPTIMISE32 = ["optimise", "--max-sets", "1", "--workers", "1", "--quiet", "--estimators", "LOWPASS", "{in32}/rec.npz",
              "-o", "{out}/p.toml"]
RESUME32 = ["run", "--participant", "p1", "--simulated-participant", "--headless", "--protocol", PROTOCOL,
            "--results", "{in32}/wrong_types"]

# case: (argv, what the one line must name)
CASES_32 = {
    # 1. writes over participant data
    "live-wav-over-session-audio": ([*LIVE[:2], f"wav:{S32}/audio.wav", *LIVE[3:]], "session folder"),
    "live-wav-new-in-session": ([*LIVE[:2], f"wav:{S32}/take.wav", *LIVE[3:]], "session folder"),
    "live-wav-session-by-dotdot": ([*LIVE[:2], f"wav:{S32}/../{{session}}/take.wav", *LIVE[3:]], "session folder"),
    "live-wav-session-by-link": ([*LIVE[:2], "wav:{in32}/link/take.wav", *LIVE[3:]], "session folder"),
    "live-wav-events": ([*LIVE[:2], f"wav:{S32}/events.jsonl", *LIVE[3:]], ".wav"),
    "live-wav-folder": ([*LIVE[:2], f"wav:{S32}", *LIVE[3:]], ".wav"),
    "live-wav-fifo": ([*LIVE[:2], "wav:{in32}/fifo.wav", *LIVE[3:]], "FIFO"),
    "live-wav-trailing-slash": ([*LIVE[:2], "wav:{out}/take.wav/", *LIVE[3:]], ".wav"),
    "live-wav-is-protocol": ([*LIVE[:2], f"wav:{PROTOCOL}", *LIVE[3:], "--protocol", PROTOCOL], ".wav"),
    **{f"notes-add-events-{name}": (["notes", NOTES_ADD.replace("{name}", name), "--add", "text"], named)
       for name, named in (("binary", "no valid event"), ("folder", "is a folder"), ("zero", "(a device)"),
                           ("sparse", "sparse"))},
    "run-over-wrong-types": (RESUME32, "p1"),
    "run-resume-over-wrong-types": ([*RESUME32, "--resume"], "session.json"),
    # 4. accepted when it should be refused
    "estimate-two-position-columns": (["estimate", "{in32}/dup.csv", *ESTIMATE], "'position' appears twice"),
    "estimate-boolean-positions": (["estimate", "{in32}/bool.npz", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
                                   "bool"),
    "estimate-out-trailing-slash": (["estimate", "{in32}/good.csv", *ESTIMATE[:4], "-o", "{out}/x.csv/"], "-o"),
    "estimate-out-dot": (["estimate", "{in32}/good.csv", *ESTIMATE[:4], "-o", "{out}/x.csv/."], "-o"),
    "export-out-trailing-slash": (["export", "{in32}/results", "-o", "{out}/x.csv/"], "-o"),
    "evaluate-complex-positions": (["evaluate", "{in32}/complex.npz"], "complex"),
    "live-estimators-empty": ([*LIVE, "--estimators", ""], "--estimators"),
    "live-estimators-commas": ([*LIVE, "--estimators", " , "], "--estimators"),
    "run-results-empty": ([*RUN, "--results", "", "--protocol", PROTOCOL], "--results"),
    "gui-results-empty": (["gui", "--results", ""], "--results"),
    "run-break-every-0": ([*RUN32, "{in32}/break0.toml"], "break_every"),
    "run-rating-fmax-inaudible": ([*RUN32, "{in32}/rating_inaudible.toml"], "[rating] fmax"),
    "run-ceiling-inaudible": ([*RUN32, "{in32}/ceiling_inaudible.toml"], "[adjustment] ceiling"),
    # 5. messages that mislead
    "optimise-recording-after-estimators-checkpoint-fifo": ([*OPTIMISE32, "--checkpoint", "{in32}/fifo.wav"],
                                                            "--checkpoint"),
    "optimise-recording-after-estimators-range": ([*OPTIMISE32, "--range", "LOWPASS.cutoff_hz=x"], "--range"),
    "optimise-recording-after-estimators-scheduler": ([*OPTIMISE32, "--scheduler", "nowhere"], "--scheduler"),
    "tradeoff-rates-0": ([*TRADEOFF, "-o", "{out}/t", "--rates", "0"], "--rates"),
    **{f"evaluate-meta-rate-{tag}": (["evaluate", f"{{in32}}/rate_{tag}.npz"], f"rate_{tag}.npz")
       for tag in ("1e9", "500", "1e-300", "true")},
    **{f"estimate-meta-rate-{tag}": (["estimate", f"{{in32}}/rate_{tag}.npz", "--estimator", "LOWPASS"],
                                     f"rate_{tag}.npz") for tag in ("1e9", "500", "1e-300", "true")},
}


def _argv32(template, inputs32, out):
    session = _session_of(inputs32 / "results").name
    return [a.replace("{in32}", str(inputs32)).replace("{out}", str(out)).replace("{session}", session)
            for a in template]


def _contents32(folder):
    """Every file's bytes (locks included) and every name, links as their target."""
    return {str(p.relative_to(folder)): (os.readlink(p) if p.is_symlink() else p.read_bytes() if p.is_file()
                                         else p.is_dir()) for p in sorted(Path(folder).rglob("*"))
            if not (p.is_file() and p.stat().st_size > 1 << 20)}  # the sparse files: their names only


@pytest.mark.parametrize("case", list(CASES_32))
def test_issue32_bad_input_is_refused_in_one_line_naming_it(case, inputs32, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    template, named = CASES_32[case]
    before = (_contents32(inputs32), _tree(out))
    code = main(_argv32(template, inputs32, out))
    err = capsys.readouterr().err
    assert_refused(code, err, before, (_contents32(inputs32), _tree(out)))
    assert named.replace("{session}", "") in err, err


def test_issue32_complex_positions_warn_of_nothing(inputs32, tmp_path, capsys):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's ComplexWarning before the error was a second line
        code = main(["evaluate", str(inputs32 / "complex.npz")])
    assert code == 2 and "complex" in capsys.readouterr().err


HANG_S = 30  # seconds: a command that takes this long on a refused input has hung (the machine may be busy)


@contextlib.contextmanager
def no_hang(seconds=HANG_S):
    """Fail, instead of hanging, when the body runs longer than ``seconds`` (SIGALRM interrupts a blocking
    open or read too: the handler's exception ends it)."""
    def hung(signum, frame):
        raise AssertionError(f"hung for {seconds} s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


HANGS_32 = {
    "estimate-sparse-3gb-csv": ["estimate", "{in32}/sparse.csv", *ESTIMATE],
    "evaluate-zip-bomb": ["evaluate", "{in32}/bomb.npz"],
    "estimate-zip-bomb": ["estimate", "{in32}/bomb.npz", "--estimator", "LOWPASS", "-o", "{out}/e.csv"],
    "optimise-zip-bomb": [*OPTIMISE32[:-3], "{in32}/bomb.npz", "-o", "{out}/p.toml"],
    "notes-add-events-fifo": ["notes", NOTES_ADD.replace("{name}", "fifo"), "--add", "text"],
}


@pytest.mark.parametrize("case", list(HANGS_32))
def test_issue32_no_reader_hangs_on_a_huge_sparse_packed_or_special_input(case, inputs32, tmp_path, capsys,
                                                                         monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    before = (_contents32(inputs32), _tree(out))
    with no_hang():
        code = main(_argv32(HANGS_32[case], inputs32, out))
    assert_refused(code, capsys.readouterr().err, before, (_contents32(inputs32), _tree(out)))


# 3. deeply nested JSON (a line of events.jsonl, a session.json): read as damaged, never a traceback
NESTED_32 = {
    "export": ["export", "{in32}/{name}", "-o", "{out}/x.csv"],
    "notes": ["notes", "{in32}/{name}"],
    "notes-add": ["notes", "{in32}/{name}/demo/p1/{session}", "--add", "text"],
    "plan-results": ["plan", "--protocol", PROTOCOL, "--participant", "p1", "--results", "{in32}/{name}"],
    "run-replay-gesture": [*RUN32, PROTOCOL, "--replay-gesture", "{in32}/{name}/demo/p1/{session}"],
}


@pytest.mark.parametrize("name", ["nested_line", "nested_session"])
@pytest.mark.parametrize("command", list(NESTED_32))
def test_issue32_deeply_nested_json_is_damage_not_a_traceback(command, name, inputs32, tmp_path, capsys,
                                                               monkeypatch):
    import shutil

    copy = tmp_path / "in"  # notes --add writes (a repaired log): on a copy
    shutil.copytree(inputs32 / name, copy / name, symlinks=True)
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    session = _session_of(copy / name).name
    argv = [a.replace("{in32}", str(copy)).replace("{out}", str(out)).replace("{name}", name)
            .replace("{session}", session) for a in NESTED_32[command]]
    code = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err and "RecursionError" not in err, err
    assert code in (0, 2), err
    if code == 2:
        assert len(err.strip().splitlines()) == 1 and "hand_trace" in err, err  # the replay finds no bowing
