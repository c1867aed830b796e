"""The estimators by name, in the order of ``names()``."""

from studyapp.errors import ParameterError
from studyapp.estimators import bdiff, complementary, foaw, hybrids, kalman, kinds, leastsq, levant, lowpass, lvt

SPECS = {
    spec.name: spec
    for spec in (
        bdiff.SPEC,
        lowpass.SPEC,
        leastsq.SPEC,
        foaw.SPEC,
        levant.SPEC_LEVANT,
        levant.SPEC_LEVANTLP,
        kalman.SPEC_KALPOS,
        kalman.SPEC_KALMAN,
        hybrids.SPEC_KALLEV,
        hybrids.SPEC_KALLEVACC,
        hybrids.SPEC_KALFOAW,
        hybrids.SPEC_KALFOAWACC,
        complementary.SPEC_COMP1,
        complementary.SPEC_COMP2,
        lvt.SPEC,
    )
}
assert list(SPECS) == kinds.NAMES and all(SPECS[n].kind == i for i, n in enumerate(kinds.NAMES))


def spec(name):
    try:
        return SPECS[name]
    except KeyError:
        raise ParameterError(f"unknown estimator {name!r}: allowed are {', '.join(SPECS)}") from None
