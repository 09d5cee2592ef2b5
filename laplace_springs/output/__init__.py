"""Stage 5, output: LaTeX, plots and scene diagrams (matplotlib is imported when drawing)."""
