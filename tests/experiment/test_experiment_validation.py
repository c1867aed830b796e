"""Everything in a protocol is checked before enrolment: every number has a finite range the
model accepts, and a refused protocol is one line naming the file and the field, exit 2,
with no participant folder left behind (issue 14, item 5)."""

from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.engine.safety import SafetyLimits
from studyapp.errors import ParameterError
from studyapp.experiment.protocol import SAFE_CEILING, load_protocol
from studyapp.experiment.session import Session
from studyapp.model.fmax_knob import KNOB_MAX, fmax_from_knob
from studyapp.model.loop import FMAX_LIMIT, check_fmax

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
LISTEN = '\n[listen]\nconditions = ["LVT"]\nfmax = 0.5\nduration_s = 1.0\ninstructions = "Listen."\n'


def demo(**replace):
    """The demo protocol (with a listen table), each ``old=new`` text replaced once."""
    text = DEMO.read_text().replace('tasks = ["rating", "adjustment"]', 'tasks = ["rating", "adjustment", "listen"]')
    text += LISTEN
    for old, new in replace.values():
        assert old in text
        text = text.replace(old, new, 1)
    return text


BAD = [
    ("[rating] fmax", dict(a=("fmax = 1.0", "fmax = 1e6"))),
    ("[rating] fmax", dict(a=("fmax = 1.0", "fmax = inf"))),
    ("[rating] fmax", dict(a=("fmax = 1.0", "fmax = nan"))),
    ("[rating] fmax", dict(a=("fmax = 1.0", "fmax = 200.001"))),
    ("[adjustment] ceiling", dict(a=("ceiling = 40.0", "ceiling = 1e6"))),
    ("[adjustment] ceiling", dict(a=("ceiling = 40.0", "ceiling = inf"))),
    ("[adjustment] ceiling", dict(a=("ceiling = 40.0", "ceiling = -inf"))),
    ("[adjustment] decades", dict(a=("decades = 2.0", "decades = inf"))),
    ("[adjustment] decades", dict(a=("decades = 2.0", "decades = nan"))),
    ("[listen] duration_s", dict(a=("duration_s = 1.0", "duration_s = inf"))),
    ("[listen] duration_s", dict(a=("duration_s = 1.0", "duration_s = 0.0"))),
    ("[listen] duration_s", dict(a=("duration_s = 1.0", "duration_s = 1e6"))),
    ("[listen] fmax", dict(a=("fmax = 0.5", "fmax = 1e6"))),
    ("[apparatus] rate", dict(a=("rate = 5000.0", "rate = inf"))),
    ("[apparatus] rate", dict(a=("rate = 5000.0", "rate = nan"))),
    ("[estimators] LOWPASS", dict(a=("[apparatus]", "[estimators]\nLOWPASS = { cutoff_hz = inf }\n\n[apparatus]"))),
    # issue 21 item 9: no F_max above the protocol's ceiling (the engine's hard clamp), at most the motors' 60 N
    ("[rating] fmax", dict(a=("fmax = 1.0", "fmax = 100.0"))),
    ("[listen] fmax", dict(a=("fmax = 0.5", "fmax = 60.5"))),
    ("[adjustment] ceiling", dict(a=("ceiling = 40.0", "ceiling = 61.0"))),
    ("[apparatus] fmax_ceiling", dict(a=("rate = 5000.0", "rate = 5000.0\nfmax_ceiling = 61.0"))),
    ("[apparatus] fmax_ceiling", dict(a=("rate = 5000.0", "rate = 5000.0\nfmax_ceiling = 0.0"))),
    ("[adjustment] ceiling", dict(a=("rate = 5000.0", "rate = 5000.0\nfmax_ceiling = 5.0"))),
    ("[rating] fmax", dict(a=("rate = 5000.0", "rate = 5000.0\nfmax_ceiling = 0.5"),
                           b=("ceiling = 40.0", "ceiling = 0.5"))),
]


@pytest.mark.parametrize("field,replace", BAD, ids=[f"{f} {r['a'][1].split('=')[-1].strip()}" for f, r in BAD])
def test_a_bad_number_is_refused_before_enrolment(tmp_path, capsys, field, replace):
    results = tmp_path / "results"
    Session.create(load_protocol(DEMO), "P01", results).close()  # an enrolled participant
    before = sorted(p.relative_to(results) for p in results.rglob("*"))
    bad = tmp_path / "bad.toml"
    bad.write_text(demo(**replace))
    code = main(["run", "--protocol", str(bad), "--participant", "P02", "--headless", "--simulated-participant",
                 "--results", str(results)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
    assert err.startswith(f"studyapp: error: {bad}: {field}") and "allowed" in err
    assert sorted(p.relative_to(results) for p in results.rglob("*")) == before  # no P02, P01 untouched


def test_the_ranges_end_where_the_model_and_the_safety_ceiling_do(tmp_path):
    # The top is the motors' sustained limit, the engine's default ceiling (issue 21 item 9: before, the
    # protocol took up to the loop's 200 N, and the engine applied 60 N while the log said 200).
    assert SAFE_CEILING == SafetyLimits().fmax_ceiling == 60.0 and SAFE_CEILING <= FMAX_LIMIT
    path = tmp_path / "top.toml"
    path.write_text(demo(a=("fmax = 1.0", f"fmax = {SAFE_CEILING}"), b=("ceiling = 40.0", f"ceiling = {SAFE_CEILING}"),
                         c=("decades = 2.0", "decades = 12.0")))
    protocol = load_protocol(path)
    adjustment = protocol.task("adjustment")
    # Every F_max a session can set at the top of the ranges is one the loop accepts.
    for k in (1, KNOB_MAX):
        assert check_fmax(fmax_from_knob(k, adjustment.ceiling, adjustment.decades)) > 0
    assert check_fmax(protocol.task("rating").fmax) == SAFE_CEILING == protocol.fmax_ceiling
    with pytest.raises(ParameterError):
        check_fmax(FMAX_LIMIT * (1 + 1e-9))


def test_the_protocols_ceiling_is_given_or_the_largest_fmax_its_tasks_use(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(demo(a=("ceiling = 40.0", "ceiling = 5.0")))
    assert load_protocol(path).fmax_ceiling == 5.0  # adjustment 5 N, rating 1 N, listen 0.5 N
    path.write_text(demo(a=("rate = 5000.0", "rate = 5000.0\nfmax_ceiling = 45.0")))
    protocol = load_protocol(path)
    assert protocol.fmax_ceiling == 45.0 and protocol.settings()["fmax_ceiling"] == 45.0
