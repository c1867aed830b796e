"""Integer ids of the estimators, used by the compiled dispatch in ``dispatch.py``.

The order is the order of ``studyapp.estimators.names()`` (the issue's table,
which follows the paper's Table 2 plus BDIFF and the LVT tachometer).
"""

BDIFF = 0
LOWPASS = 1
LEASTSQ = 2
FOAW = 3
LEVANT = 4
LEVANTLP = 5
KALPOS = 6
KALMAN = 7
KALLEV = 8
KALLEVACC = 9
KALFOAW = 10
KALFOAWACC = 11
COMP1 = 12
COMP2 = 13
LVT = 14

NAMES = [
    "BDIFF", "LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALMAN",
    "KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC", "COMP1", "COMP2", "LVT",
]
