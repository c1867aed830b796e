"""evaluation.csv and validation.csv hold plain numbers: every numeric cell parses with float() (issue 12).

numpy 2 writes repr(np.float64(0.5)) as "np.float64(0.5)"; the cells must read "0.5".
"""

import csv

import numpy as np

from studyapp.cli import main
from studyapp.evaluation.tables import write_csv
from tests.evaluation.conftest import synthetic_recording

TEXT_COLUMNS = {"estimator", "recording", "validation_recording"}


def _numeric_cells(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert rows
    return [(column, value) for row in rows for column, value in row.items() if column not in TEXT_COLUMNS]


def test_numpy_scalars_are_written_as_plain_numbers(tmp_path):
    path = tmp_path / "t.csv"
    write_csv(path, [{"a": np.float64(0.1), "b": np.int64(3), "c": np.float64("nan"), "d": np.float32(0.5)}])
    assert path.read_text().splitlines()[1] == "0.1,3,,0.5"


def test_evaluation_and_validation_tables_hold_plain_numbers(tmp_path, capsys):
    from studyapp.io.recording import save

    for folder, seed in (("train", 0), ("validation", 1)):
        (tmp_path / folder).mkdir()
        for fmax in (1.1, 4.4):
            save(synthetic_recording(fmax, duration=0.3, seed=seed), tmp_path / folder / f"fmax_{fmax}.npz")
    out = tmp_path / "ev"
    assert main(["evaluate", str(tmp_path / "train"), "--estimators", "LOWPASS,KALMAN,FOAW", "-o", str(out),
                 "--validation", str(tmp_path / "validation")]) == 0
    capsys.readouterr()
    for name in ("evaluation.csv", "validation.csv"):
        cells = _numeric_cells(out / name)
        assert not [c for c in cells if "np." in c[1]], name
        for column, value in cells:
            if value:  # empty: NaN (a percentage of a LOWPASS delay of 0)
                float(value)
