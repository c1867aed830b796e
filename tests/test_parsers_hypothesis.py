"""Generated input for the parsers (issue 14, item 7): any bytes or text is parsed or refused with a UserError.

Never another exception: a ``KeyError``, ``TypeError``, ``RecursionError`` or
``OverflowError`` here would be a traceback on the command line. The
protocol and parameter cases also mutate one field of a valid document to a
generated value, so they reach the checks behind the TOML syntax.
"""

import json
import math
import os
import tempfile
import tomllib
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studyapp.errors import UserError
from studyapp.evaluation import params_file
from studyapp.experiment.protocol import parse_protocol
from studyapp.io.recording_blocks import RecordingBlocks
from studyapp.io.sample_table import SampleTable

REPO = Path(__file__).resolve().parents[1]
DEMO = (REPO / "protocols" / "demo.toml").read_text(encoding="utf-8")
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

scalars = st.one_of(st.integers(-2**70, 2**70), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
                    st.text(max_size=20))
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(st.text("abcxyz_", min_size=1, max_size=6),
                                                                       inner, max_size=3)), max_leaves=8)


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and not math.isfinite(v):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"


def toml_document(doc):
    lines = []
    for table, fields in doc.items():
        if isinstance(fields, dict):
            lines.append(f"[{json.dumps(table)}]")
            lines += [f"{json.dumps(k)} = {toml_value(v)}" for k, v in fields.items()]
        elif isinstance(fields, list) and all(isinstance(item, dict) for item in fields):
            for item in fields:  # an array of tables, e.g. [[pages]]
                lines.append(f"[[{json.dumps(table)}]]")
                lines += [f"{json.dumps(k)} = {toml_value(v)}" for k, v in item.items()]
        else:
            lines.insert(0, f"{json.dumps(table)} = {toml_value(fields)}")
    return "\n".join(lines) + "\n"


def _file(data, suffix):
    fd, name = tempfile.mkstemp(suffix=suffix)
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    return name


def _csv_bytes():
    cells = st.one_of(st.sampled_from(["0.1", "-1e3", "nan", "inf", "", "x", '"1,2"', "1e400", "0x10"]),
                      st.text(max_size=6))
    rows = st.lists(st.lists(cells, min_size=1, max_size=4).map(",".join), max_size=6)
    header = st.sampled_from(["position", "\ufeffposition", "position,velocity", "speed", "", "position,position"])
    text = st.tuples(header, rows).map(lambda hr: "\n".join([hr[0], *hr[1]]))
    return st.one_of(st.binary(max_size=200), text.map(lambda t: t.encode("utf-8")))


@SETTINGS
@given(_csv_bytes(), st.integers(1, 4))
def test_csv_is_parsed_or_refused(data, block):
    name = _file(data, ".csv")
    try:
        with SampleTable(name) as table:
            names = [n for n in ("position", "velocity") if n in table.header]
            for rows, columns in table.blocks(block, names):
                assert all(len(r) == len(table.header) for r in rows)
                assert all(c.dtype == np.float64 and len(c) == len(rows) for c in columns.values())
    except UserError:
        pass
    finally:
        os.unlink(name)


@SETTINGS
@given(st.binary(max_size=300))
def test_recording_bytes_are_read_or_refused(data):
    name = _file(data, ".npz")
    try:
        with RecordingBlocks(name) as rec:
            for _ in rec.blocks(3):
                pass
    except UserError:
        pass
    finally:
        os.unlink(name)


@SETTINGS
@given(st.text(max_size=300))
def test_protocol_text_is_parsed_or_refused(text):
    try:
        parse_protocol(text, "p.toml")
    except UserError:
        pass


def field_paths(doc):
    """(table, key) for a table's fields; (table, index, key) for an array of tables' (e.g. [[pages]])."""
    paths = []
    for table, fields in doc.items():
        if isinstance(fields, dict):
            paths += [(table, key) for key in fields]
        elif isinstance(fields, list):
            paths += [(table, i, key) for i, item in enumerate(fields) for key in item]
    return paths


@SETTINGS
@given(st.sampled_from(field_paths(tomllib.loads(DEMO))), values)
def test_protocol_with_one_field_changed_is_parsed_or_refused(field, value):
    doc = tomllib.loads(DEMO)
    target = doc
    for key in field[:-1]:
        target = target[key]
    target[field[-1]] = value
    try:
        protocol = parse_protocol(toml_document(doc), "p.toml")
    except UserError:
        return
    assert math.isfinite(protocol.rate) and protocol.rate > 0


@SETTINGS
@given(st.one_of(st.binary(max_size=300), st.text(max_size=300).map(str.encode)))
def test_params_bytes_are_read_or_refused(data):
    name = _file(data, ".toml")
    try:
        params_file.read(name)
    except UserError:
        pass
    finally:
        os.unlink(name)


@SETTINGS
@given(st.sampled_from(["provenance", "objective", "LOWPASS", "KALMAN", "NOPE"]), st.one_of(values, scalars))
def test_params_with_one_table_changed_are_read_or_refused(table, value):
    doc = {"provenance": {"seed": 0}, "objective": {"LOWPASS": 1.0}, "LOWPASS": {"cutoff_hz": 256.0}}
    doc[table] = value
    name = _file(toml_document(doc).encode("utf-8"), ".toml")
    try:
        params, provenance = params_file.read(name)
        assert isinstance(provenance, dict) and all(isinstance(p, dict) for p in params.values())
    except UserError:
        pass
    finally:
        os.unlink(name)
