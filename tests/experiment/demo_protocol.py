"""The demo protocol with its trials only (no pages, no practice, no breaks), as it was before them.

The tests of the log, the session, resume and export count lines, steps and
rows of a demo session; they are about those layers, not the participant's
flow (tests/experiment/test_experiment_pages.py), so they run this variant.
"""

from pathlib import Path

DEMO = Path(__file__).resolve().parents[2] / "protocols" / "demo.toml"
PHASE_FIELDS = ("practice", "break_every", "min_listen_s", "bow")


def trials_only(text):
    """``text`` without its ``[[pages]]`` tables and phase fields."""
    kept, in_page = [], False
    for line in text.splitlines(keepends=True):
        if line.startswith("["):
            in_page = line.strip() == "[[pages]]"
        if not in_page and line.split("=")[0].strip() not in PHASE_FIELDS:
            kept.append(line)
    return "".join(kept)


def trials_only_demo(folder):
    """The trials-only demo protocol written to ``folder``/demo.toml; returns its path."""
    path = Path(folder) / "demo.toml"
    path.write_text(trials_only(DEMO.read_text()))
    return path
