"""scripts/start_latency.py: the protocol without its pages, and one measured run through the real console
(the times are measured, never asserted: only that each was taken and is a finite, positive time)."""

import importlib.util
import math
import tomllib

import pytest

from studyapp.experiment.protocol import load_protocol
from tests.gui.conftest import DEMO, ROOT

pytestmark = pytest.mark.gui


def load_script():
    spec = importlib.util.spec_from_file_location("start_latency", ROOT / "scripts" / "start_latency.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_without_pages_leaves_every_other_table_whole(tmp_path):
    text = DEMO.read_text()
    bare = load_script().without_pages(text)
    original, stripped = tomllib.loads(text), tomllib.loads(bare)
    assert original["pages"] and "pages" not in stripped
    assert stripped == {k: v for k, v in original.items() if k != "pages"}
    path = tmp_path / "bare.toml"
    path.write_text(bare)
    assert load_protocol(path).pages == ()


def test_one_run_times_the_page_and_the_first_sound(qapp, tmp_path):
    script = load_script()
    times = script.one_run(qapp, DEMO, "null", tmp_path / "results", "LAT1")
    assert times["start_to_sound"] is None  # the demo starts with a page
    assert all(math.isfinite(times[k]) and times[k] > 0 for k in ("start_to_page", "ack_to_sound"))
