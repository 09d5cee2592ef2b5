"""Running hostile attempts where they may hang: in a fresh interpreter, with a time limit.

``attempts(setup, cases, timeout)`` runs ``setup`` and then each case (a Python expression)
in one child process, one line of output per case: ``name <TAB> outcome <TAB> text``, the
outcome ``ok`` (the repr of the value follows) or the exception's class name (its message
follows). A case that does not finish within the time left fails the test with its name;
a child that dies (a crash, a MemoryError killing it) fails it with the child's stderr.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from dataclasses import dataclass

__all__ = ["Outcome", "attempts"]

_CHILD = """
import sys, traceback
{setup}
cases = {cases!r}
for name, source in cases:
    try:
        value = eval(source)
        print(name, "ok", " ".join(repr(value).split())[:2000], sep="\\t", flush=True)
    except BaseException as exc:
        text = " ".join(str(exc).split())
        print(name, type(exc).__name__, text[:2000], sep="\\t", flush=True)
        if not isinstance(exc, Exception):
            raise
"""


@dataclass(frozen=True)
class Outcome:
    """What one attempt did: ``kind`` is ``"ok"`` or an exception class name."""

    kind: str
    text: str

    @property
    def ok(self) -> bool:
        return self.kind == "ok"


def attempts(setup: str, cases: dict[str, str], timeout: float = 60.0) -> dict[str, Outcome]:
    """Run ``cases`` (name -> expression) after ``setup`` in a child interpreter.

    Raises
    ------
    AssertionError
        When an attempt does not finish before ``timeout`` seconds (for all of them) have
        passed, naming it, or when the child dies.
    """
    source = _CHILD.format(setup=textwrap.dedent(setup), cases=list(cases.items()))
    try:
        run = subprocess.run([sys.executable, "-c", source], capture_output=True, text=True,
                             timeout=timeout, check=False)
        output, error, died = run.stdout, run.stderr, run.returncode != 0
    except subprocess.TimeoutExpired as exc:
        output = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
        done = {line.split("\t", 1)[0] for line in output.splitlines()}
        hanging = next(name for name in cases if name not in done)
        raise AssertionError(f"attempt {hanging!r} did not finish within {timeout} s "
                             f"(the attempts before it took the rest)") from None
    found: dict[str, Outcome] = {}
    for line in output.splitlines():
        name, kind, text = (line.split("\t", 2) + ["", ""])[:3]
        found[name] = Outcome(kind, text)
    missing = [name for name in cases if name not in found]
    if died or missing:
        raise AssertionError(f"the child died before {missing[:1]}: {error[-2000:]}")
    return found
