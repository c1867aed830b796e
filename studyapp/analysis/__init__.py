"""Analysis and reporting of study responses (paper Sec. 9-10).

    responses.load_responses(path)        -> (checked DataFrame, label): a responses .csv or a results folder
    study.analyse(responses, ...)         -> StudyAnalysis: summaries, pairwise Wilcoxon rank-sum tests,
                                             compact letters, missing trials, consistency, numerical comparison
    report_folder.write_report_folder(...) writes the CSV tables, Figs. 7-9 (PNG, SVG) and report.html
    report_folder.open_study(path)        -> StudyAnalysis of a report folder, results folder or .csv

The statistical tests themselves live in studyapp.stats (shared with the
numerical evaluation); rank_sum, summary and consistency here apply them to the
study's responses as plain functions on DataFrames; figures.py draws on matplotlib Figures
without pyplot, so the GUI shows the report's own figures.
"""
