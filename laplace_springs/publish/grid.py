"""The precomputed parameter grid behind a worked-example page's sliders.

A page has no Python kernel, so its sliders move over values computed beforehand: the
scene's knobs (:mod:`~laplace_springs.publish.knobs`: its parameters, or up to three of its
springs, dashpots and masses) each get a few values around their own (41 for one knob, 15
for two, 7 for three, in all at most :attr:`~laplace_springs.limits.Limits.page_max_grid_sets`
sets), and one :func:`laplace_springs.sweeps.sweep` computes x(t) for every set at
:data:`GRID_TIMES` times (each set to :attr:`~laplace_springs.limits.Limits.explore_target`
of its motion's size: curves to draw). The page carries the
values as float32 (base64) and redraws the curves of the set the sliders point at.
"""

from __future__ import annotations

import base64
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..sweeps.compile import compile_scene
from ..sweeps.run import grid as cartesian
from ..sweeps.run import sweep
from .knobs import Knob, knobbed_scene

__all__ = ["SliderGrid", "slider_grid", "GRID_TIMES", "COUNTS"]

#: Times per curve in the page.
GRID_TIMES = 121
#: Values per knob, by the number of knobs.
COUNTS = {1: 41, 2: 15, 3: 7}


@dataclass(frozen=True)
class SliderGrid:
    """The sliders' data: knobs, their values, the times and x(t) of every set.

    Attributes
    ----------
    knobs : tuple of Knob
    axes : tuple of numpy.ndarray
        The values of each knob (the sets are their Cartesian product, the last knob fastest).
    times : numpy.ndarray
    values : numpy.ndarray
        x(t) of every set, shape (sets, n, times).
    names : tuple of str
        The coordinates.
    """

    knobs: tuple[Knob, ...]
    axes: tuple[np.ndarray, ...]
    times: np.ndarray
    values: np.ndarray
    names: tuple[str, ...]

    def start(self) -> tuple[int, ...]:
        """The index of each knob's own value on its axis."""
        return tuple(int(np.argmin(np.abs(axis - knob.value))) for axis, knob in zip(self.axes, self.knobs))

    def set_index(self, indices: Sequence[int]) -> int:
        """The set the sliders at ``indices`` point at (row-major, the last knob fastest)."""
        index = 0
        for axis, i in zip(self.axes, indices):
            index = index * len(axis) + int(i)
        return index

    def encoded(self) -> str:
        """The values as little-endian float32, base64."""
        return base64.b64encode(np.ascontiguousarray(self.values, dtype="<f4").tobytes()).decode("ascii")


def slider_grid(scene: Scene, *, t_end: float, knobs: Sequence[str] | None = None,
                values: Mapping[str, Any] | None = None) -> SliderGrid:
    """Compute the sliders' grid (see the module notes).

    Raises
    ------
    SceneError
        When the scene cannot be compiled for the vectorised sweep (sampled, periodic or
        delayed forces, more than :attr:`~laplace_springs.limits.Limits.sweep_max_coordinates`
        coordinates: solving the grid set by set would take minutes), or has nothing to turn.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> grid = slider_grid(ls.load_scene("wall-pair"), t_end=10.0)
    >>> [k.name for k in grid.knobs], grid.values.shape
    (['k1', 'k2', 'k3'], (343, 2, 121))
    """
    knobbed, found = knobbed_scene(scene, knobs=knobs, values=values, initial=False, forcing=False,
                                   most=3)
    if not found and knobs is None:  # no parameters or components (a matrix scene): the initial data
        knobbed, found = knobbed_scene(scene, values=values, initial=True, forcing=False)
    found = found[:3]
    if not found:
        raise SceneError("the scene has neither parameters nor springs, dashpots, masses or "
                         "initial data that can be turned")
    count = COUNTS[len(found)]
    most = limits().page_max_grid_sets
    count = min(count, max(2, int(math.floor(most ** (1.0 / len(found))))))
    axes = tuple(knob.grid(count) for knob in found)
    product = cartesian(**{knob.name: axis for knob, axis in zip(found, axes)})
    given = {str(k): v for k, v in (values or {}).items()}
    turned = {knob.name for knob in found}
    others = {s.name: float(given.get(s.name, 1.0))  # parameters not turned stay at their values
              for s in knobbed.parameters if s.name not in turned}
    compile_scene(knobbed)  # refuses, with the reason, what the vectorised sweep cannot take
    times = np.linspace(0.0, float(t_end), GRID_TIMES)
    sets = len(next(iter(product.values())))
    data = dict(product, **{name: np.full(sets, value) for name, value in others.items()})
    result = np.asarray(sweep(knobbed, data, times, target=limits().explore_target), dtype=float)
    return SliderGrid(tuple(found), axes, times, result, tuple(scene.names))
