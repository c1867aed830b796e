"""The two pseudo-sources of the loop's velocity: what can drive the model besides an estimator (paper Sec. 4.2, 8.4).

The force (eq. 1's friction) is computed from one velocity, the "source". It is an
active estimator's output, or one of two pseudo-sources read straight from the
sensors, with no estimator in between:

    TRUE        the simulated device's true velocity (simulation only; a real device has none)
    LVT_SENSOR  the linear velocity transducer's reading, the study's reference condition (Sec. 8.4)

The loop's control vector selects them by the negative indices below (an
estimator by its index in the active set). The user-visible name of the sensor
source is "LVT", the same text as the LVT estimator's name (estimators/lvt.py),
which passes the same reading through: the text stays for compatibility with
command lines, protocols and recordings' metadata, and the two give the same
velocity, so the shared name is harmless. In code, the sensor source is
``LVT_SENSOR`` and the estimator is ``estimators.lvt.NAME``.
"""

TRUE = "TRUE"
LVT_SENSOR = "LVT"
PSEUDO_SOURCES = (LVT_SENSOR, TRUE)
TRUE_INDEX = -1
LVT_SENSOR_INDEX = -2


def is_pseudo(source):
    """Whether ``source`` is a pseudo-source (needs no estimator in the active set)."""
    return source in PSEUDO_SOURCES


def with_pseudo_sources(names):
    """``names`` (estimators) followed by the pseudo-sources not already among them."""
    names = list(names)
    return names + [s for s in PSEUDO_SOURCES if s not in names]
