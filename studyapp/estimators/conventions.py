"""The conventions that give Table 1's numbers their meaning, recorded beside every parameter set.

A parameter value means a filter only under a convention: Table 1's KALPOS
q = 0.191 is a good filter with continuous white noise and a 39-sample lag
with eq. 19 as printed; FOAW's size 17 is a line fitted to 17 samples, not 18;
LEVANT's observer starts at 0 or at the first sample. Each estimator's
defaults are the conventions the authors' code had (the one its Table 1 value
was tuned in), and every output that carries parameters records them
(PARAMS.toml's ``[conventions]``, ``evaluation.json``'s and
``tradeoff.json``'s ``conventions``, ``session.json``'s ``conventions``).

An estimator's conventions are

- its choice parameters, whose value selects the convention
  (``q_convention`` of the Kalman filters, ``start`` of the Levant
  observers), and
- fixed meanings of a parameter, declared in its spec's
  ``extra["conventions"]`` (FOAW's ``window`` = ``"size"``, the paper's Size).

``of(name, params)`` gives them as ``{parameter: convention}``, ``text``
as one line with what each means, ``record`` for a whole parameter set.
"""

from studyapp.estimators.registry import spec as lookup

MEANINGS = {
    "q_convention": {
        "eq19": "Q = q Gamma Gamma^T (the paper's eq. 19 as printed)",
        "scaled": "Q = q T Gamma Gamma^T (the authors' third-order filters)",
        "continuous": "continuous white noise of spectral density q, Q = q [[T^3/3, T^2/2], [T^2/2, T]] "
                      "for [x, v] (the authors' KALPOS)",
    },
    "start": {
        "zero": "the observer starts at w = 0, u1 = 0 (the authors')",
        "first": "the observer starts at the first position, u1 = 0",
    },
    "window": {
        "size": "the most samples a line is fitted to, the newest included (the paper's Size)",
    },
}


def of(name, params):
    """``{parameter: convention}`` of estimator ``name`` run with ``params`` (a parameter not given: its default)."""
    spec = lookup(name)
    out = {p.name: params.get(p.name, p.default) for p in spec.params if p.kind == "choice"}
    out.update(spec.extra.get("conventions", {}))
    return dict(sorted(out.items()))


def text(name, params):
    """One line: each convention of ``name`` and what it means; empty when it has none."""
    return "; ".join(f"{key} = {value}: {MEANINGS[key][value]}" for key, value in of(name, params).items())


def record(params):
    """``{name: {parameter: convention}}`` for a parameter set ``{name: params}``, estimators without conventions left out."""
    out = {name: of(name, values) for name, values in params.items()}
    return {name: conventions for name, conventions in out.items() if conventions}
