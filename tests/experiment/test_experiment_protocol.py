"""Protocol validation: the shipped protocols load; every missing or bad field is one clear error."""

import hashlib
import json
from pathlib import Path

import pytest

from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "protocols"

BASE = {
    "study": {"name": "pilot", "title": "A pilot", "tasks": ["rating", "adjustment"], "seed": 7},
    "apparatus": {"rate": 5000.0, "knobs": 8, "pads": 8, "gesture": "strokes"},
    "estimators": {"LOWPASS": {"cutoff_hz": 300.0}},
    "rating": {"conditions": ["LOWPASS", "LEVANT", "LVT"], "fmax": 1.0, "confirm_pad": 0,
               "instructions": "Rate the noisiness."},
    "adjustment": {"conditions": ["LOWPASS", "LVT"], "trials": 2, "ceiling": 30.0, "decades": 2.0,
                   "knob": 0, "confirm_pad": 1, "instructions": "Find the breakdown."},
}

REQUIRED = [
    ("study", "name"), ("study", "tasks"), ("study", "seed"), ("apparatus", "rate"),
    ("rating", "conditions"), ("rating", "fmax"), ("rating", "instructions"),
    ("adjustment", "conditions"), ("adjustment", "trials"), ("adjustment", "ceiling"),
    ("adjustment", "instructions"),
]


def toml(document):
    """TOML text for a document of tables whose values are strings, numbers, lists or inline tables."""

    def value(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        return json.dumps(v)

    return "".join(
        f"[{table}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in fields.items()) + "\n"
        for table, fields in document.items()
    )


def write(tmp_path, document, name="study.toml"):
    path = tmp_path / name
    path.write_text(toml(document), encoding="utf-8")
    return path


def without(table, field=None):
    doc = json.loads(json.dumps(BASE))
    if field is None:
        del doc[table]
    else:
        del doc[table][field]
    return doc


def error(path):
    with pytest.raises(UserError) as info:
        load_protocol(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    assert "allowed" in message
    return message


@pytest.mark.parametrize("name", ["sinclair2014.toml", "demo.toml"])
def test_shipped_protocols_load(name):
    p = load_protocol(SHIPPED / name)
    assert p.sha256 == hashlib.sha256((SHIPPED / name).read_bytes()).hexdigest()
    assert p.tasks == ("rating", "adjustment")
    assert p.rate == 5000.0


def test_sinclair2014_is_the_paper_study():
    p = load_protocol(SHIPPED / "sinclair2014.toml")
    assert set(p.task("rating").conditions) == {"LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALLEV", "LVT"}
    assert set(p.task("adjustment").conditions) == set(p.task("rating").conditions) | {"KALFOAW"}
    assert p.task("rating").fmax == 1.0 and p.task("adjustment").trials == 6 and p.knobs == 8
    assert p.estimator_params("LEVANT") == {"c": 19.7, "start": "zero"}
    assert p.estimator_params("KALLEV")["q"] == 6.38e4
    # Table 1's numbers with the conventions they were tuned in, stated in the file
    assert p.estimator_params("KALPOS")["q_convention"] == "continuous"
    assert p.estimator_params("KALLEV")["q_convention"] == p.estimator_params("KALFOAW")["q_convention"] == "scaled"


def test_demo_is_short():
    p = load_protocol(SHIPPED / "demo.toml")
    assert len(p.task("rating").conditions) == 3 and len(p.task("adjustment").conditions) == 3 and p.task("adjustment").trials == 1


def test_a_complete_protocol_loads(tmp_path):
    p = load_protocol(write(tmp_path, BASE))
    assert p.study == "pilot" and p.task("adjustment").confirm_pad == 1 and p.task("adjustment").decades == 2.0
    assert p.estimator_params("LOWPASS") == {"cutoff_hz": 300.0} and p.estimator_params("LVT") == {}
    assert p.settings()["rating"]["conditions"] == ["LOWPASS", "LEVANT", "LVT"]


@pytest.mark.parametrize("table,field", REQUIRED, ids=[f"{t}.{f}" for t, f in REQUIRED])
def test_each_missing_field_names_itself(tmp_path, table, field):
    message = error(write(tmp_path, without(table, field)))
    assert f"[{table}] {field} is missing" in message


@pytest.mark.parametrize("table", ["study", "apparatus", "rating", "adjustment"])
def test_each_missing_table_names_itself(tmp_path, table):
    assert f"[{table}]" in error(write(tmp_path, without(table)))


def test_a_task_table_may_go_with_its_task(tmp_path):
    doc = without("rating")
    doc["study"]["tasks"] = ["adjustment"]
    assert load_protocol(write(tmp_path, doc)).tasks == ("adjustment",)


@pytest.mark.parametrize(
    "table,field,value,expected",
    [
        ("study", "name", "no spaces", "[study] name"),
        ("study", "tasks", ["rating", "rating"], "[study] tasks"),
        ("study", "tasks", ["ratings"], "[study] tasks"),
        ("study", "seed", -1, "[study] seed"),
        ("apparatus", "rate", 100.0, "[apparatus] rate"),
        ("apparatus", "knobs", 0, "[apparatus] knobs"),
        ("apparatus", "gesture", "waltz", "[apparatus] gesture = 'waltz'"),
        ("rating", "conditions", ["LOWPASS"], "[rating] conditions"),
        ("rating", "conditions", ["LOWPASS", "NOPE"], "unknown condition 'NOPE'"),
        ("rating", "conditions", ["LVT", "LVT"], "twice"),
        ("rating", "conditions", ["BDIFF", "LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS",
                                  "KALMAN", "LVT"], "[rating] conditions"),
        ("rating", "fmax", 0.0, "[rating] fmax"),
        ("rating", "fmax", "1 N", "[rating] fmax"),
        ("rating", "confirm_pad", 8, "[rating] confirm_pad"),
        ("adjustment", "trials", 0, "[adjustment] trials"),
        ("adjustment", "trials", 2.5, "[adjustment] trials"),
        ("adjustment", "ceiling", -3.0, "[adjustment] ceiling"),
        ("adjustment", "decades", 0.0, "[adjustment] decades"),
        ("adjustment", "knob", 8, "[adjustment] knob"),
        ("adjustment", "instructions", "", "[adjustment] instructions"),
        ("adjustment", "colour", "red", "[adjustment] colour is not a known field"),
        ("estimators", "LOWPASS", {"cutoff_hz": 4000.0}, "cutoff_hz"),
        ("estimators", "LOWPASS", {"cutof_hz": 300.0}, "cutof_hz"),
        ("estimators", "NOPE", {}, "[estimators] NOPE"),
    ],
)
def test_bad_values_are_named(tmp_path, table, field, value, expected):
    doc = json.loads(json.dumps(BASE))
    doc[table][field] = value
    path = write(tmp_path, doc)
    with pytest.raises(UserError) as info:
        load_protocol(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    assert expected in message
    assert "allowed" in message


def test_unknown_table_and_bad_toml(tmp_path):
    doc = json.loads(json.dumps(BASE))
    doc["extras"] = {"x": 1}
    assert "[extras] is not a known table" in error(write(tmp_path, doc))
    bad = tmp_path / "bad.toml"
    bad.write_text("[study\nname = 1\n")
    with pytest.raises(UserError, match="bad.toml: invalid TOML"):
        load_protocol(bad)
    with pytest.raises(UserError, match="missing.toml: cannot read"):
        load_protocol(tmp_path / "missing.toml")


def test_hash_is_sha256_of_the_bytes(tmp_path):
    a = write(tmp_path, BASE, "a.toml")
    b = tmp_path / "b.toml"
    b.write_bytes(a.read_bytes() + b"# a comment changes the hash\n")
    assert load_protocol(a).sha256 == hashlib.sha256(a.read_bytes()).hexdigest()
    assert load_protocol(b).sha256 != load_protocol(a).sha256


def test_session_settings_record_the_estimators_conventions(tmp_path):
    """session.json's protocol settings say what the numbers mean: the protocol's choices, else the defaults."""
    given = {**BASE, "estimators": {"KALPOS": {"q": 0.191, "q_convention": "eq19"}, "LEVANT": {"start": "first"}}}
    conventions = load_protocol(write(tmp_path, given)).settings()["conventions"]
    assert conventions["KALPOS"] == {"q_convention": "eq19"} and conventions["LEVANT"] == {"start": "first"}
    assert conventions["KALMAN"] == {"q_convention": "scaled"} and conventions["FOAW"] == {"window": "size"}
    assert "LOWPASS" not in conventions
    shipped = load_protocol(SHIPPED / "sinclair2014.toml").settings()["conventions"]
    assert shipped["KALPOS"] == {"q_convention": "continuous"} and shipped["LEVANT"] == {"start": "zero"}
    json.dumps(conventions)
