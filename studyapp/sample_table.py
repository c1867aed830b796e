"""CSV tables of samples: one header row, one row per sample, SI units.

Reading checks everything before anything is computed, so a bad file stops
with one line that names the file, the line and the column, and nothing is
written. Cells keep their original text, so a table can be written back out
with an added column without reformatting the user's numbers.
"""

import csv
from dataclasses import dataclass

import numpy as np

from studyapp.errors import InputDataError


@dataclass
class SampleTable:
    path: str
    header: list
    rows: list  # list of lists of cell text

    def column(self, name):
        """The column ``name`` as float64; a non-numeric cell raises InputDataError."""
        j = self.header.index(name)
        out = np.empty(len(self.rows))
        for i, row in enumerate(self.rows):
            cell = row[j].strip()
            try:
                out[i] = float(cell)
            except ValueError:
                raise InputDataError(
                    f"{self.path}: line {i + 2}, column {name!r}: {cell!r} is not a number"
                ) from None
        return out


def read_csv(path, required=("position",)):
    try:
        with open(path, newline="") as f:
            reader = csv.reader(f)
            header = next(reader, None)
            rows = list(reader)
    except FileNotFoundError:
        raise InputDataError(f"{path}: no such file") from None
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputDataError(f"{path}: not a readable CSV file ({exc})") from None
    if not header:
        raise InputDataError(f"{path}: empty file; expected a header row with a 'position' column")
    header = [h.strip() for h in header]
    for name in required:
        if name not in header:
            raise InputDataError(f"{path}: column {name!r} missing; the header has {', '.join(header)}")
    rows = [r for r in rows if r]  # a trailing blank line is not a sample
    for i, row in enumerate(rows):
        if len(row) != len(header):
            raise InputDataError(f"{path}: line {i + 2} has {len(row)} cells, the header has {len(header)}")
    if not rows:
        raise InputDataError(f"{path}: no samples below the header")
    return SampleTable(str(path), header, rows)


def write_csv(f, header, rows, extra_name, extra_values):
    """Write ``rows`` with one more column ``extra_name`` (values as shortest round-trip text)."""
    writer = csv.writer(f, lineterminator="\n")
    writer.writerow(list(header) + [extra_name])
    for row, value in zip(rows, extra_values):
        writer.writerow(list(row) + [repr(float(value))])
