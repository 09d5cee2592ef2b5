"""Publishing a scene: worked-example pages, LaTeX documents, the interactive explorer.

The last stage before the command line: it uses the solution, the sweeps (the explorer and
the pages' sliders are compiled once with :mod:`laplace_springs.sweeps`) and the outputs.

- :mod:`~laplace_springs.publish.page`: ``worked_example(scene)``, a self-contained HTML
  page like the seed's course page (and its ``.tex`` twin, :mod:`~laplace_springs.publish.document`);
- :mod:`~laplace_springs.publish.explore`: ``explore(scene)``, sliders in Jupyter;
- :mod:`~laplace_springs.publish.mathjax`: the packaged MathJax that typesets both, offline;
- :mod:`~laplace_springs.publish.commands`: ``laplace-springs animate`` and ``laplace-springs page``.
"""
