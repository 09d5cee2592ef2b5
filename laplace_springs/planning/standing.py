"""The standing plan: the planner's choice for every request of one kind, made once.

On a scene the tiny engine takes (unforced, at most Limits.tiny_max_coordinates
coordinates, rational entries, an invertible M: :func:`tiny_scene`), :func:`plan
<laplace_springs.planning.plan.plan>` puts the tiny engine first for every float64 request
of x itself (derivative 0) of at most :data:`STANDING_MAX_COUNT` times, whatever the times
and the target: the engines' table gives the tiny engine no horizon and no expected miss,
and costs below those of every other engine that serves such a scene (a build of at most
15 + 4·40 µs against 1.5 ms or more; 20·n² ns per time, as the general modal engine's, and
30 ns for one coordinate, where that engine's 20 ns overtake the tiny engine's smaller
build beyond some 2·10⁵ times). The plan of such a request is then
known before it is made, so :func:`~laplace_springs.solve` (method "auto") and
``Solution.evaluate`` skip the scene's facts and the per-request plan there: the tiny engine
evaluates every time, and only where a bound misses the target is the request planned and
executed in full (which runs the same primary first, so the values are the same).
tests/planning/test_standing.py checks the claim against :func:`plan` on random scenes and
requests.

The reading the decision needs (the scene's exact entries) is the tiny engine's own, so the
decision costs nothing the engine would not pay.
"""

from __future__ import annotations

from ..limits import limits
from ..model.scene import Scene
from ..numeric.tiny import TinyData, tiny_cost, tiny_data

__all__ = ["STANDING_ENGINE", "STANDING_MAX_COUNT", "tiny_scene", "standing_engine",
           "standing_covers", "standing_seconds"]

#: The engine of the standing plan.
STANDING_ENGINE = "tiny"
#: The most times a request may have for the standing plan to hold (well inside every
#: crossover of the cost table; a larger request is planned, which costs little beside it).
STANDING_MAX_COUNT = 10_000


def tiny_scene(scene: Scene) -> TinyData | None:
    """The tiny engine's exact data when it takes the scene and the scene is unforced (the
    scenes whose facts the tiny engine's reading gives, and whose plans stand), else None.

    >>> tiny_scene(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])).n
    1
    >>> eye = [[int(i == j) for j in range(5)] for i in range(5)]
    >>> tiny_scene(Scene.from_matrices(M=eye, K=eye, x0=[1, 0, 0, 0, 0], v0=[0] * 5)) is None
    True
    """
    if scene.forcing is not None or scene.sampled is not None \
            or scene.n > limits().tiny_max_coordinates:
        return None
    data = tiny_data(scene)
    return None if isinstance(data, str) else data


def standing_engine(scene: Scene, method: str) -> str | None:
    """The engine every float64 request of x on ``scene`` starts with under ``method``, when
    that is known without planning (:data:`STANDING_ENGINE` for "auto" on a scene
    :func:`tiny_scene` takes), else None.

    >>> scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    >>> standing_engine(scene, "auto"), standing_engine(scene, "exact")
    ('tiny', None)
    """
    if method != "auto" or tiny_scene(scene) is None:
        return None
    return STANDING_ENGINE


def standing_covers(count: int) -> bool:
    """Whether the standing plan holds for a request of x at ``count`` times.

    >>> standing_covers(100), standing_covers(10**6)
    (True, False)
    """
    return 0 < count <= STANDING_MAX_COUNT


def standing_seconds(scene: Scene, count: int) -> float:
    """The plan's estimate of the standing engine's run over ``count`` times of x, its data
    built (what ``Plan.seconds`` would be: the executor shows progress beyond
    Limits.progress_after_seconds).

    >>> scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    >>> standing_seconds(scene, 100) < 1e-5
    True
    """
    return tiny_cost(scene, count=count) - tiny_cost(scene, count=0)
