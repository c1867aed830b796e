"""Write a ``StudyAnalysis`` to a report folder: tables (CSV), figures (PNG, SVG), report.html.

Names are fixed, so scripts and the GUI find them:

    wilcoxon_adjustment.csv, wilcoxon_rating.csv   condition_a, condition_b, statistic, p_value, significant
    summary_adjustment.csv, summary_rating.csv     condition, n, median, q1, q3 (best first)
    spearman_participants.csv                      participant, rho, p_value
    variance_adjustment.csv                        intra- and inter-subject variance per condition
    missing_trials.csv                             participant, task, condition, expected, present, missing_trials
    spearman_numerical.csv                         only with an evaluation
    responses_analysed.csv                         the checked responses the numbers come from
    fig7_adjustment, fig8_rating, fig9_scatter     .png and .svg
    report.html                                    everything above in one file

Each file is written atomically; report.html comes last, so its presence
means the folder is complete.
"""

from pathlib import Path

from studyapp.analysis.consistency import SPEARMAN_COLUMNS
from studyapp.analysis.figures import FIGURES, render, save_figure
from studyapp.analysis.rank_sum import WILCOXON_COLUMNS
from studyapp.analysis.report import report_html
from studyapp.analysis.summary import SUMMARY_COLUMNS
from studyapp.atomic import atomic_open

RESPONSES_FILE = "responses_analysed.csv"
REPORT_FILE = "report.html"


def write_report_folder(study, directory, progress=None):
    """Write every output of ``study`` into ``directory``; returns the paths written.

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
        table(f"summary_{task.task}.csv", task.summary, SUMMARY_COLUMNS)
    table("spearman_participants.csv", study.participant_spearman, SPEARMAN_COLUMNS)
    table("variance_adjustment.csv", study.variance)
    table("missing_trials.csv", study.missing)
    if study.numerical is not None:
        table("spearman_numerical.csv", study.numerical)
    table(RESPONSES_FILE, study.responses)

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
