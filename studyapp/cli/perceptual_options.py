"""The options shared by ``evaluate --perceptual`` and ``optimise --objective perceptual`` (paper Sec. 10).

Both simulate the same cases (studyapp.evaluation.perceptual_scores.Cases):
``--perceptual-fmax``, ``--perceptual-seeds``, ``--perceptual-duration``.
``evaluate --perceptual`` also adds ``audio_distance`` per estimator to its
JSON, writes perceptual.csv and draws perceptual.png (``add_to_evaluation``,
``write_outputs``).
"""

# The defaults of studyapp.evaluation.perceptual_scores, repeated for --help (argparse only at start-up).
HELP_DEFAULTS = {"fmax": "1 2.2 4.4 7.7", "seeds": "0 1", "duration": "2"}
OPTIONS = {"fmax": "--perceptual-fmax", "seed": "--perceptual-seeds", "seeds": "--perceptual-seeds",
           "duration": "--perceptual-duration", "rate": "--rate"}


def add_options(parser, enabled_by):
    group = parser.add_argument_group(f"perceptual cases (with {enabled_by})")
    group.add_argument("--perceptual-fmax", nargs="+", type=float, metavar="N",
                       help=f"F_max values simulated, N (default {HELP_DEFAULTS['fmax']})")
    group.add_argument("--perceptual-seeds", nargs="+", type=int, metavar="SEED",
                       help=f"simulation seeds, each with every F_max (default {HELP_DEFAULTS['seeds']})")
    group.add_argument("--perceptual-duration", type=float, metavar="SECONDS",
                       help=f"length of each simulation (default {HELP_DEFAULTS['duration']} s)")


def cases(args, rate, enabled, enabled_by):
    """The ``Cases`` the options ask for, or None when not ``enabled`` (then no option may be given)."""
    from studyapp.errors import ParameterError, UserError
    from studyapp.evaluation import perceptual_scores as ps

    given = {"fmax": args.perceptual_fmax, "seeds": args.perceptual_seeds, "duration": args.perceptual_duration}
    if not enabled:
        for key, value in given.items():
            if value is not None:
                raise UserError(f"--perceptual-{key}: only with {enabled_by}")
        return None
    try:
        return ps.Cases(
            rate,
            tuple(ps.DEFAULT_FMAX if given["fmax"] is None else given["fmax"]),
            tuple(ps.DEFAULT_SEEDS if given["seeds"] is None else given["seeds"]),
            ps.DEFAULT_DURATION if given["duration"] is None else given["duration"],
        )
    except ParameterError as exc:
        field = str(exc).split(" ", 1)[0].rstrip(":")
        raise UserError(f"{OPTIONS.get(field, 'perceptual')}: {exc}") from None


def progress_line(command):
    import sys

    def report(done, total, name):
        if name is not None:
            print(f"{command}: perceptual: {name} ({done + 1}/{total})", file=sys.stderr, flush=True)

    return report


def distance_progress(progress, optimiser):
    """The optimiser's progress with each estimator's best audio distance in place of F_g.

    (With one objective F_g only says where an estimator stands between the best and the worst.)
    """

    def report(iteration, evaluated, objectives, done, final=False, waiting=None):
        distances = {name: float(optimiser.sum.best[name][0]) for name in objectives}
        progress(iteration, evaluated, distances, done, final=final, waiting=waiting)

    return report


def add_to_evaluation(cases, result, document):
    """Score every evaluated estimator; add ``audio_distance`` and a ``perceptual`` section to ``document``."""
    import numpy as np

    from studyapp.evaluation.perceptual_scores import estimator_score, spearman

    report = progress_line("studyapp evaluate")
    scores = {}
    for i, name in enumerate(result.names):
        report(i, len(result.names), name)
        scores[name] = estimator_score(cases, name, result.params[name])
    distances = {name: s["audio_distance"] for name, s in scores.items()}
    errors = {name: float(np.nanmedian(result.error_pct(name))) if np.isfinite(result.error_pct(name)).any()
              else float("nan") for name in result.names}
    correlation = spearman(distances, errors)
    for name, score in scores.items():
        document["estimators"][name]["audio_distance"] = _number(score["audio_distance"])
    document["perceptual"] = {
        **cases.describe(),
        "distance": "loudness in critical bands, 0 to sqrt(2) (studyapp.evaluation.perceptual)",
        "spearman_error_pct_lowpass": correlation,
        "broken": {name: s["broken"] for name, s in scores.items()},
        "cases": {name: [{**row, "audio_distance": _number(row["audio_distance"])} for row in s["cases"]]
                  for name, s in scores.items()},
    }
    return {"scores": scores, "distances": distances, "errors": errors, "spearman": correlation}


def write_outputs(output, perceptual, names):
    """perceptual.csv (one row per estimator and case) and perceptual.png/.svg."""
    from studyapp.evaluation.perceptual_figure import perceptual_plot
    from studyapp.evaluation.tables import write_csv

    rows = [{"estimator": name, **row} for name in names for row in perceptual["scores"][name]["cases"]]
    write_csv(output / "perceptual.csv", rows, ["estimator", "fmax", "seed", "audio_distance", "broken", "fault"])
    perceptual_plot(names, perceptual["distances"], perceptual["errors"], output / "perceptual",
                    perceptual["spearman"])


def print_table(perceptual, names):
    distances = perceptual["distances"]
    print("audio distance to TRUE in the loop (perceptual, mean over the cases; 0 = same sound):")
    for name in sorted(names, key=lambda n: distances[n]):
        print(f"      {name:<11} {distances[name]:>10.4g}")
    s = perceptual["spearman"]
    if s["rho"] is not None:
        print(f"Spearman rho (audio distance, median error % of LOWPASS) = {s['rho']:.2f} (n = {s['n']}, "
              f"p = {s['p']:.2g})")


def _number(x):
    import math

    x = float(x)
    return x if math.isfinite(x) else None
