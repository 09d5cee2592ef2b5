"""Execute the notebooks once per test session (shared by test_notebooks and test_docs).

The executed copies (with outputs) go to a temporary folder; the docs build renders
those instead of executing the notebooks a second time. Kernels run two at a time.
"""

from __future__ import annotations

import functools
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))


def _execute(path: Path, outdir: Path) -> BaseException | None:
    import nbclient
    import nbformat

    notebook = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(notebook, timeout=120, kernel_name="python3",
                                     resources={"metadata": {"path": str(path.parent)}})
    try:
        client.execute()
    except Exception as exc:  # reported by the test of this notebook
        return exc
    nbformat.write(notebook, outdir / path.name)
    return None


@functools.cache
def executed_notebooks() -> tuple[Path, dict[str, BaseException | None]]:
    """(folder of executed copies, {notebook name: None or the error it raised})."""
    outdir = Path(tempfile.mkdtemp(prefix="laplace-springs-notebooks-"))
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda path: _execute(path, outdir), NOTEBOOKS))
    return outdir, {path.name: error for path, error in zip(NOTEBOOKS, results)}
