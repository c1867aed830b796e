"""Which estimators to run, with which parameters: from PARAMS.toml, --estimators, or Table 1.

Without a parameter file the paper's thirteen estimators run with their
defaults (the paper's Table 1); with ``for_rate`` Table 1 is made for the
rate as breakdown and tradeoff make it (``estimators/at_rate.py``: counts in
samples keep their duration; at Table 1's 5 kHz nothing changes): ``evaluate``
runs it so, and sets it beside a tuned file with ``--compare-paper``. With one, its estimators run with its values;
``--estimators`` picks a subset (or adds estimators, with their defaults).
Every value is checked against the estimator's spec here, so a bad file fails
before any work with one line naming the file, table and parameter.

A value that is allowed at some rate but not at this one (a cut-off above
``NYQUIST_FRACTION * rate``, e.g. Table 1's COMP2 high-pass at 2,254 Hz below
4.6 kHz) means the estimator cannot exist at this rate; with an
``unavailable`` dict it is recorded there with the reason and left out, so the
caller can report it and go on.
"""

from studyapp.errors import ParameterError, UserError
from studyapp.estimators.at_rate import table1
from studyapp.estimators.registry import spec
from studyapp.evaluation import params_file
from studyapp.evaluation.dataset import estimator_names
from studyapp.evaluation.space import PAPER_ESTIMATORS


def parameter_sets(params_path=None, estimators=None, rate=None, unavailable=None, for_rate=False):
    """name -> parameters (validated at ``rate``), and the file's provenance (or {}).

    ``for_rate``: without a file, Table 1 made for ``rate`` (``at_rate.table1``), not its values as printed.
    ``unavailable``: a dict to receive name -> reason for the estimators whose
    parameters cannot exist at ``rate`` (else those raise like any bad value).
    """
    loaded, provenance = ({}, {}) if params_path is None else params_file.read(params_path)
    default = list(loaded) if loaded else PAPER_ESTIMATORS
    names = estimator_names(estimators, default)
    at = rate if rate is not None else 5000.0
    chosen = {}
    for name in names:
        given = table1(name, at) if for_rate and params_path is None else loaded.get(name, {})
        where = f"{params_path}: [{name}] " if params_path is not None else ""
        try:
            reason = None if unavailable is None else spec(name).not_available(at, given)
            if reason is not None:
                unavailable[name] = where + reason
                continue
            _, chosen[name] = spec(name).validate(at, given)
        except ParameterError as exc:
            raise UserError(f"{where}{exc}") from None
    if not chosen:
        if unavailable:
            raise UserError("no estimator is available: " + "; ".join(unavailable.values()))
        raise UserError(f"{params_path}: holds no estimator table")
    return chosen, provenance
