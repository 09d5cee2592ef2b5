"""The hostile-input audit of issue 22, runnable: ``python -m tests.hostile_audit``.

Not a test module (pytest does not collect it): it runs every finding of issue 22 and
more attempts of each class, each in its own interpreter with a time limit (20 s) and an
address-space limit (4 GiB, ``resource.setrlimit``), and prints one line per attempt and
a count per verdict:

* ``clear``: a SceneError/LimitError/InversionError, a ValueError raised by the package's
  own check (bad times), or the CLI's one line (exit 2), whose message quotes nothing of
  a file outside the scene's folder;
* ``correct``: accepted, and the result checked against a value computed another way;
* ``accepted``: accepted, with no independent check written for it;
* ``unclear``: any other exception (OverflowError, TypeError, MemoryError, ...), or a
  CLI internal error (exit 1);
* ``wrong``: accepted with a result that fails its check, or text that was executed;
* ``hang``: no answer within the time limit; ``crash``: the child died.

``--only WORD`` runs the attempts whose class or name contains WORD; ``--jobs N`` runs N
children at once (default 2).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

TIMEOUT = 20.0
MEMORY = 4 * 2**30
SECRET = "SECRET-LINE-7f3a"
PWNED = "hostile-audit-pwned"

_CHILD = r'''
import resource, sys, json, io, contextlib, os, traceback
resource.setrlimit(resource.RLIMIT_AS, ({memory}, {memory}))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np, sympy as sp
import laplace_springs as ls
from laplace_springs.cli import main
from laplace_springs.model.errors import SceneError, LimitError, InversionError
from fractions import Fraction
from decimal import Decimal
t = ls.t
folder = {folder!r}
SECRET, PWNED = {secret!r}, {pwned!r}

class CliClear(Exception):
    pass

class CliInternal(Exception):
    pass

def cli(*args, check=None):
    """Run the CLI; exit 2 with one line is CliClear, exit 1 CliInternal; exit 0 returns
    the verdict: check(out) when given, else no 'nan' in the output."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    lines = err.getvalue().strip().splitlines()
    if code == 2:
        if len(lines) == 1 and lines[0].startswith("laplace-springs: error: "):
            raise CliClear(lines[0])
        raise CliInternal(f"exit 2 but not one line: {{err.getvalue()[:300]!r}}")
    if code != 0:
        raise CliInternal(f"exit {{code}}: {{err.getvalue()[:300]}}")
    text = out.getvalue()
    return check(text) if check else "nan" not in text.lower()

def close(a, b, rtol=1e-9, atol=1e-12):
    a, b = np.asarray(a, dtype=complex), np.asarray(b, dtype=complex)
    return a.shape == b.shape and bool(np.allclose(a, b, rtol=rtol, atol=atol))

verdict = None
try:
    exec(compile({code!r}, "<attempt>", "exec"))
    if os.path.exists(os.path.join(folder, PWNED)):
        verdict = False
    print(json.dumps({{"outcome": "ok", "verdict": None if verdict is None else bool(verdict)}}))
except BaseException as exc:
    frames = traceback.extract_tb(exc.__traceback__)
    ours = bool(frames) and os.path.abspath(frames[-1].filename).startswith(os.path.dirname(ls.__file__))
    print(json.dumps({{"outcome": type(exc).__name__, "ours": ours,
                      "message": " ".join(str(exc).split())[:400]}}))
'''

#: Exceptions that are clear errors (the message is then checked too).
CLEAR = {"SceneError", "LimitError", "FloatRangeError", "InversionError", "CliClear", "UsageError"}


@dataclass(frozen=True)
class Attempt:
    kind: str  # the class of issue 22 it belongs to
    name: str
    code: str  # sets `verdict` (True: correct, False: wrong) when it is accepted


def _attempts() -> list[Attempt]:
    found: list[Attempt] = []

    def add(kind: str, name: str, code: str) -> None:
        found.append(Attempt(kind, name, textwrap.dedent(code).strip()))

    swapped = ('masses={"x2": 1, "x1": 2}, springs={"k1": ("wall", "x2", 3), "k2": ("x2", "x1", 1)}')
    # -- names of masses and coordinates: one resolution everywhere ----------------------
    add("names", "scene file: force for x1 with masses x2, x1",
        'open(folder + "/sw.toml", "w").write("[masses]\\nx2 = 1\\nx1 = 2\\n[springs]\\nk1 = [\\"wall\\", \\"x2\\", 3]\\n'
        'k2 = [\\"x2\\", \\"x1\\", 1]\\n[forcing]\\nx1 = \\"cos(t)\\"\\n")\n'
        'f = ls.load_scene(folder + "/sw.toml").forcing\nverdict = list(f) == [0, sp.cos(t)]')
    add("names", "with_forcing: force for x1 with masses x2, x1",
        f'f = ls.Scene.from_components({swapped}).with_forcing({{"x1": "cos(t)"}}).forcing\n'
        'verdict = list(f) == [0, sp.cos(t)]')
    add("names", "with_initial: x1 with masses x2, x1",
        f'x0 = ls.Scene.from_components({swapped}).with_initial(x0={{"x1": 1}}).x0\nverdict = list(x0) == [0, 1]')
    add("names", "three masses x3, x1, x2: force for x2",
        'sc = ls.Scene.from_components(masses={"x3": 1, "x1": 1, "x2": 1}, springs={"a": ("wall", "x3", 1), '
        '"b": ("x3", "x1", 1), "c": ("x1", "x2", 1)}).with_forcing({"x2": 5})\nverdict = list(sc.forcing) == [0, 0, 5]')
    add("names", "sweep output x1 with masses x2, x1",
        f'sc = ls.Scene.from_components({swapped}, x0={{"x1": 1}}, parameters={{"k": "positive"}})\n'
        'sc = sc.with_forcing({"x1": "k*cos(t)"})\n'
        'x = ls.sweep(sc, {"k": [1, 2]}, [0.5, 1.5], outputs=["x1"])\n'
        'ref = [ls.solve(sc.subs({"k": k})).evaluate([0.5, 1.5])[1] for k in (1, 2)]\n'
        'verdict = close(np.asarray(x)[:, 0, :], ref, rtol=1e-10)')
    add("names", "CLI --forcing x1= on masses x2, x1",
        'open(folder + "/sw2.toml", "w").write("[masses]\\nx2 = 1\\nx1 = 2\\n[springs]\\nk1 = [\\"wall\\", \\"x2\\", 3]\\n'
        'k2 = [\\"x2\\", \\"x1\\", 1]\\n")\n'
        'ref = ls.solve(ls.Scene.from_matrices(M=[[1, 0], [0, 2]], K=[[4, -1], [-1, 1]], x0=[0, 0], v0=[0, 0], '
        'forcing=[0, "cos(t)"])).evaluate([2.0])[:, 0]\n'
        'verdict = cli("solve", folder + "/sw2.toml", "--forcing", "x1=cos(t)", "--at", "2", '
        'check=lambda out: close([float(v) for v in out.splitlines()[-1].split()[1:]], ref, rtol=1e-9))')
    add("names", "transmissibility output x1 with masses x2, x1",
        'sc = ls.Scene.from_components(masses={"x2": 1, "x1": 2}, springs={"k1": ("ground", "x2", 3), '
        '"k2": ("x2", "x1", 1)})\nT = np.ravel(ls.transmissibility(sc, [0.7], outputs=["x1"]))\n'
        'D = np.array([[4 - 0.49, -1], [-1, 1 - 0.98]])\nverdict = close(T, [abs(np.linalg.solve(D, [3, 0])[1])])')
    add("names", "two masses with the same name (scene file)",
        'open(folder + "/dup.toml", "w").write("[masses]\\nm = 1\\nm = 2\\n")\nls.load_scene(folder + "/dup.toml")')
    add("names", "a mass named wall",
        'ls.Scene.from_components(masses={"wall": 1}, springs={"k": ("wall", "wall", 1)})')
    add("names", "a mass named like a reserved symbol (omega)",
        'sc = ls.Scene.from_components(masses={"omega": 1}, springs={"k": ("wall", "omega", 4)}, x0={"omega": 1})\n'
        'verdict = close(ls.solve(sc).evaluate([1.0])[0], [np.cos(2.0)])')
    add("names", "force for a coordinate and its mass at once",
        'ls.Scene.from_components(masses={"m1": 1, "m2": 1}, springs={"k": ("wall", "m1", 1), "j": ("m1", "m2", 1)})'
        '.with_forcing({"m1": 1, "x1": 2})')
    add("names", "massless node named m2",
        'ls.Scene.from_components(masses={"m1": 1, "m2": 0}, springs={"k": ("wall", "m1", 1)})')
    add("names", "mass name with spaces and unicode",
        'ls.Scene.from_components(masses={"m 1": 1, "ω": 1}, springs={"k": ("wall", "m 1", 1)})')

    # -- parameters named like the toolkit's own symbols ----------------------------------
    for name in ("omega", "s", "lam", "lambda", "t", "pi", "E", "I", "oo", "nan", "x1"):
        add("reserved", f"parameter {name} (from_components)",
            f'ls.Scene.from_components(masses={{"m": 1}}, springs={{"k": ("wall", "m", "{name}")}}, '
            f'parameters=["{name}"])')
    for name in ("omega", "s", "lam", "t"):
        add("reserved", f"Symbol {name} in K (from_matrices, SymPy)",
            f'sc = ls.Scene.from_matrices(M=[[1]], K=[[sp.Symbol("{name}", positive=True)]], x0=[1], v0=[0])\n'
            'print(ls.transfer_function(sc))')
    add("reserved", "parameter x1 in equations with the unknown x1",
        'ls.Scene.from_equations("x1\'\' + x1*x1 = 0, x1(0) = 1, x1\'(0) = 0", parameters=["x1"])')
    add("reserved", "parameter omega in a scene file",
        'open(folder + "/om.toml", "w").write("[parameters]\\nomega = \\"positive\\"\\n[masses]\\nm = 1\\n'
        '[springs]\\nk = [\\"wall\\", \\"m\\", \\"omega\\"]\\n")\nls.load_scene(folder + "/om.toml")')
    add("reserved", "parameter s in equations",
        'ls.Scene.from_equations("x1\'\' + s*x1 = 0, x1(0) = 1, x1\'(0) = 0", parameters=["s"])')
    add("reserved", "sweep over a parameter named omega (mapping key Symbol)",
        'sc = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])\n'
        'ls.sweep(sc, {ls.omega: [1, 2]}, [0.5])')
    add("reserved", "frequency_response with parameter w (allowed), checked",
        'sc = ls.Scene.from_matrices(M=[[1]], K=[["w"]], x0=[1], v0=[0], parameters=["w"])\n'
        'H = ls.frequency_response(sc)[0, 0]\nverdict = sp.simplify(H - 1/(sp.Symbol("w", positive=True) - ls.omega**2)) == 0 '
        'or sp.simplify(H.subs({sc.parameters[0]: 3, ls.omega: 1}) - sp.Rational(1, 2)) == 0')

    # -- sweeps hold every set to Scene.subs's checks ------------------------------------
    sweep_scene = ('sc = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], '
                   'parameters={"m": "real", "k": "positive", "c": "nonnegative"})\n')
    for label, values in (("negative mass declared real", '{"m": [1, -1], "k": [1, 1], "c": [0, 0]}'),
                          ("negative damping", '{"m": [1], "k": [1], "c": [-0.5]}'),
                          ("negative stiffness", '{"m": [1], "k": [-1], "c": [0]}'),
                          ("nan", '{"m": [1], "k": [float("nan")], "c": [0]}'),
                          ("inf", '{"m": [1], "k": [np.inf], "c": [0]}'),
                          ("complex", '{"m": [1], "k": [1j], "c": [0]}'),
                          ("text", '{"m": [1], "k": ["abc"], "c": [0]}'),
                          ("text that would run", '{"m": [1], "k": ["__import__(\'os\').system(\'touch \' + folder + \'/\' + PWNED)"], "c": [0]}'),
                          ("1e400 as text", '{"m": [1], "k": ["1e400"], "c": [0]}'),
                          ("unknown parameter", '{"m": [1], "k": [1], "c": [0], "q": [1]}'),
                          ("lengths differ", '{"m": [1, 2], "k": [1], "c": [0]}'),
                          ("missing parameter", '{"m": [1], "k": [1]}'),
                          ("values not a sequence", '{"m": 1, "k": object(), "c": 0}'),
                          ("2-D values", '{"m": [[1, 2]], "k": [[1, 1]], "c": [[0, 0]]}')):
        add("sweeps", label, sweep_scene + f'ls.sweep(sc, {values}, [0.5, 1.0])')
    add("sweeps", "zero mass: as Scene.subs + solve does", sweep_scene +
        'try:\n    alone = ls.solve(sc.subs({"m": 0, "k": 1, "c": 0})).evaluate([0.5, 1.0])\n'
        'except ValueError as exc:\n    alone = exc\n'
        'try:\n    swept = np.asarray(ls.sweep(sc, {"m": [0], "k": [1], "c": [0]}, [0.5, 1.0]))[0]\n'
        'except ValueError as exc:\n    swept = exc\n'
        'verdict = (type(alone) is type(swept)) if isinstance(alone, Exception) else close(swept, alone)')
    add("sweeps", "good sets checked against ls.solve", sweep_scene +
        'x = np.asarray(ls.sweep(sc, {"m": [1, 2], "k": [4, 1], "c": [0, "1/2"]}, [0.5, 1.0]))\n'
        'ref = [ls.solve(sc.subs({"m": m, "k": k, "c": c})).evaluate([0.5, 1.0])[0] for m, k, c in ((1, 4, 0), (2, 1, "1/2"))]\n'
        'verdict = close(x[:, 0, :], ref, rtol=1e-10)')
    add("sweeps", "negative time", sweep_scene + 'ls.sweep(sc, {"m": [1], "k": [1], "c": [0]}, [-1.0])')
    add("sweeps", "nan time", sweep_scene + 'ls.sweep(sc, {"m": [1], "k": [1], "c": [0]}, [np.nan])')
    add("sweeps", "10^12 sets by grid", sweep_scene +
        'ls.sweep(sc, ls.grid(m=np.linspace(1, 2, 10**4), k=np.linspace(1, 2, 10**4), c=np.linspace(0, 1, 10**4)), [0.5])')
    add("sweeps", "10^4 sets x 10^5 times", sweep_scene +
        'ls.sweep(sc, {"m": np.ones(10**4), "k": np.ones(10**4), "c": np.zeros(10**4)}, np.linspace(0, 1, 10**5))')
    add("sweeps", "sample_parameters 10**12", 'ls.sample_parameters({"k": ("normal", 1, 0.1)}, 10**12)')
    add("sweeps", "sample_parameters -1", 'ls.sample_parameters({"k": ("normal", 1, 0.1)}, -1)')
    add("sweeps", "sample_parameters nan sigma", 'ls.sample_parameters({"k": ("normal", 1, float("nan"))}, 10)')
    add("sweeps", "sample_parameters unknown law", 'ls.sample_parameters({"k": ("cauchy", 1, 1)}, 10)')
    add("sweeps", "sample_parameters size 2.5", 'ls.sample_parameters({"k": ("normal", 1, 0.1)}, 2.5)')

    # -- sampled data -------------------------------------------------------------------
    for label, times, values in (("complex values", "[0, 1, 2]", "np.array([0, 1j, 0])"),
                                 ("10**400", "[0, 1]", "[10**400, 0]"),
                                 ("huge Fraction", "[0, 1]", "[Fraction(10**400, 3), 0]"),
                                 ("Decimal nan", "[0, 1]", "[Decimal('nan'), 0]"),
                                 ("nan", "[0, 1]", "[np.nan, 0]"),
                                 ("inf time", "[0, np.inf]", "[0, 1]"),
                                 ("text values", "[0, 1]", "['1', 'x']"),
                                 ("None", "[0, 1]", "[None, 1]"),
                                 ("2-D values", "[0, 1]", "[[0, 1], [1, 2]]"),
                                 ("lengths differ", "[0, 1, 2]", "[0, 1]"),
                                 ("decreasing times", "[0, 2, 1]", "[0, 1, 2]"),
                                 ("repeated times", "[0, 1, 1]", "[0, 1, 2]"),
                                 ("one sample", "[0]", "[1]"),
                                 ("no samples", "[]", "[]"),
                                 ("negative times", "[-2, -1]", "[1, 1]"),
                                 ("longdouble 1e4000", "[0, 1]", "np.array([np.longdouble('1e4000'), 0])"),
                                 ("10^8 samples", "np.arange(10**8)", "np.zeros(10**8)"),
                                 ("object array of sympy", "[0, 1]", "np.array([sp.Integer(1), sp.pi], dtype=object)"),
                                 ("symbolic value", "[0, 1]", "[sp.Symbol('k'), 1]"),
                                 ("bool values", "[0, 1]", "[True, False]"),
                                 ("generator", "[0, 1]", "(v for v in (0, 1))"),
                                 ("time 1e300 apart", "[0, 1e300]", "[0, 1]")):
        add("sampled", label, f'f = ls.sampled({times}, {values})\n'
            'sol = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[0], v0=[0], forcing=[f]))\n'
            'v = sol.evaluate([0.5])\nverdict = bool(np.all(np.isfinite(v)))')
    add("sampled", "linear sample checked (constant force 1: x = (1 - cos 2t)/4)",
        'f = ls.sampled([0, 5, 10], [1, 1, 1])\n'
        'sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[f]))\n'
        'verdict = close(sol.evaluate([1.0, 3.0])[0], [(1 - np.cos(2.0)) / 4, (1 - np.cos(6.0)) / 4], rtol=1e-10)')
    add("sampled", "kind unknown", 'ls.sampled([0, 1], [0, 1], kind="cubic")')

    # -- periodic inputs ------------------------------------------------------------------
    periodic_scene = 'sc = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[0], v0=[0], forcing=[f])\n'
    for label, force in (("period 0", 'ls.square_wave(1, 0)'), ("negative period", 'ls.square_wave(1, -2)'),
                         ("nan period", 'ls.square_wave(1, float("nan"))'), ("inf period", 'ls.square_wave(1, np.inf)'),
                         ("period 1e-400", 'ls.square_wave(1, "1e-400")'), ("period 1e400", 'ls.square_wave(1, "1e400")'),
                         ("duty 0", 'ls.square_wave(1, 2, 0)'), ("duty 2", 'ls.square_wave(1, 2, 2)'),
                         ("duty nan", 'ls.square_wave(1, 2, float("nan"))'),
                         ("pulse wider than its period", 'ls.pulse_train(1, 1, 2)'),
                         ("amplitude 1e400", 'ls.square_wave("1e400", 2)'),
                         ("one period t**1000", 'ls.periodic("t**1000", 1)'),
                         ("one period exp(t**2)", 'ls.periodic("exp(t**2)", 1)'),
                         ("one period of text that would run", 'ls.periodic("__import__(\'os\')", 1)'),
                         ("symbolic period", 'ls.periodic("t", sp.Symbol("P"))'),
                         ("period as text with t", 'ls.periodic("t", "t")'),
                         ("complex amplitude", 'ls.square_wave(1j, 2)')):
        add("periodic", label, f'f = {force}\n' + periodic_scene + 'v = ls.solve(sc).evaluate([0.5, 3.0])\n'
            'verdict = bool(np.all(np.isfinite(v)))')
    add("periodic", "square wave at t = 1e6 + 0.25 vs the first periods (steady state)",
        'f = ls.square_wave(1, 2)\n' + periodic_scene +
        'sol = ls.solve(sc)\nlate, early = sol.evaluate([1e6 + 0.25])[0, 0], sol.evaluate([100.25])[0, 0]\n'
        'verdict = abs(late - early) < 1e-9')
    add("periodic", "periodic solution at 10^7 times", 'f = ls.square_wave(1, 2)\n' + periodic_scene +
        'sol = ls.solve(sc)\ntimes = np.linspace(0, 100, 10**7)\nv = sol.evaluate(times)\n'
        'verdict = close(v[0, [0, 5_000_000, -1]], sol.evaluate(times[[0, 5_000_000, -1]])[0], rtol=1e-9, atol=1e-12)')
    add("periodic", "periodic solution at t = 1e300", 'f = ls.square_wave(1, 2)\n' + periodic_scene +
        'v = ls.solve(sc).evaluate([1e300])\nverdict = bool(np.all(np.isfinite(v)))')

    # -- scene files and CSV files ----------------------------------------------------------
    fifo_setup = ('p = folder + "/pipe.csv"\nos.path.exists(p) or os.mkfifo(p)\n'
                  'q = folder + "/pipe.toml"\nos.path.exists(q) or os.mkfifo(q)\n')
    csv_scene = '[masses]\\nm1 = 1\\n[springs]\\nk = [\\"wall\\", \\"m1\\", 4]\\n[forcing]\\nm1 = {{ csv = \\"{}\\", time = \\"t\\", value = \\"F\\" }}\\n'

    def scene_naming(csv: str, file: str = "named.toml") -> str:
        return f'open(folder + "/{file}", "w").write("{csv_scene.format(csv)}")\n'

    add("files", "FIFO as a CSV", fifo_setup + 'ls.sampled_from_csv(p)')
    add("files", "FIFO as a scene file", fifo_setup + 'ls.load_scene(q)')
    add("files", "FIFO named in a scene file", fifo_setup + scene_naming("pipe.csv") + 'ls.load_scene(folder + "/named.toml")')
    add("files", "FIFO through the CLI", fifo_setup + 'cli("solve", q)')
    add("files", "FIFO through --equations", fifo_setup + 'cli("solve", "--equations", q)')
    add("files", "symlink to a FIFO", fifo_setup + 'l = folder + "/link.toml"\nos.path.lexists(l) or os.symlink(q, l)\n'
        'ls.load_scene(l)')
    add("files", "/dev/zero as scene", 'ls.load_scene("/dev/zero")')
    add("files", "/dev/stdin as scene", 'ls.load_scene("/dev/stdin")')
    add("files", "/dev/zero as CSV", 'ls.sampled_from_csv("/dev/zero")')
    add("files", "/proc/self/environ as CSV (outside, absolute)", scene_naming("/proc/self/environ") +
        'ls.load_scene(folder + "/named.toml")')
    add("files", "directory as scene", 'ls.load_scene(folder)')
    for csv in ("/etc/passwd", "../secret.csv", "sub/../../secret.csv", "~/secret.csv", "escape.csv",
                "file:///etc/passwd", "\\\\u0000x.csv", "./././../secret.csv"):
        add("files", f"csv = {csv!r}", scene_naming(csv) +
            'try:\n    ls.load_scene(folder + "/named.toml")\nexcept SceneError as e:\n'
            '    assert SECRET not in str(e) and "root:" not in str(e), str(e)\n    raise')
    add("files", "a CSV cell of 200,000 characters",
        'open(folder + "/wide.csv", "w").write("t,F\\n0," + "1" * 200_000 + "\\n")\nls.sampled_from_csv(folder + "/wide.csv", value="F")')
    add("files", "a NUL in a CSV", 'open(folder + "/nul.csv", "w").write("t,F\\n0,1\\x00\\n")\n'
        'ls.sampled_from_csv(folder + "/nul.csv", value="F")')
    add("files", "a CSV of binary garbage", 'open(folder + "/bin.csv", "wb").write(bytes(range(256)) * 10)\n'
        'ls.sampled_from_csv(folder + "/bin.csv")')
    add("files", "a CSV with a BOM, checked", 'open(folder + "/bom.csv", "w", encoding="utf-8-sig").write("t,F\\n0,1\\n1,3\\n")\n'
        's = ls.sampled_from_csv(folder + "/bom.csv", value="F")\nverdict = list(s.values) == [1.0, 3.0]')
    add("files", "10^6 parameters", 'open(folder + "/many.toml", "w").write("[parameters]\\n" + "".join(f"p{i} = \\"positive\\"\\n" '
        'for i in range(10**6)) + "[masses]\\nm = 1\\n")\nls.load_scene(folder + "/many.toml")')
    add("files", "2*10^4 parameters as a list", 'ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], '
        'parameters=[f"p{i}" for i in range(20_000)])')
    add("files", "nested TOML", 'from laplace_springs.model.scene_files import scene_from_toml_text\n'
        'scene_from_toml_text("x = " + "[" * 10000 + "]" * 10000)')
    add("files", "a scene file that is not UTF-8", 'open(folder + "/latin.toml", "wb").write(b"[masses]\\nm\\xe9 = 1\\n")\n'
        'ls.load_scene(folder + "/latin.toml")')
    add("files", "a 20 MB scene file", 'open(folder + "/big.toml", "w").write("#" * 20_000_000)\nls.load_scene(folder + "/big.toml")')
    for label, value in (("123", "123"), ("None", "None"), ("bytes", 'b"wall-pair"'), ("list", '["wall-pair"]'),
                         ("empty string", '""'), ("NUL in the path", '"a\\x00b.toml"'), ("unknown name", '"no-such-scene"')):
        add("files", f"load_scene({label})", f'ls.load_scene({value})')
    add("files", "from_state_space([0, 1])", 'ls.from_state_space([0, 1])')
    add("files", "mass 1e400 in a scene file", 'open(folder + "/huge.toml", "w").write("[masses]\\nm = \\"1e400\\"\\n")\n'
        'ls.load_scene(folder + "/huge.toml")')
    add("files", "text that would run, as a mass", 'open(folder + "/run.toml", "w").write("[masses]\\nm = \\"__import__(\'os\').system(\'touch '
        '" + folder + "/" + PWNED + "\')\\"\\n")\nls.load_scene(folder + "/run.toml")')

    # -- the command line -------------------------------------------------------------------
    for args in (["response", "wall-pair", "--at", "1e300"], ["response", "wall-pair", "--at", "1e400"],
                 ["response", "wall-pair", "--at=-inf"], ["response", "wall-pair", "--at", "1e300Hz"],
["response", "wall-pair", "--force", "0"],
                 ["solve", "wall-pair", "--plot", "motion"], ["solve", "wall-pair", "--plot", "{folder}"],
                 ["solve", "wall-pair", "--plot", "/dev/null"], ["solve", "wall-pair", "--plot", "{folder}/nowhere/x.png"],
                 ["solve", "wall-pair", "--plot", "{folder}/pipe.png"], ["response", "wall-pair", "--plot", "{folder}/"],
                 ["solve", "wall-pair", "--latex", "-o", "/dev/full"], ["solve", "wall-pair", "--latex", "-o", "{folder}"],
                 ["bench", "--list", "--time-limit", "nan"], ["bench", "--list", "--time-limit", "-1"],
                 ["bench", "--list", "--sympy-limit", "inf"], ["bench", "--list", "-o", "/dev/null"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--fps", "0"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--fps", "1000000000"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--t-end", "-1"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--t-end", "1e300"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--duration", "0"],
                 ["animate", "wall-pair", "-o", "{folder}/a.gif", "--speed", "nan"],
                 ["animate", "wall-pair", "-o", "{folder}/a.txt"], ["page", "wall-pair", "-o", "{folder}"],
                 ["page", "wall-pair", "-o", "{folder}/p.pdf"],
["solve", "wall-pair", "--at", "1e400"],
                 ["solve", "wall-pair", "--at", "0", "--dps", "0"], ["solve", "wall-pair", "--at", "0", "--dps", "100000"],
                 ["solve", "wall-pair", "--param", "k=nan"], ["solve", "wall-pair", "--param", "k=1"],
                 ["solve", "wall-pair", "--forcing", "x1=t**1000"],
                 ["solve", "wall-pair", "--forcing", "x1=__import__('os').system('touch {folder}/{pwned}')"],
                 ["solve", "wall-pair", "--coordinates", "x9"], ["solve", "wall-pair", "--unit", "parsec"],
                 ["solve", "wall-pair", "--at", "0," * 100_000 + "0"]):
        shown = " ".join(arg if len(arg) < 40 else arg[:20] + "..." for arg in args)
        code = (fifo_setup.replace("pipe.csv", "pipe.png") +
                f'cli(*[a.replace("{{folder}}", folder).replace("{{pwned}}", PWNED) for a in {args!r}])')
        add("cli", shown, code if len(code) < 5000 else code)
    add("cli", "response --at 0 checked (H = K^-1)",
        'K = np.array([[0.38, -0.08], [-0.08, 0.28]])\n'
        'verdict = cli("response", "wall-pair", "--at", "0", check=lambda out: '
        'close([float(v) for v in out.splitlines()[-1].split()[1:]], np.abs(np.linalg.inv(K)[:, 0]), rtol=1e-9))')
    add("cli", "solve --at 1e300 checked against 50 digits",
        'ref = ls.solve(ls.load_scene("wall-pair")).evaluate([1e300], dps=50)\n'
        'verdict = cli("solve", "wall-pair", "--at", "1e300", check=lambda out: '
        'close([float(v) for v in out.splitlines()[-1].split()[1:]], [float(v) for v in ref[:, 0]], rtol=1e-9))')
    add("cli", "solve wall-pair-dashpot --at 37.5 checked against 50 digits",
        'ref = ls.solve(ls.load_scene("wall-pair-dashpot")).evaluate([37.5], dps=50)\n'
        'verdict = cli("solve", "wall-pair-dashpot", "--at", "37.5", check=lambda out: '
        'close([float(v) for v in out.splitlines()[-1].split()[1:]], [float(v) for v in ref[:, 0]], rtol=1e-9))')
    add("cli", "animate --dpi 0", 'cli("animate", "wall-pair", "-o", folder + "/d0.gif", "--dpi", "0", "--fps", "2")')
    add("cli", "animate --dpi 1e9", 'cli("animate", "wall-pair", "-o", folder + "/d9.gif", "--dpi", "1e9", "--fps", "2")')
    add("cli", "response --at 1e100 checked (|H11| = 1/omega^2)",
        'verdict = cli("response", "wall-pair", "--at", "1e100", check=lambda out: '
        'abs(float(out.splitlines()[-1].split()[1]) / 1e-200 - 1) < 1e-6)')

    # -- forcing that runs for minutes, sizes that exhaust memory --------------------------
    one = 'sc = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0]'
    for label, force in (("t**1000", '"t**1000"'), ("t**1000*exp(-t)", '"t**1000*exp(-t)"'),
                         ("(cos+sin)**30", '"(cos(t)+sin(2*t)+cos(3*t)+sin(5*t))**30"'),
                         ("cos(t)**200", '"cos(t)**200"'), ("exp(t**2)", '"exp(t**2)"'), ("1/(1+t)", '"1/(1+t)"'),
                         ("t**(10**6) text", '"t**(10**6)"'), ("sin(t)**2**20", '"sin(t)**2**20"'),
                         # built unevaluated: SymPy's own Add of 10^4 steps takes 30 s
                         ("SymPy 10^4 Heavisides", 'sp.Add(*[sp.Heaviside(sp.Add(t, -sp.Rational(k, 100), evaluate=False), evaluate=False) for k in range(10**4)], evaluate=False)'),
                         ("SymPy 10^4 cosines", 'sp.Add(*[sp.cos(k * t) for k in range(1, 10**4)], evaluate=False)'),
                         ("SymPy degree 10^5", 'sp.Add(*[sp.Mul(k, sp.Pow(t, k, evaluate=False), evaluate=False) for k in range(1, 10**5 + 1)], evaluate=False)'),
                         ("SymPy 10^4 exponentials", 'sp.Add(*[sp.exp(-k * t) for k in range(1, 10**4)], evaluate=False)'),
                         ("SymPy t**10**6", 'sp.Pow(t, 10**6)'),
                         ("SymPy exp(exp(exp(t)))", 'sp.exp(sp.exp(sp.exp(t)))'),
                         ("SymPy unknown function", 'sp.Function("f")(t)'),
                         ("SymPy 10^3 deltas", 'sum(sp.DiracDelta(t - k) for k in range(1, 1001))'),
                         ("SymPy nested 500 deep", 'functools.reduce(lambda a, k: sp.sin(a, evaluate=False), range(500), t)'),
                         ("SymPy Piecewise 10^3", 'sp.Piecewise(*[(k, t < k) for k in range(1, 1000)], (0, True))'),
                         ("SymPy Integral", 'sp.Integral(sp.exp(-t * sp.Symbol("u")), (sp.Symbol("u"), 0, 1))')):
        add("resources", f"forcing {label}", 'import functools\n' + f'{one}, forcing=[{force}])\n'
            'v = ls.solve(sc).evaluate([0.5])\nverdict = bool(np.all(np.isfinite(v)))')
    add("resources", "forcing t**3 checked by quadrature",
        'sc = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["t**3"])\n'
        'v = ls.solve(sc).evaluate([1.0])[0, 0]\nimport mpmath\n'
        'ref = mpmath.quad(lambda u: mpmath.sin(2 * (1 - u)) / 2 * u**3, [0, 1])\nverdict = abs(v - float(ref)) < 1e-12')
    add("resources", "evaluate on 10^8 times", f'{one})\nls.solve(sc).evaluate(np.linspace(0, 1, 10**8))')
    add("resources", "2 masses on 3*10^7 times",
        'sc = ls.load_scene("wall-pair")\nls.solve(sc).evaluate(np.linspace(0, 1, 3 * 10**7))')
    add("resources", "1 mass on 4*10^7 times (within the limits)",
        f'{one})\nsol = ls.solve(sc)\ntimes = np.linspace(0, 10, 4 * 10**7)\nv = sol.evaluate(times)\n'
        'verdict = close(v[0, [7, -1]], sol.evaluate(times[[7, -1]])[0])')
    add("resources", "evaluate at 10^7 times as a Python list", f'{one})\nls.solve(sc).evaluate([0.5] * 10**7)')
    add("resources", "evaluate with dps=10000 at 10^4 times", f'{one})\nls.solve(sc).evaluate(np.linspace(0, 1, 10**4), dps=10000)')
    add("resources", "evaluate at time 1e300 (damped: 0)", f'{one})\nv = ls.solve(sc).evaluate([1e300])\n'
        'verdict = bool(np.all(v == 0))')
    add("resources", "frequency_response at 10^8 frequencies", f'{one})\nls.frequency_response(sc, np.linspace(0, 1, 10**8))')
    add("resources", "transmissibility at 10^8 frequencies",
        'sc = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 4)})\n'
        'ls.transmissibility(sc, np.linspace(0, 1, 10**8))')
    add("resources", "frequency_response of 1,000 coordinates at 1,000 frequencies",
        'sc = ls.Scene.from_components(masses={f"m{i}": 1 for i in range(1000)}, '
        'springs={f"k{i}": ("wall", f"m{i}", i + 1) for i in range(1000)})\n'
        'H = ls.frequency_response(sc, np.linspace(0, 1, 1000))\nverdict = close(H[3, 9, 9], 1 / (10 - (3 / 999) ** 2))')
    add("resources", "sweep 10^3 sets x 10^5 times for quantities (streams)", sweep_scene +
        'r = ls.sweep(sc, {"m": np.ones(1000), "k": np.full(1000, 4.0), "c": np.zeros(1000)}, '
        'np.linspace(0, 10, 10**5), quantities=["peak"])\nverdict = close(r.quantities["peak"][:, 0], np.ones(1000), rtol=1e-9)')
    add("resources", "animate figsize 1000 x 1000", 'ls.animate(ls.solve(ls.load_scene("wall-pair")), duration=1, fps=2, '
        'figsize=(1000, 1000))')
    add("resources", "grid of 10^6 x 10^6", 'ls.grid(a=np.arange(10**6), b=np.arange(10**6))')
    add("resources", "a 10^5-coordinate dense matrix as lists",
        'ls.Scene.from_matrices(M=[[1] * 10**5] * 10**5, K=[[0]], x0=[0], v0=[0])')
    return found


def _run(attempt: Attempt, folder: str) -> tuple[str, str]:
    source = _CHILD.format(memory=MEMORY, folder=folder, secret=SECRET, pwned=PWNED, code=attempt.code)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    try:
        run = subprocess.run([sys.executable, "-"], input=source, capture_output=True, text=True,
                             timeout=TIMEOUT, check=False, env=env)
    except subprocess.TimeoutExpired:
        return "hang", f"no answer within {TIMEOUT:g} s"
    line = next((line for line in reversed(run.stdout.splitlines()) if line.startswith("{")), None)
    if line is None:
        return "crash", f"exit {run.returncode}: {run.stderr.strip()[-300:]}"
    found = json.loads(line)
    if found["outcome"] == "ok":
        verdict = found["verdict"]
        return ("accepted", "") if verdict is None else ("correct", "") if verdict else ("wrong", "check failed")
    message = found["message"]
    if found["outcome"] in CLEAR or (found["outcome"] == "ValueError" and found["ours"]):
        if SECRET in message or "root:" in message:
            return "wrong", f"message quotes a file outside: {message}"
        return "clear", f"{found['outcome']}: {message}"
    return "unclear", f"{found['outcome']}: {message}"


def _folder() -> str:
    folder = tempfile.mkdtemp(prefix="hostile-audit-")
    outside = os.path.dirname(folder)
    secret = os.path.join(outside, "secret.csv")
    with open(secret, "w") as handle:
        handle.write(f"{SECRET},x\n1,2\n")
    os.makedirs(os.path.join(folder, "sub"), exist_ok=True)
    os.symlink(secret, os.path.join(folder, "escape.csv"))
    return folder


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run the attempts whose class or name contains this")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    chosen = [a for a in _attempts() if not args.only or args.only in a.kind or args.only in a.name]
    folder = _folder()
    counts: dict[str, int] = {}
    start = time.perf_counter()
    with ThreadPoolExecutor(args.jobs) as pool:
        for attempt, (verdict, text) in zip(chosen, pool.map(lambda a: _run(a, folder), chosen)):
            counts[verdict] = counts.get(verdict, 0) + 1
            print(f"{verdict:9} {attempt.kind:9} {attempt.name[:60]:60} {text[:220]}", flush=True)
    print(f"\n{len(chosen)} attempts in {time.perf_counter() - start:.0f} s: "
          + ", ".join(f"{counts[k]} {k}" for k in sorted(counts)))
    return 0 if not {"unclear", "wrong", "hang", "crash"} & set(counts) else 1


if __name__ == "__main__":
    sys.exit(main())
