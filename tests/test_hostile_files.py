"""Hostile files (issue 22): what a path can point at, and what a scene file can name.

FIFOs, devices and directories given as scene files or CSV files (directly, named in a
scene file, or on the command line) are refused before they are opened: each attempt
runs in a child process with a time limit, since a regression would block on the FIFO.
A scene file cannot make the toolkit read, or quote, files outside its folder. Broken
CSV files, odd path types and a million parameters are clear errors at once.
"""

from __future__ import annotations

import os
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.model.errors import LimitError, SceneError
from laplace_springs.model.sampled import Sampled
from laplace_springs.model.scene_files import scene_from_toml_text
from tests._hostile import attempts

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs need a POSIX system")

SCENE = '[masses]\nm1 = 1\n[springs]\nk = ["wall", "m1", 4]\n'
SECRET = "SECRET-LINE-7f3a"


def _scene_naming(csv: str) -> str:
    return SCENE + f'[forcing]\nm1 = {{ csv = "{csv}", time = "t", value = "F" }}\n'


@pytest.fixture
def folder(tmp_path):
    """A scene folder with a FIFO, a good CSV, a scene file naming the FIFO, and a secret
    file beside the folder."""
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    os.mkfifo(scenes / "pipe.csv")
    os.mkfifo(scenes / "pipe.toml")
    (scenes / "force.csv").write_text("t,F\n0,0\n1,1\n2,0\n")
    (scenes / "via-pipe.toml").write_text(_scene_naming("pipe.csv"))
    (scenes / "sub").mkdir()
    (scenes / "link.toml").symlink_to(scenes / "pipe.toml")
    (tmp_path / "secret.csv").write_text(f"{SECRET},x\n1,2\n")
    (scenes / "escape.csv").symlink_to(tmp_path / "secret.csv")
    return scenes


def test_fifos_devices_and_directories_are_refused_before_reading(folder):
    setup = f"""
import laplace_springs as ls
from laplace_springs.cli import main
folder = {str(folder)!r}
"""
    cases = {
        "FIFO as a scene file": "ls.load_scene(folder + '/pipe.toml')",
        "FIFO as a scene file (Path)": "ls.load_scene(__import__('pathlib').Path(folder) / 'pipe.toml')",
        "symlink to a FIFO": "ls.load_scene(folder + '/link.toml')",
        "FIFO as a CSV file": "ls.sampled_from_csv(folder + '/pipe.csv')",
        "FIFO named in a scene file": "ls.load_scene(folder + '/via-pipe.toml')",
        "FIFO through the CLI": "main(['solve', folder + '/pipe.toml'])",
        "a directory as a scene file": "ls.load_scene(folder + '/sub')",
        "a directory as a CSV file": "ls.sampled_from_csv(folder + '/sub')",
        "a device as a scene file": "ls.load_scene('/dev/zero')",
        "a device as a CSV file": "ls.sampled_from_csv('/dev/zero')",
        "a terminal-like device": "ls.load_scene('/dev/null')",
    }
    found = attempts(setup, cases, timeout=60)
    for name, outcome in found.items():
        if name == "FIFO through the CLI":
            assert outcome.kind == "ok" and outcome.text == "2", (name, outcome)
            continue
        assert outcome.kind == "SceneError", (name, outcome)
        assert "not a regular file" in outcome.text, (name, outcome)
        kind = ("a FIFO" if "FIFO" in name else "a directory" if "directory" in name
                else "a character device")
        assert kind in outcome.text, (name, outcome)


def test_a_scene_file_cannot_name_files_outside_its_folder(folder, tmp_path):
    for csv in (str(tmp_path / "secret.csv"), "../secret.csv", "sub/../../secret.csv", "escape.csv"):
        path = folder / "bad.toml"
        path.write_text(_scene_naming(csv))
        with pytest.raises(SceneError) as caught:
            ls.load_scene(path)
        message = str(caught.value)
        assert "absolute path" in message or "leads out of the scene file's folder" in message, message
        assert SECRET not in message
    inside = folder / "good.toml"
    inside.write_text(_scene_naming("force.csv"))
    assert ls.load_scene(inside).sampled[0].values.tolist() == [0.0, 1.0, 0.0]
    trusted = folder / "trusted.toml"
    trusted.write_text(_scene_naming("../secret.csv"))
    with pytest.raises(SceneError) as caught:  # read when trusted; its header is not quoted
        ls.load_scene(trusted, allow_outside=True)
    assert "no column 't' for the time in the header row (2 columns)" in str(caught.value)
    assert SECRET not in str(caught.value)


def test_scene_text_without_a_file_names_files_relative_to_the_current_folder(folder, monkeypatch):
    monkeypatch.chdir(folder)
    assert scene_from_toml_text(_scene_naming("force.csv")).sampled is not None
    with pytest.raises(SceneError, match="leads out of the scene file's folder"):
        scene_from_toml_text(_scene_naming("../secret.csv"))


def test_error_messages_quote_only_the_offending_cell(tmp_path):
    path = tmp_path / "f.csv"
    path.write_text(f"t,F\n0,0\n1,{SECRET}-{'x' * 200}\n")
    with pytest.raises(SceneError) as caught:
        Sampled.from_csv(path)
    message = str(caught.value)
    assert message.startswith("f.csv, line 3, column 'F': 'SECRET-LINE-7f3a-") and len(message) < 140
    path.write_text(f"{SECRET},{SECRET}2\n0,0\n")
    with pytest.raises(SceneError) as caught:
        Sampled.from_csv(path)
    assert SECRET not in str(caught.value)


@pytest.mark.parametrize(("content", "fragment"), [
    ("t,F\n0," + "1" * 140_000 + "\n1,0\n", "f.csv, line 2: a cell has more than 131,072 characters"),
    ("t,F\n0,\x001\n", "f.csv, line 2"),
    ("t,F\n0,1j\n1,0\n", "f.csv, line 2, column 'F': '1j' is not a number"),
    ("t,F\n0,1e400\n1,0\n", "'1e400' is not finite"),
    ("t,F\n0,nan\n1,0\n", "'nan' is not finite"),
    ("t,F\n1,0\n0,0\n", "strictly increasing"),
    ("", "the CSV file is empty"),
    ("t,F,G\n0,1,2\n", "say which column is the force (value=...): the header (line 1) has 3 columns"),
    ("t,F\n0\n", "f.csv, line 2: no 'F' entry"),
], ids=["long cell", "NUL", "complex", "huge", "nan", "decreasing", "empty", "three columns", "short row"])
def test_broken_csv_files_are_named_by_file_and_line(tmp_path, content, fragment):
    path = tmp_path / "f.csv"
    path.write_text(content)
    with pytest.raises(SceneError, match=None) as caught:
        Sampled.from_csv(path)
    assert fragment in str(caught.value)


def test_csv_options_are_checked_before_reading(tmp_path):
    path = tmp_path / "f.csv"
    path.write_text("t,F\n0,1\n1,1\n")
    for options, fragment in (({"delimiter": ";;"}, "delimiter must be one character"),
                              ({"delimiter": 5}, "delimiter must be one character"),
                              ({"kind": "cubic"}, "kind must be one of linear, zoh"),
                              ({"time": 3}, "time must be a column name")):
        with pytest.raises(SceneError, match=fragment):
            Sampled.from_csv(path, **options)


@pytest.mark.parametrize("given", [123, None, b"wall-pair.toml", bytearray(b"x.toml"), 1.5, ["a.toml"],
                                   "bad\x00name.toml"])
def test_odd_things_given_as_scene_paths_are_named(given):
    with pytest.raises(SceneError, match=r"load_scene: expected a"):
        ls.load_scene(given)
    if not isinstance(given, str):
        with pytest.raises(SceneError, match=r"CSV file: expected a path"):
            ls.sampled_from_csv(given)


def test_a_million_parameters_is_refused_at_once(tmp_path):
    path = tmp_path / "many.toml"
    path.write_text("[parameters]\n" + "".join(f'p{i} = "r"\n' for i in range(1_000_000))[:15_000_000]
                    + SCENE)
    setup = "import laplace_springs as ls"
    found = attempts(setup, {"load": f"ls.load_scene({str(path)!r})"}, timeout=30)
    assert found["load"].kind == "SceneError"
    assert "more than the limit 10,000 (Limits.max_parameters)" in found["load"].text
    with pytest.raises(SceneError, match="Limits.max_parameters"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], parameters=[f"p{i}" for i in range(10_001)])


def test_the_sample_limit_is_read_at_call_time(set_limits, tmp_path):
    path = tmp_path / "f.csv"
    path.write_text("t,F\n" + "".join(f"{k},1\n" for k in range(20)))
    set_limits(max_samples=10)
    with pytest.raises(LimitError, match=r"f.csv: 20 rows of samples, more than the limit 10 \(Limits.max_samples\)"):
        Sampled.from_csv(path)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(st.binary(max_size=300) | st.text(max_size=300).map(str.encode))
def test_any_bytes_as_a_csv_file_give_samples_or_a_scene_error(tmp_path, data):
    path = tmp_path / "any.csv"
    path.write_bytes(data)
    try:
        result = Sampled.from_csv(path)
    except SceneError:
        return
    assert result.times.size >= 2


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(alphabet=st.sampled_from(list('[]=",{}\n mk1wall0.5csvforcing/.\\') + ["\x00"]), max_size=200))
def test_any_text_as_a_scene_file_gives_a_scene_or_a_scene_error(text):
    try:
        scene = scene_from_toml_text(text)
    except SceneError:
        return
    assert isinstance(scene, ls.Scene)


def test_the_public_probe_fifo_is_not_read(tmp_path):
    """The acceptance probe: a FIFO given to ls.load_scene raises a ValueError at once."""
    pipe = tmp_path / "scene.toml"
    os.mkfifo(pipe)
    found = attempts("import laplace_springs as ls", {"probe": f"ls.load_scene({str(pipe)!r})"}, timeout=20)
    assert found["probe"].kind == "SceneError" and issubclass(SceneError, ValueError)
    assert sys.platform != "win32"
