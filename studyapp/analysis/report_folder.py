"""Write a ``StudyAnalysis`` to a report folder: tables (CSV), figures (PNG, SVG), report.html.

Names are fixed, so scripts and the GUI find them:

    wilcoxon_adjustment.csv, wilcoxon_rating.csv   condition_a, condition_b, statistic, p_value, significant
                                                   (rank-sum, trials pooled across participants, as the paper)
    friedman.csv                                   task, statistic, p_value, n_participants
    signed_rank_adjustment.csv, signed_rank_rating.csv
                                                   condition_a, condition_b, statistic, p_value, p_holm,
                                                   effect_size, significant (within-subject)
    summary_adjustment.csv, summary_rating.csv     condition, n, median, q1, q3 (best first)
    spearman_participants.csv                      participant, rho, p_value
    variance_adjustment.csv                        intra- and inter-subject variance per condition
    missing_trials.csv                             participant, task, condition, expected, present, missing_trials
    spearman_numerical.csv                         only with an evaluation
    perceptual_correlation.csv                     only with an evaluation: noisiness against audio_distance
    responses_analysed.csv                         the checked responses the numbers come from
    analysis_settings.json                         source, Holm, alpha, expected trials, evaluation, which
                                                   rows were kept (include_practice, include_simulated),
                                                   pooled_letters, and under "tests" the test behind each table
    fig7_adjustment, fig8_rating, fig9_scatter     .png and .svg
    report.html                                    everything above in one file

Each file is written atomically; report.html comes last, so its presence
means the folder is complete. ``open_study`` reads a report folder back (its
responses and settings give the same figures), or analyses a results folder or
a responses .csv with the defaults: what the GUI's analysis view shows.
"""

import json
from pathlib import Path

import pandas as pd

from studyapp.analysis.consistency import SPEARMAN_COLUMNS
from studyapp.analysis.figures import FIGURES, render, save_figure
from studyapp.analysis.numerical import load_evaluation
from studyapp.analysis.perceptual import PERCEPTUAL_COLUMNS
from studyapp.analysis.rank_sum import POOLED, WILCOXON_COLUMNS
from studyapp.analysis.report import report_html
from studyapp.analysis.responses import load_responses
from studyapp.analysis.study import analyse
from studyapp.analysis.summary import SUMMARY_COLUMNS
from studyapp.analysis.within_subject import FRIEDMAN_COLUMNS, SIGNED_RANK_COLUMNS
from studyapp.io.atomic import atomic_open
from studyapp.errors import InputDataError, UserError
from studyapp.io.small_files import read_json

RESPONSES_FILE = "responses_analysed.csv"
SETTINGS_FILE = "analysis_settings.json"
REPORT_FILE = "report.html"
TESTS = {
    "wilcoxon_{task}.csv": f"Wilcoxon rank-sum test of every pair of conditions, {POOLED}",
    "friedman.csv": "Friedman test across conditions on per-participant medians (within-subject)",
    "signed_rank_{task}.csv": "Wilcoxon signed-rank test of every pair of conditions on per-participant "
    "medians (within-subject, zero differences dropped), Holm-corrected; effect size: matched-pairs "
    "rank-biserial correlation (Kerby 2014)",
}


def open_study(path, include_simulated=False):
    """``StudyAnalysis`` of a report folder, a results folder or a responses .csv at ``path``.

    ``include_simulated`` applies to a results folder or .csv; a report folder keeps its own settings.
    """
    path = Path(path)
    settings_path = path / SETTINGS_FILE
    if not (path.is_dir() and (path / RESPONSES_FILE).is_file() and settings_path.is_file()):
        responses, label = load_responses(path, include_simulated=include_simulated)
        return analyse(responses, source=label, include_simulated=include_simulated)
    try:
        settings = read_json(settings_path, "analysis settings file")
        source, holm, alpha = str(settings["source"]), bool(settings["holm"]), float(settings["alpha"])
        expected, evaluation = settings.get("expected"), settings.get("evaluation")
        # what the analysed responses kept (older folders: the defaults)
        kept = {key: bool(settings.get(key, False)) for key in ("include_practice", "include_simulated")}
        pooled_letters = bool(settings.get("pooled_letters", False))
    except (UserError, KeyError, TypeError, ValueError) as exc:
        raise InputDataError(f"{settings_path}: not a valid analysis settings file ({exc})") from None
    responses, _ = load_responses(path / RESPONSES_FILE, **kept)
    evaluation = load_evaluation(evaluation) if evaluation and Path(evaluation).exists() else None
    return analyse(responses, source=source, evaluation=evaluation, holm=holm, alpha=alpha, expected=expected,
                   pooled_letters=pooled_letters, include_simulated=kept["include_simulated"])


def write_report_folder(study, directory, progress=None, evaluation_path=None, expected=None):
    """Write every output of ``study`` into ``directory``; returns the paths written.

    ``evaluation_path`` and ``expected`` (the analysis inputs besides the
    responses) are recorded in the settings file for ``open_study``.

    ``progress`` is called with a short message before each step (or None).
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda message: None)
    written = []

    def table(name, frame, columns=None):
        path = directory / name
        with atomic_open(path, "w", newline="", encoding="utf-8") as f:
            (frame if columns is None else frame[columns]).to_csv(f, index=False)
        written.append(path)

    say("writing tables")
    for task in (study.adjustment, study.rating):
        table(f"wilcoxon_{task.task}.csv", task.wilcoxon, WILCOXON_COLUMNS)
        table(f"signed_rank_{task.task}.csv", task.within.signed_rank, SIGNED_RANK_COLUMNS)
        table(f"summary_{task.task}.csv", task.summary, SUMMARY_COLUMNS)
    table("friedman.csv", study.friedman(), FRIEDMAN_COLUMNS)
    table("spearman_participants.csv", study.participant_spearman, SPEARMAN_COLUMNS)
    table("variance_adjustment.csv", study.variance)
    table("missing_trials.csv", study.missing)
    if study.numerical is not None:
        table("spearman_numerical.csv", study.numerical)
        table("perceptual_correlation.csv", study.perceptual, PERCEPTUAL_COLUMNS)
    table(RESPONSES_FILE, study.responses)
    settings = {
        "source": study.source,
        "holm": study.holm,
        "alpha": study.alpha,
        "pooled_letters": study.pooled_letters,
        "include_simulated": study.include_simulated,
        "include_practice": bool(study.responses.get("practice", pd.Series(dtype=bool)).astype(bool).any()),
        "expected": expected,
        "evaluation": None if evaluation_path is None else str(Path(evaluation_path).resolve()),
        "tests": {
            name.format(task=task): text
            for name, text in TESTS.items()
            for task in ("adjustment", "rating")
        },
    }
    path = directory / SETTINGS_FILE
    with atomic_open(path, "w", encoding="utf-8") as f:
        json.dump(settings, f, indent=2)
    written.append(path)

    pngs = {}
    for name in FIGURES:
        say(f"drawing {name}")
        figure = render(name, study)
        written += save_figure(figure, directory, name)
        pngs[name] = (directory / f"{name}.png").read_bytes()

    say("writing report.html")
    path = directory / REPORT_FILE
    with atomic_open(path, "w", encoding="utf-8") as f:
        f.write(report_html(study, pngs))
    written.append(path)
    return written
