"""The estimators by name, in the order of ``names()``: each one's spec and compiled kernel, registered once.

``REGISTRY`` pairs every ``EstimatorSpec`` with its kernel ``step(s, p, x, a, v)``.
Everything else that lists estimators is derived from it (``SPECS``,
``KERNELS``, ``names()``) or checked against it: the ids in ``kinds.py`` (below,
at import) and the compiled dispatch's two switches (``dispatch.py``, by
tests/estimators/test_estimators_dispatch.py, which runs every registered kind
through both and compares with the kernel called directly).

Adding an estimator: its module (kernel, ``build``, ``SPEC``), an id in
``kinds.py``, one line here, and one branch in each of ``dispatch.step_any`` and
``dispatch.run_block`` (a kind without its branch raises, and fails that test).
"""

from studyapp.errors import ParameterError
from studyapp.estimators import bdiff, complementary, foaw, hybrids, kalman, kinds, leastsq, levant, lowpass, lvt

REGISTRY = (
    (bdiff.SPEC, bdiff.step),
    (lowpass.SPEC, lowpass.step),
    (leastsq.SPEC, leastsq.step),
    (foaw.SPEC, foaw.step),
    (levant.SPEC_LEVANT, levant.step_levant),
    (levant.SPEC_LEVANTLP, levant.step_levantlp),
    (kalman.SPEC_KALPOS, kalman.step_kalpos),
    (kalman.SPEC_KALMAN, kalman.step_kalman),
    (hybrids.SPEC_KALLEV, hybrids.step_kallev),
    (hybrids.SPEC_KALLEVACC, hybrids.step_kallevacc),
    (hybrids.SPEC_KALFOAW, hybrids.step_kalfoaw),
    (hybrids.SPEC_KALFOAWACC, hybrids.step_kalfoawacc),
    (complementary.SPEC_COMP1, complementary.step),
    (complementary.SPEC_COMP2, complementary.step),
    (lvt.SPEC, lvt.step),
)
SPECS = {spec.name: spec for spec, _ in REGISTRY}
KERNELS = {spec.name: step for spec, step in REGISTRY}


def _check_ids():
    """Each spec's kind is its position here and the constant of its name in kinds.py."""
    for position, (spec, _) in enumerate(REGISTRY):
        if not spec.kind == position == getattr(kinds, spec.name, None):
            raise RuntimeError(f"estimator {spec.name}: kind {spec.kind}, position {position}, "
                               f"kinds.{spec.name} = {getattr(kinds, spec.name, None)}: all three must be equal")
    if len(SPECS) != len(REGISTRY):
        raise RuntimeError("two estimators share a name in the registry")


_check_ids()


def spec(name):
    try:
        return SPECS[name]
    except KeyError:
        raise ParameterError(f"unknown estimator {name!r}: allowed are {', '.join(SPECS)}") from None
