"""The protocol's F_max ceiling is the worker's hard clamp: sessions, the console's preview and
``live --protocol`` (issue 21, item 9). Before, the engine's ceiling was always 60 N: with a 5 N
protocol the preview applied 20 N at the knob's top."""

from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.engine import commands as cmd
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.live.controller import SessionController
from tests.engine.waiting import wait_for

DEMO = Path(__file__).resolve().parents[2] / "protocols" / "demo.toml"


class RecordingHost:
    """Stands in for ``EngineHost``: keeps the config it was given, runs nothing."""

    configs = []

    def __init__(self, config, describe=""):
        self.configs.append(config)
        self.running = False
        self.engine = None

    def start(self):
        return self

    def stop(self, wait=True):
        pass


def _protocol(tmp_path, ceiling):
    path = tmp_path / "five.toml"
    path.write_text(DEMO.read_text().replace("ceiling = 40.0", f"ceiling = {ceiling}"))
    return path


def test_the_preview_engine_clamps_at_the_protocols_ceiling(tmp_path):
    controller = SessionController(audio="null", midi="none", make_host=RecordingHost)
    controller.load_protocol(_protocol(tmp_path, 5.0))
    config = RecordingHost.configs[-1]
    assert config.safety.fmax_ceiling == 5.0
    engine = Engine(config).start()
    try:
        engine.send(cmd.Control("knob1", 1.0))  # the preview's F_max knob at its top (20 N on its scale)
        wait_for(lambda: engine.status()["fmax"] > 0, timeout=5.0)
        assert engine.status()["fmax"] == pytest.approx(5.0)
        engine.send(cmd.SetFmax(30.0))
        wait_for(lambda: engine.status()["command_latency_max"] > 0, timeout=5.0)
        wait_for(lambda: engine.status()["blocks"] > 10, timeout=5.0)
        assert engine.status()["fmax"] <= 5.0
    finally:
        engine.stop()


def test_live_refuses_an_fmax_above_the_protocols_ceiling_before_starting(tmp_path, capsys):
    code = main(["live", "--audio", "null", "--midi", "none", "--seconds", "0.2", "--fmax", "6",
                 "--protocol", str(_protocol(tmp_path, 5.0))])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "fmax = 6" in err and "5 N" in err


def test_an_engine_refuses_an_fmax_above_its_ceiling():
    from studyapp.engine.safety import SafetyLimits
    from studyapp.errors import ParameterError

    with pytest.raises(ParameterError, match="fmax"):
        Engine(EngineConfig(fmax=6.0, safety=SafetyLimits(fmax_ceiling=5.0)))
