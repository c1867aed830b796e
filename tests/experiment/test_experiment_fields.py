"""experiment/fields.py: the protocol's field readers, public, so pages.py reads its tables without protocol.py."""

import ast
import inspect

import pytest

from studyapp.errors import UserError
from studyapp.experiment import pages
from studyapp.experiment.fields import Fields, table_fields


def test_pages_no_longer_imports_the_protocol():
    """The circle pages.py <-> protocol.py (pages took the private _Fields from protocol) is gone."""
    tree = ast.parse(inspect.getsource(pages))
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    imported |= {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
    assert "studyapp.experiment.protocol" not in imported
    assert "studyapp.experiment.fields" in imported


def test_each_problem_is_one_line_naming_file_table_and_field():
    fields = Fields("p.toml", "rating", {"fmax": float("nan"), "trials": 3, "typo": 1})
    with pytest.raises(UserError, match=r"^p\.toml: \[rating\] fmax = nan: allowed is a number from 0 to 200 N$"):
        fields.number("fmax", 0.0, 200.0, "N")
    assert fields.integer("trials", 1, 10) == 3
    with pytest.raises(UserError, match=r"^p\.toml: \[rating\] typo is not a known field: allowed is one of fmax, trials$"):
        fields.finish()
    with pytest.raises(UserError, match=r"^p\.toml: \[rating\] missing is missing: allowed is a non-empty string$"):
        fields.string("missing")


def test_a_table_is_read_or_refused():
    assert table_fields("p.toml", {}, "estimators", required=False) is None
    with pytest.raises(UserError, match=r"table \[study\] is missing"):
        table_fields("p.toml", {}, "study")
    with pytest.raises(UserError, match=r"\[study\] = 3: allowed is a table"):
        table_fields("p.toml", {"study": 3}, "study")
    assert table_fields("p.toml", {"study": {"seed": 1}}, "study").integer("seed", 0, 9) == 1
