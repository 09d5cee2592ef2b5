"""Draw every bundled scene's diagram and motion plot into PNG files.

Run ``python docs/make_figures.py [OUTDIR]`` (default docs/_static/scenes); the docs build
calls it too. Files: ``<scene>-diagram.png`` and ``<scene>-motion.png``. The PNGs carry no
version or date metadata, so redrawing unchanged figures leaves the files unchanged.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

import laplace_springs as ls
from laplace_springs.output.plots import plot_motion

_METADATA = {"Software": None}
_DEFAULT_OUTDIR = Path(__file__).resolve().parent / "_static" / "scenes"


def main(outdir: Path | str = _DEFAULT_OUTDIR) -> list[Path]:
    """Write the PNGs; return their paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    written = []
    for name in ls.bundled_scenes():
        scene = ls.load_scene(name)
        solution = ls.solve(scene)
        for kind, ax in (("diagram", ls.draw_scene(scene)), ("motion", plot_motion(solution))):
            path = outdir / f"{name}-{kind}.png"
            ax.figure.savefig(path, dpi=90, bbox_inches="tight", metadata=_METADATA)
            plt.close(ax.figure)
            written.append(path)
    return written


if __name__ == "__main__":
    for path in main(*sys.argv[1:2]):
        print(path)
