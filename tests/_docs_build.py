"""Build the documentation site once per test session (shared by test_docs and test_browser).

The notebooks are executed once (tests/_notebook_runs.py) and the build renders those
copies; the HTML goes to a temporary folder.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from tests._notebook_runs import executed_notebooks

DOCS = Path(__file__).resolve().parent.parent / "docs"


@functools.cache
def built_docs() -> tuple[Path, int, str]:
    """(the HTML folder, an exit status: sphinx's, or 1 when a notebook fails to execute, the
    end of sphinx's output)."""
    outdir, errors = executed_notebooks()  # executed once, shared with test_notebooks
    failed = [name for name, error in errors.items() if error is not None]
    build = Path(tempfile.mkdtemp(prefix="laplace-springs-docs-"))
    environment = dict(os.environ, LAPLACE_SPRINGS_EXECUTED_NOTEBOOKS=str(outdir))
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
               "-d", str(build / "doctrees"), str(DOCS), str(build / "html")]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=environment,
                            check=False)
    output = result.stdout[-4000:] + result.stderr[-4000:]
    if failed:  # the site is built all the same (those notebooks without outputs)
        return build / "html", 1, f"notebooks that fail to execute: {failed} (see test_notebooks)\n{output}"
    return build / "html", result.returncode, output
