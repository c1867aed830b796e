"""Integer ids of the estimators, the compile-time constants of the compiled dispatch (``dispatch.py``).

The id of an estimator is its position in ``registry.REGISTRY`` (the order of
``studyapp.estimators.names()``: the paper's Table 2 plus BDIFF and the LVT
tachometer); the registry checks this at import, and
tests/estimators/test_estimators_dispatch.py checks that the dispatch sends
every id to its registered kernel.
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
