"""Hostile command lines (issue 22): every bad option is one line on stderr and exit 2,
before any work is done, and nothing is written anywhere else.

Output paths (``--plot``, ``-o``) that are directories, devices, FIFOs, missing folders or
lack a format suffix; numbers that are not finite in any option (``bench --time-limit
nan``); a frequency beyond the float64 range (``response --at 1e300`` printed nan and
exited 0); FIFOs as scene files (in a child process with a time limit).
"""

from __future__ import annotations

import contextlib
import io
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import laplace_springs.cli as cli
from laplace_springs.cli import main
from tests._hostile import attempts


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_line_error(code: int, err: str, *fragments: str) -> None:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("laplace-springs: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


@pytest.fixture
def no_work(monkeypatch):
    """Solving or plotting fails the test: the options must be refused before."""
    def refuse(*args, **kwargs):
        raise AssertionError("work started before the options were checked")
    for name in ("solve", "modes", "frequency_response", "overview_figure", "plot_frequency_response"):
        monkeypatch.setattr(cli, name, refuse)


@pytest.fixture
def places(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    os.mkfifo(tmp_path / "pipe.png")
    (tmp_path / "folder.png").mkdir()
    (tmp_path / "file.txt").write_text("kept\n")
    return tmp_path


_BAD_OUTPUTS = [
    (["solve", "wall-pair", "--plot", "motion"], "'motion' has no suffix"),
    (["solve", "wall-pair", "--plot", "folder.png"], "'folder.png' is a directory, not a file to write"),
    (["solve", "wall-pair", "--plot", "pipe.png"], "'pipe.png' is a FIFO, not a file to write"),
    (["solve", "wall-pair", "--plot", "/dev/null"], "'/dev/null' is a character device"),
    (["solve", "wall-pair", "--plot", "."], "'.' is a directory"),
    (["solve", "wall-pair", "--plot", "nowhere/x.png"], "the folder 'nowhere' does not exist"),
    (["solve", "wall-pair", "--plot", "x.doc"], "has the suffix '.doc'"),
    (["solve", "wall-pair", "--plot", ""], "'' is not a file name"),
    (["solve", "wall-pair", "--latex", "-o", "folder.png"], "-o/--output: 'folder.png' is a directory"),
    (["solve", "wall-pair", "--latex", "-o", "/dev/zero"], "is a character device"),
    (["response", "wall-pair", "--plot", "bode"], "--plot: 'bode' has no suffix"),
    (["response", "wall-pair", "--plot", "pipe.png"], "is a FIFO"),
    (["bench", "--list", "-o", "file.txt"], "-o/--out: 'file.txt' is a file, not a folder"),
    (["bench", "--list", "-o", "nowhere/out"], "the folder 'nowhere' does not exist"),
]


@pytest.mark.parametrize(("args", "fragment"), _BAD_OUTPUTS,
                         ids=[" ".join(args[2:]) or "empty" for args, _ in _BAD_OUTPUTS])
def test_output_paths_are_checked_before_any_work(capsys, places, no_work, args, fragment):
    before = sorted(os.listdir(places))
    one_line_error(*run(capsys, *args)[::2], fragment)
    assert sorted(os.listdir(places)) == before  # nothing written beside them
    assert (places / "file.txt").read_text() == "kept\n"


@pytest.mark.parametrize("args", [
    ["bench", "--list", "--time-limit", "nan"],
    ["bench", "--list", "--time-limit", "inf"],
    ["bench", "--list", "--sympy-limit=-inf"],
    ["animate", "wall-pair", "-o", "x.gif", "--t-end", "nan"],
    ["animate", "wall-pair", "-o", "x.gif", "--duration", "inf"],
    ["animate", "wall-pair", "-o", "x.gif", "--dpi", "nan"],
    ["solve", "wall-pair", "--at", "0,nan"],
    ["solve", "wall-pair", "--at", "inf"],
    ["response", "wall-pair", "--at", "nan"],
    ["solve", "wall-pair", "--param", "k=nan"],
])
def test_numbers_that_are_not_finite_are_refused_in_every_option(capsys, places, no_work, args):
    code, _, err = run(capsys, *args)
    one_line_error(code, err)
    assert any(word in err for word in ("finite", "nan", "inf")), err


def test_a_frequency_beyond_the_float64_range_is_an_error_not_nan(capsys):
    code, out, err = run(capsys, "response", "wall-pair", "--at", "1e300")
    one_line_error(code, err, "omega = 1e+300", "beyond the float64 range")
    assert "nan" not in out.lower()
    code, out, err = run(capsys, "response", "wall-pair", "--at", "1e100")
    assert code == 0 and "nan" not in out.lower(), err
    amplitudes = [float(v) for v in out.splitlines()[-1].split()[1:]]
    assert amplitudes[0] == pytest.approx(1e-200, rel=1e-6)  # |H11| → 1/(m1 ω²), m1 = 1


def test_fifos_on_the_command_line_are_refused_at_once(tmp_path):
    os.mkfifo(tmp_path / "scene.toml")
    os.mkfifo(tmp_path / "eq.txt")
    setup = f"from laplace_springs.cli import main\nfolder = {str(tmp_path)!r}"
    found = attempts(setup, {
        "solve": "main(['solve', folder + '/scene.toml'])",
        "response": "main(['response', folder + '/scene.toml'])",
        "equations": "main(['solve', '--equations', folder + '/eq.txt'])",
    }, timeout=60)
    assert {name: outcome.text for name, outcome in found.items()} == {
        "solve": "2", "response": "2", "equations": "2"}


@settings(max_examples=40, deadline=None)
@given(st.lists(st.sampled_from(list("ab./\\-_ ~") + [".png", ".pdf", "/dev/", ".."]), max_size=12)
       .map(lambda parts: "".join(parts).lstrip("/")))  # relative: nothing written outside tmp
def test_any_plot_path_is_written_or_refused_in_one_line(tmp_path_factory, name):
    """Random --plot names (relative, so that an accepted one lands in a temporary folder):
    a refusal is one line; what is accepted has a known suffix and is written there."""
    folder = tmp_path_factory.mktemp("plots")
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main(["solve", "wall-pair", "--at", "0", f"--plot={name}"])  # "-a" too
    finally:
        os.chdir(cwd)
    if code == 0:
        assert os.path.splitext(name)[1].lower() in (".png", ".pdf")
        assert os.path.isfile(folder / name), name
    else:
        one_line_error(code, err.getvalue())
