"""CSV tables of samples, read a block of rows at a time: one header row, one row per sample, SI units.

``SampleTable(path)`` opens the file and checks its header; ``blocks(size,
names)`` then yields ``(rows, columns)`` for each run of ``size`` samples:
``rows`` the cells' original text (so a table is written back out with an
added column without reformatting the user's numbers) and ``columns`` the
named columns as float64. Memory stays that of one block whatever the file's
length. A UTF-8 byte order mark (Excel's "CSV UTF-8") is accepted.

A bad file stops with one ``InputDataError`` that names the file, the line and
the column. The header (each column once), the first row and the file's kind
(a regular file: a device such as ``/dev/zero`` never ends; not sparse,
``file_bounds``) are checked on opening; a line longer than ``LINE_LIMIT``
characters is refused when reached (a file without line breaks is never read
whole); a bad cell
further down is found when its block is read, so a caller writing as it reads
writes atomically (``studyapp.io.atomic``).
"""

import csv
import os
import stat

import numpy as np

from studyapp.errors import InputDataError
from studyapp.number_text import to_float
from studyapp.io.small_files import NotARegularFile, open_regular


LINE_LIMIT = 1 << 16  # characters: a row of a few numbers is a few hundred


class SampleTable:
    """An open CSV file of samples; use as a context manager, or call ``close``."""

    def __init__(self, path, required=("position",)):
        self.path = str(path)
        try:  # opened without blocking: a FIFO is refused at once, not waited on
            self._file = open_regular(path, "CSV", "r", newline="", encoding="utf-8-sig")
        except NotARegularFile as exc:
            raise InputDataError(str(exc)) from None
        except FileNotFoundError:
            raise InputDataError(f"{path}: no such file") from None
        except IsADirectoryError:
            raise InputDataError(f"{path}: is a folder: allowed is a CSV file") from None
        except OSError as exc:
            raise InputDataError(f"{path}: cannot read ({exc.strerror or exc})") from None
        try:
            if not stat.S_ISREG(os.fstat(self._file.fileno()).st_mode):
                raise InputDataError(f"{path}: not a regular file: allowed is a CSV file")
            self._reader = csv.reader(self._lines())
            header = self._next_row()
            if not header:
                raise InputDataError(f"{path}: empty file; expected a header row with a 'position' column")
            self.header = [h.strip() for h in header]
            twice = next((h for i, h in enumerate(self.header) if h in self.header[:i]), None)
            if twice is not None:
                raise InputDataError(f"{path}: column {twice!r} appears twice in the header: allowed is each "
                                     "column once")
            for name in required:
                if name not in self.header:
                    raise InputDataError(f"{path}: column {name!r} missing; the header has {', '.join(self.header)}")
            self._first = self._next_row()
            if self._first is None:
                raise InputDataError(f"{path}: no samples below the header")
        except BaseException:
            self._file.close()
            raise

    def _lines(self):
        """The file's lines, each at most ``LINE_LIMIT`` characters (a file without line breaks is not read whole)."""
        number = 0
        while True:
            line = self._file.readline(LINE_LIMIT + 1)
            number += 1
            if len(line) > LINE_LIMIT:
                raise InputDataError(f"{self.path}: line {number} is longer than {LINE_LIMIT} characters: allowed "
                                     "is one sample per line")
            if not line:
                return
            yield line

    def _next_row(self):
        """The next non-blank row (a trailing blank line is not a sample), checked for its length; None at the end."""
        try:
            for row in self._reader:
                if not row:
                    continue
                if hasattr(self, "header") and len(row) != len(self.header):
                    raise InputDataError(f"{self.path}: line {self._reader.line_num} has {len(row)} cells, "
                                         f"the header has {len(self.header)}")
                return row
        except (UnicodeDecodeError, csv.Error) as exc:
            raise InputDataError(f"{self.path}: not a readable CSV file ({exc})") from None
        return None

    def blocks(self, size, names):
        """Yield ``(rows, {name: float64 array})`` for runs of up to ``size`` rows; ``names`` must be in the header."""
        indices = {name: self.header.index(name) for name in names}
        row = self._first
        while row is not None:
            rows, lines = [], []
            while row is not None and len(rows) < size:
                rows.append(row)
                lines.append(self._reader.line_num)
                row = self._next_row()
            yield rows, {name: self._floats(rows, lines, j, name) for name, j in indices.items()}

    def _floats(self, rows, lines, j, name):
        cells = [row[j] for row in rows]
        if "_" not in "".join(cells):  # numpy, like float(), reads "1_0" as 10 (studyapp.number_text)
            try:
                return np.array(cells, dtype=np.float64)  # float() per cell, in C
            except ValueError:
                pass
        out = np.empty(len(rows))
        for i, row in enumerate(rows):  # find the cell to name
            try:
                out[i] = to_float(row[j])
            except ValueError:
                raise InputDataError(
                    f"{self.path}: line {lines[i]}, column {name!r}: {row[j].strip()!r} is not a number"
                ) from None
        return out

    def close(self):
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def write_header(f, header, extra_name):
    csv.writer(f, lineterminator="\n").writerow(list(header) + [extra_name])


def write_rows(f, rows, extra_values):
    """Write ``rows`` (lists of cells) each with one more cell, ``extra_values`` as shortest round-trip text."""
    # csv writes a float as repr() does: the shortest text that reads back to the same number
    csv.writer(f, lineterminator="\n").writerows(list(r) + [v] for r, v in zip(rows, extra_values.tolist()))
