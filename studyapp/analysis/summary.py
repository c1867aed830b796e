"""Median and quartiles per condition, the numbers behind the box plots of Figs. 7-8.

Quartiles are ``numpy.percentile`` at 25 and 75 with linear interpolation
between order statistics (Hyndman-Fan type 7, the default of numpy, R and
matplotlib's box plots), so the table and the boxes agree.
"""

import numpy as np
import pandas as pd

SUMMARY_COLUMNS = ["condition", "n", "median", "q1", "q3"]


def summarise(groups):
    """DataFrame ``condition, n, median, q1, q3`` for ``groups`` ({condition: values}), in order."""
    rows = []
    for name, values in groups.items():
        v = np.asarray(values, dtype=float)
        q1, median, q3 = np.percentile(v, [25.0, 50.0, 75.0])
        rows.append((name, v.size, float(median), float(q1), float(q3)))
    table = pd.DataFrame(rows, columns=SUMMARY_COLUMNS)
    table["condition"] = table["condition"].astype(object)
    return table
