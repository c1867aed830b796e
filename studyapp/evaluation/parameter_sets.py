"""Which estimators to run, with which parameters: from PARAMS.toml, --estimators, or Table 1.

Without a parameter file the paper's thirteen estimators run with their
defaults (the paper's Table 1). With one, its estimators run with its values;
``--estimators`` picks a subset (or adds estimators, with their defaults).
Every value is checked against the estimator's spec here, so a bad file fails
before any work with one line naming the file, table and parameter.
"""

from studyapp.errors import ParameterError, UserError
from studyapp.evaluation import params_file
from studyapp.evaluation.dataset import estimator_names
from studyapp.evaluation.space import PAPER_ESTIMATORS


def parameter_sets(params_path=None, estimators=None, rate=None):
    """name -> parameters (validated at ``rate``), and the file's provenance (or {})."""
    from studyapp.estimators.registry import spec

    loaded, provenance = ({}, {}) if params_path is None else params_file.read(params_path)
    default = list(loaded) if loaded else PAPER_ESTIMATORS
    names = estimator_names(estimators, default)
    chosen = {}
    for name in names:
        given = loaded.get(name, {})
        try:
            _, values = spec(name).validate(rate if rate is not None else 5000.0, given)
        except ParameterError as exc:
            where = f"{params_path}: [{name}] " if params_path is not None else ""
            raise UserError(f"{where}{exc}") from None
        chosen[name] = values
    if not chosen:
        raise UserError(f"{params_path}: holds no estimator table")
    return chosen, provenance
