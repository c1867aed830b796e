"""The velocity estimators of the paper (Sec. 5, Tables 1-2), plus BDIFF and LVT.

    names()                      -> list of estimator names
    describe(name)               -> parameters (default, unit, allowed range) and inputs
    create(name, rate, **params) -> Estimator with process(position, acceleration=None,
                                    velocity=None) and reset()
    Bank(rate, names)            -> several estimators on one stream

Every estimator has a compiled streaming form (``dispatch.step_guarded``) and
a block form (``Estimator.process``) whose output equals per-sample stepping
exactly. Units are SI; the sample rate (1 kHz to 96 kHz) is a parameter.
"""

from studyapp.estimators.estimator import Bank, Estimator
from studyapp.estimators.registry import SPECS, spec


def names():
    """The estimator names, in the paper's order (Table 2) with BDIFF first and LVT last."""
    return list(SPECS)


def describe(name):
    """A dict: name, description, inputs, and for each parameter its default, unit and allowed range."""
    return spec(name).describe()


def create(name, rate, **params):
    """A new ``Estimator`` ``name`` at ``rate`` Hz with ``params`` over Table 1's defaults."""
    return Estimator(name, rate, **params)


__all__ = ["Bank", "Estimator", "create", "describe", "names"]
