"""CSV tables of evaluation results, written atomically (NaN and None as empty cells)."""

import csv
import math

from studyapp.io.atomic import atomic_open


def _cell(v):
    if v is None:
        return ""
    if hasattr(v, "item"):  # numpy scalars first: np.float64 is a float whose repr is "np.float64(...)"
        return _cell(v.item())
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return v


def write_csv(path, rows, columns=None):
    rows = list(rows)
    if columns is None:
        columns = list(rows[0]) if rows else []
    with atomic_open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _cell(row.get(k)) for k in columns})
