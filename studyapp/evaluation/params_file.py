"""PARAMS.toml: tuned estimator parameters (our Table 1) with their provenance.

The file is flat TOML, one table per estimator plus two tables of metadata:

    # Tuned by studyapp optimise ...
    [provenance]
    studyapp_version = "0.1.0"
    seed = 0
    recordings = ["sim/fmax_0.3.npz", ...]
    recording_sha256 = ["9f2c...", ...]
    ...

    [objective]           # F_g of each estimator under the final scale
    KALMAN = 3.21

    [conventions]         # what the numbers mean (studyapp.estimators.conventions)
    KALMAN = "q_convention = scaled: Q = q T Gamma Gamma^T (the authors' third-order filters)"

    [KALMAN]
    q = 108.0
    r_acc = 62800.0
    r_pos = 2e-10
    q_convention = "scaled"

Every other table must be named after an estimator, and its keys are that
estimator's parameters (``studyapp estimators`` lists them). ``[conventions]``
is written for the reader, from the estimator tables, one line per estimator
that has conventions: the choice parameters (``q_convention``, ``start``) and
fixed meanings (FOAW's ``window`` is the paper's Size). What runs is what the
estimator tables say; ``read`` accepts the table and does not use it. ``read`` uses the
standard library's ``tomllib`` (through ``studyapp.io.small_files``: a regular
file of at most 1 MB); ``write`` writes the flat structure by hand
(strings, numbers, booleans and flat lists of them), atomically.
"""

import json
import math
from pathlib import Path

from studyapp.errors import UserError
from studyapp.estimators import conventions
from studyapp.estimators.registry import SPECS
from studyapp.io.atomic import atomic_open
from studyapp.io.small_files import read_toml

META_TABLES = ("provenance", "objective", "conventions")


def read(path):
    """(params, provenance): params is name -> {parameter: value}; names are checked, values are not."""
    path = Path(path)
    _, data = read_toml(path, "parameter (PARAMS.toml)")
    params = {}
    for key, value in data.items():
        if key in META_TABLES:
            if not isinstance(value, dict):
                raise UserError(f"{path}: {key} = {value!r}: allowed is a table [{key}]")
            continue
        if key not in SPECS:
            raise UserError(f"{path}: table [{key}] is not an estimator: allowed are {', '.join(SPECS)}, "
                            f"{', '.join(META_TABLES)}")
        if not isinstance(value, dict):
            raise UserError(f"{path}: {key} must be a table [{key}] of parameters")
        for name, v in value.items():
            if isinstance(v, (dict, list)):
                raise UserError(f"{path}: [{key}] {name} must be a number or a string")
        params[key] = dict(value)
    if not params:
        raise UserError(f"{path}: no estimator table: allowed is a file of [NAME] tables, as studyapp optimise "
                        "writes")
    return params, dict(data.get("provenance", {}))


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string: same escapes as JSON
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if hasattr(v, "item"):  # numpy scalars
        return _value(v.item())
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _key(k):
    return k if k.replace("_", "").replace("-", "").isalnum() and k.isascii() else json.dumps(k)


def dumps(params, provenance=None, objective=None, comment=None):
    lines = []
    if comment:
        lines += [f"# {line}" for line in comment.splitlines()] + [""]

    tables = []
    if provenance:
        tables.append(("provenance", provenance))
    if objective:
        tables.append(("objective", objective))
    meanings = {name: conventions.text(name, values) for name, values in params.items()}
    meanings = {name: line for name, line in meanings.items() if line}
    if meanings:
        tables.append(("conventions", meanings))
    tables += list(params.items())
    for name, table in tables:
        lines.append(f"[{_key(name)}]")
        lines += [f"{_key(k)} = {_value(v)}" for k, v in table.items()]
        lines.append("")
    return "\n".join(lines)


def write(path, params, provenance=None, objective=None, comment=None):
    text = dumps(params, provenance, objective, comment)
    with atomic_open(path, "w", encoding="utf-8") as f:
        f.write(text)
