"""Stage 1, the model: exact numbers and the safe parser, scenes, scene files, forcing.

Nothing here solves anything; every later stage reads a :class:`~laplace_springs.model.scene.Scene`.
"""
