"""Generated bad input of the families of issue 32, so that new cases of the same kinds hold.

tests/test_bad_input.py has the named cases; these draw (hypothesis) from the same families:

- paths: a session folder, a link to it, ``..`` and ``.`` through it, trailing slashes, FIFOs,
  devices, sockets, folders, inputs: every spelling that lands in a session folder, names a folder
  or a special file is refused as an output (``-o``, ``--audio wav:``), and nothing is written;
- values: JSON nested to any depth (an events.jsonl line, a session.json, a recording's metadata),
  files huge or sparse, archives that unpack to far more than they hold, bad numbers (a recording's
  rate, a protocol's ``break_every`` and F_max): refused with one ``UserError`` naming the file or
  field, never another exception, never a hang (``signal.alarm`` turns one into a failure).
"""

import contextlib
import io
import json
import math
import os
import socket
import warnings
import zipfile
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studyapp.cli import main, output_paths
from studyapp.errors import InputDataError, UserError
from studyapp.io import archive_bounds, bounded_json
from tests.test_bad_input import PROTOCOL, RATE, _npz, _results, _session_of, _signal, no_hang

SETTINGS = settings(max_examples=25, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])

@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """A results folder with one session, a link to it, a FIFO, a socket, an input and an output folder."""
    d = tmp_path_factory.mktemp("world")
    _results(d / "results")
    session = _session_of(d / "results")
    (session / "audio.wav").write_bytes(b"RIFF....WAVE")
    (d / "link").symlink_to(session)
    os.mkfifo(d / "fifo")
    os.mkfifo(d / "fifo.wav")
    server = socket.socket(socket.AF_UNIX)
    server.bind(str(d / "socket.wav"))
    (d / "in").mkdir()
    (d / "in" / "input.csv").write_text("position\n0.1\n")
    (d / "out").mkdir()
    yield d, session
    server.close()


def _snapshot(folder):
    """Every name under ``folder`` and the bytes of its files (what a refused command must leave as it was)."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() and not p.is_symlink() else None)
            for p in sorted(Path(folder).rglob("*")) if not (p.is_fifo() or p.is_socket())}


def _participant_data(world):
    d, session = world
    return _snapshot(session), (session.parent / ".lock").read_bytes()


BASES = ["{session}", "{link}", "{results}", "{session}/..", "{out}", "{in}", "{in}/input.csv", "{fifo}",
         "{world}/fifo.wav", "{world}/socket.wav", "/dev/null", "/dev/zero"]
TAILS = ["", "/", "/.", "/..", "/x.csv", "/x.wav", "/new/x.csv", "/./x.wav", "/../{name}/x.wav", "//x.csv",
         "/audio.wav", "/events.jsonl", "/session.json", "/x.wav/", "/../{name}/new/x.wav"]
path_spellings = st.tuples(st.sampled_from(BASES), st.sampled_from(TAILS), st.booleans())


def _spell(world, spelling):
    d, session = world
    base, tail, relative = spelling
    text = base + tail
    for key, value in (("{session}", session), ("{link}", d / "link"), ("{results}", d / "results"),
                       ("{out}", d / "out"), ("{in}", d / "in"), ("{fifo}", d / "fifo"), ("{world}", d),
                       ("{name}", session.name)):
        text = text.replace(key, str(value))
    return os.path.relpath(text, d / "out") + ("/" if text.endswith("/") else "") if relative and \
        text.startswith(str(d)) else text


def _lands_in_session(text, cwd):
    """True when a file written at ``text`` (from ``cwd``) would be in a session folder, by the file system."""
    parent = Path(os.path.realpath(os.path.join(cwd, os.path.dirname(text.rstrip("/")) or ".")))
    return any((p / "events.jsonl").exists() for p in [parent, *parent.parents])


def _must_refuse(text, cwd):
    target = os.path.join(cwd, text)
    special = os.path.exists(target) and not (os.path.isfile(target) or os.path.isdir(target))
    return (_lands_in_session(text, cwd) or text.endswith(("/", "/.", "/..")) or os.path.isdir(target)
            or special)


@SETTINGS
@given(path_spellings, st.booleans())
def test_an_output_path_into_a_session_a_folder_or_a_special_file_is_refused(world, monkeypatch, spelling, wav):
    d, session = world
    monkeypatch.chdir(d / "out")
    text = _spell(world, spelling)
    before = _snapshot(d)
    try:
        with no_hang():
            if wav:
                output_paths.check_audio(f"wav:{text}")
            else:
                output_paths.check_file(text)
        refused = False
    except UserError:
        refused = True
    assert _snapshot(d) == before
    if _must_refuse(text, d / "out") or (wav and not text.lower().endswith(".wav")):
        assert refused, text


@settings(SETTINGS, max_examples=15)
@given(path_spellings)
def test_notes_o_writes_outside_session_folders_or_refuses_in_one_line(world, monkeypatch, capsys, spelling):
    d, session = world
    monkeypatch.chdir(d / "out")
    text = _spell(world, spelling)
    before = _participant_data(world)
    with no_hang():
        code = main(["notes", str(d / "results"), "-o", text])
    err = capsys.readouterr().err
    assert "Traceback" not in err and code in (0, 2), err
    assert _participant_data(world) == before
    if code == 2:
        assert len(err.strip().splitlines()) == 1, err
    else:
        assert not _must_refuse(text, d / "out"), text
        os.unlink(os.path.join(d / "out", text))


# ---- nested JSON ---------------------------------------------------------------------------------------

@st.composite
def nested_json(draw):
    """(text, depth): brackets nested ``depth`` deep, with strings holding brackets and escapes on the way."""
    depth = draw(st.one_of(st.integers(1, 80), st.integers(60, 70), st.integers(80, 20_000)))
    pattern = draw(st.lists(st.sampled_from(["[", "{"]), min_size=1, max_size=8))
    kinds = [pattern[i % len(pattern)] for i in range(depth)]
    noise = draw(st.sampled_from(['', '"[[{\\"", ', '"]]}}", ', '"\\\\", ']))
    opened, closed = [], []
    for kind in kinds:
        opened.append(f'{{"k": ' if kind == "{" else f"[{noise}")
        closed.append("}" if kind == "{" else "]")
    return "".join(opened) + "1" + "".join(reversed(closed)), depth


@SETTINGS
@given(nested_json())
def test_json_nested_beyond_the_bound_is_refused_and_within_it_parsed_as_json_does(case):
    text, depth = case
    if depth > bounded_json.MAX_DEPTH:
        with pytest.raises(bounded_json.NestedTooDeeply):
            bounded_json.loads(text)
    else:
        assert bounded_json.loads(text) == json.loads(text)


@settings(SETTINGS, max_examples=15)
@given(nested_json(), st.sampled_from(["events", "session", "meta"]))
def test_nested_json_in_a_log_line_a_session_json_or_metadata_is_damage(world, tmp_path_factory, case, where):
    from studyapp.experiment.log_scan import scan
    from studyapp.experiment.session_description import read_description
    from studyapp.io.recording import parse_meta

    d, session = world
    text, _ = case
    with no_hang():
        if where == "events":
            log = scan((session / "events.jsonl").read_bytes() + text.encode() + b"\n")
            assert log.events  # the good lines are kept
        elif where == "meta":
            with contextlib.suppress(InputDataError):
                assert isinstance(parse_meta(text, "rec.npz"), dict)
        else:
            copy = tmp_path_factory.mktemp("session")
            (copy / "events.jsonl").write_bytes((session / "events.jsonl").read_bytes())
            (copy / "session.json").write_text(text)
            info, notes = read_description(copy)  # rebuilt from the log's session_created event
            assert info["participant"] == "p1" and notes


# ---- huge and sparse files -----------------------------------------------------------------------------

READERS = {
    "csv": lambda p: __import__("studyapp.io.sample_table", fromlist=["x"]).SampleTable(p).close(),
    "npz-blocks": lambda p: __import__("studyapp.io.recording_blocks", fromlist=["x"]).RecordingBlocks(p).close(),
    "npz-load": lambda p: __import__("studyapp.io.recording", fromlist=["x"]).load(p),
    "csv-load": lambda p: __import__("studyapp.io.recording", fromlist=["x"]).load(p),
    "log": lambda p: __import__("studyapp.experiment.log_scan", fromlist=["x"]).read_log(p),
    "protocol": lambda p: __import__("studyapp.experiment.protocol", fromlist=["x"]).load_protocol(p),
    "json": lambda p: __import__("studyapp.io.small_files", fromlist=["x"]).read_json(p, "checkpoint"),
}
SUFFIX = {"csv": ".csv", "npz-blocks": ".npz", "npz-load": ".npz", "csv-load": ".csv", "log": ".jsonl",
          "protocol": ".toml", "json": ".json"}


@settings(SETTINGS, max_examples=20)
@given(st.sampled_from(list(READERS)), st.integers((1 << 20) + 1, 1 << 36),
       st.sampled_from([b"", b"position\n0.1\n", b"PK\x03\x04", b'{"a": [', b"\x00" * 100]))
def test_a_sparse_file_is_refused_before_it_is_read(tmp_path_factory, reader, length, head):
    path = tmp_path_factory.mktemp("sparse") / f"x{SUFFIX[reader]}"
    with open(path, "wb") as f:
        f.write(head)
        f.truncate(length)
    with no_hang(), pytest.raises(UserError, match="sparse|larger than"):
        READERS[reader](path)
    path.unlink()


@settings(SETTINGS, max_examples=10)
@given(st.integers(65_537, 400_000), st.sampled_from([b"a", b"1", b"\x00", b","]))
def test_a_csv_line_without_end_is_refused_not_read_whole(tmp_path_factory, length, fill):
    from studyapp.io.sample_table import SampleTable

    path = tmp_path_factory.mktemp("line") / "x.csv"
    path.write_bytes(b"position\n" + fill * length)
    with no_hang(), pytest.raises(UserError):
        with SampleTable(path) as table:
            for _ in table.blocks(1024, ["position"]):
                pass


# ---- archives that unpack to more than they hold -------------------------------------------------------

@st.composite
def archives(draw):
    """An .npz's bytes: members of zeros or noise, packed or stored, headers true or claiming more, any dtype."""
    n = draw(st.integers(1, 400_000))
    dtype = draw(st.sampled_from(["<f8", "<i4", "|b1", "<c16", "<U3", "<f4"]))
    claim = draw(st.sampled_from([1, 1, 2, 1000]))
    zeros = draw(st.booleans())
    packed = draw(st.booleans())
    twice = draw(st.booleans()) and draw(st.booleans())
    rate = draw(st.sampled_from([RATE, 1e9, True, "abc", None]))
    values = np.zeros(n, dtype=dtype) if zeros else np.random.default_rng(n).integers(0, 9, n).astype(dtype)
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": np.dtype(dtype).str, "fortran_order": False,
                                                  "shape": (n * claim,)})
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED if packed else zipfile.ZIP_STORED) as z:
        meta = io.BytesIO()
        np.save(meta, np.array(json.dumps({} if rate is None else {"rate": rate})))
        z.writestr("__meta__.npy", meta.getvalue())
        for name in ["position", "velocity_lvt"] + (["position"] if twice else []):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # zipfile's "Duplicate name": the point of ``twice``
                z.writestr(f"{name}.npy", header.getvalue() + values.tobytes())
    return buffer.getvalue(), n * claim * np.dtype(dtype).itemsize


@settings(SETTINGS, max_examples=30)
@given(archives(), st.sampled_from(["load", "blocks"]))
def test_an_archive_is_read_or_refused_from_its_directory(tmp_path_factory, case, how):
    from studyapp.io.recording import load
    from studyapp.io.recording_blocks import RecordingBlocks

    data, _ = case
    path = tmp_path_factory.mktemp("npz") / "x.npz"
    path.write_bytes(data)
    with zipfile.ZipFile(path) as z:
        infos = z.infolist()
    bomb = any(i.file_size > (1 << 16) and i.file_size > archive_bounds.RATIO_MAX * max(i.compress_size, 1)
               for i in infos)
    with no_hang(), mock.patch.object(archive_bounds, "BOMB_MIN_BYTES", 1 << 16), warnings.catch_warnings():
        warnings.simplefilter("error")  # a ComplexWarning, a duplicate name: refused, not warned about
        try:
            if how == "load":
                load(path)
            else:
                with RecordingBlocks(path) as rec:
                    for _ in rec.blocks(1 << 16):
                        pass
        except UserError as exc:
            assert str(path) in str(exc)
        else:
            assert not bomb


# ---- bad numbers ---------------------------------------------------------------------------------------

rates = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**30, 10**30), st.booleans(),
                  st.text(max_size=8), st.lists(st.integers(), max_size=2), st.sampled_from([1e9, 500, 1e-300]))


@settings(SETTINGS, max_examples=40)
@given(rates)
def test_a_recordings_rate_is_in_range_or_refused_naming_the_file(tmp_path_factory, rate):
    from studyapp.cli.estimate import _Input
    from studyapp.evaluation.dataset import take_from_recording
    from studyapp.io.recording import load

    path = tmp_path_factory.mktemp("rate") / "rec.npz"
    _npz(path, {k: v[:200] for k, v in _signal().items()}, {"rate": rate})
    for read in (lambda: take_from_recording(load(path), str(path)).rate, lambda: _Input(str(path), None).rate):
        try:
            value = read()
        except UserError as exc:
            assert str(path) in str(exc)
        else:
            assert 1000 <= value <= 96000 and not isinstance(rate, bool)


@settings(SETTINGS, max_examples=40)
@given(st.one_of(st.none(), st.integers(-3, 2000)), st.one_of(st.floats(-1, 3), st.just(math.nan)),
       st.one_of(st.floats(-1, 80), st.just(math.nan)))
def test_an_accepted_protocol_breaks_and_is_heard(break_every, fmax, ceiling):
    from studyapp.experiment.audible_fmax import FMAX_AUDIBLE
    from studyapp.experiment.protocol import parse_protocol

    text = Path(PROTOCOL).read_text()
    text = text.replace("break_every = 2", "" if break_every is None else f"break_every = {break_every}")
    text = text.replace("fmax = 1.0", f"fmax = {fmax!r}").replace(
        "ceiling = 40.0", f"ceiling = {ceiling!r}")
    try:
        protocol = parse_protocol(text, "p.toml")
    except UserError as exc:
        assert "p.toml" in str(exc)
        return
    assert protocol.specs["rating"].fmax >= FMAX_AUDIBLE and protocol.specs["adjustment"].ceiling >= FMAX_AUDIBLE
    assert protocol.specs["adjustment"].break_every >= 1 or break_every is None
    assert math.isfinite(protocol.specs["rating"].fmax)


# ---- special files as inputs ---------------------------------------------------------------------------

def _special(kind, folder, suffix):
    path = folder / f"special{suffix}"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "socket":
        server = socket.socket(socket.AF_UNIX)
        server.bind(str(path))
        server.close()
    elif kind == "folder":
        path.mkdir()
    else:
        path.symlink_to(kind)  # a device, through a link
    return path


INPUT_COMMANDS = {
    "estimate-csv": (".csv", ["estimate", "{p}", "--estimator", "LOWPASS", "--rate", "5000", "-o", "{out}/e.csv"]),
    "estimate-npz": (".npz", ["estimate", "{p}", "--estimator", "LOWPASS", "-o", "{out}/e.csv"]),
    "evaluate": (".npz", ["evaluate", "{p}"]),
    "evaluate-params": (".toml", ["evaluate", "{rec}", "--params", "{p}"]),
    "run-protocol": (".toml", ["run", "--participant", "p9", "--simulated-participant", "--headless", "--results",
                               "{out}/r", "--protocol", "{p}"]),
    "analyse-csv": (".csv", ["analyse", "{p}", "-o", "{out}/rep"]),
    "plan-protocol": (".toml", ["plan", "--participant", "p9", "--protocol", "{p}"]),
}


@settings(SETTINGS, max_examples=20)
@given(st.sampled_from(list(INPUT_COMMANDS)), st.sampled_from(["fifo", "socket", "folder", "/dev/zero",
                                                                "/dev/urandom", "/dev/null"]))
def test_a_special_file_as_an_input_is_refused_without_blocking(tmp_path_factory, capsys, command, kind):
    from tests.test_bad_input import _recording

    folder = tmp_path_factory.mktemp("special")
    suffix, template = INPUT_COMMANDS[command]
    path = _special(kind, folder, suffix)
    (folder / "out").mkdir()
    _recording(folder / "rec.npz")
    argv = [a.format(p=path, out=folder / "out", rec=folder / "rec.npz") for a in template]
    with no_hang():
        code = main(argv)
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert not any((folder / "out").iterdir())
