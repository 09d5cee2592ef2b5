"""The notebooks run top to bottom, are committed without outputs, and the seed walkthroughs
name the seed's misprints."""

from __future__ import annotations

import json

import pytest

from tests._notebook_runs import NOTEBOOKS, executed_notebooks


def test_there_is_a_notebook_per_topic():
    names = " ".join(path.name for path in NOTEBOOKS)
    for topic in ("example1", "example2", "example3", "examples4_5", "driven", "stability"):
        assert topic in names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_committed_without_outputs(path):
    notebook = json.loads(path.read_text(encoding="utf-8"))
    for cell in notebook["cells"]:
        if cell["cell_type"] == "code":
            assert cell["outputs"] == [] and cell["execution_count"] is None, path.name


SEED_NOTEBOOKS = [path for path in NOTEBOOKS if path.name[:2] <= "06"]  # 07 on: beyond the seed


@pytest.mark.parametrize("path", SEED_NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_states_where_the_seed_misprints(path):
    text = path.read_text(encoding="utf-8")
    assert "Where the page misprints" in text or "Where the seed page misprints" in text


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_executes(path):
    pytest.importorskip("nbclient")
    outdir, errors = executed_notebooks()
    if errors[path.name] is not None:
        raise errors[path.name]  # the CellExecutionError names the cell and the traceback
    executed = json.loads((outdir / path.name).read_text(encoding="utf-8"))
    outputs = [output for cell in executed["cells"] if cell["cell_type"] == "code"
               for output in cell["outputs"]]
    assert outputs and not any(output["output_type"] == "error" for output in outputs)
