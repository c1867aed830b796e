"""The live package's structure: one sender of commands, transitions that are functions, no copy of the states."""

import ast
from pathlib import Path

import studyapp.live
from studyapp.live.states import ACTIVE, REST, TRANSITIONS, State

LIVE = Path(studyapp.live.__file__).parent
SENDERS = {"apparatus.py", "engine_loop.py"}  # the apparatus, and the trial's loop it makes


def sends(path):
    """Lines of ``path`` that call ``<something>.engine.send`` or ``engine.send``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "send":
            target = node.func.value
            name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
            if name == "engine":
                found.append(node.lineno)
    return found


def test_only_the_apparatus_and_its_loop_send_commands_to_the_worker():
    assert sends(LIVE / "apparatus.py") and sends(LIVE / "engine_loop.py")
    elsewhere = {path.name: sends(path) for path in LIVE.glob("*.py") if path.name not in SENDERS}
    assert {name: lines for name, lines in elsewhere.items() if lines} == {}


def test_every_transition_is_a_function_of_the_controller():
    assert all(callable(transition) for transition in TRANSITIONS.values())


def test_the_active_states_are_the_states_that_are_not_rest():
    assert set(ACTIVE) | set(REST) == set(State) and not set(ACTIVE) & set(REST)
    assert not any(isinstance(node, ast.Constant) and node.value == "engine_lost"
                   for node in ast.walk(ast.parse((LIVE / "simulated_session.py").read_text())))
