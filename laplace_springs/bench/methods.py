"""The methods the error-against-run-time benchmark compares (see :mod:`laplace_springs.bench.harness`).

Each :class:`Method` turns a :class:`Problem` (a scene, its times, and the same data as
float64 arrays) into x(t) at those times. ``prepare`` does untimed setup that the
method's user would already have (the transform X(λ) for the Laplace-domain peers);
``run`` is what is timed. Ours start from the exact :class:`~laplace_springs.Scene`;
the peers start from float64 data and form everything else
(the state-space system, the integrator) inside the timed call, from the
first-order matrix Z rounded once from its exact value.

Peers are imported lazily: a method whose ``requires`` modules cannot be imported is
reported as skipped by the benchmark, never an error.
"""

from __future__ import annotations

import contextlib
import importlib.util
import multiprocessing
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from time import perf_counter
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from sympy.core.cache import clear_cache

from ..exact.resolvent import resolvent
from ..kernels.precision import workdps
from ..model.scene import Scene
from ..model.symbols import TIME, lam
from ..numeric.first_order import first_order_system, float_matrix
from ..solving import solve

__all__ = ["Problem", "Outcome", "Method", "Unavailable", "TimeLimitExceeded", "all_methods",
           "QUICK_METHODS", "missing_modules"]


@dataclass(frozen=True, eq=False)
class Problem:
    """One benchmark case in the forms the methods need.

    ``times`` are float64; ``mp_times`` are the same binary values as mpmath numbers,
    so every method (and the reference) is evaluated at exactly the same instants.
    ``Z`` and ``y0`` are the first-order system y' = Z y of
    :func:`laplace_springs.numeric.first_order.first_order_system` (massless nodes reduced),
    formed exactly and rounded once to float64: the peers get it ready-made.
    """
    name: str
    kind: str
    scene: Scene
    times: np.ndarray
    mp_times: tuple[Any, ...]
    Z: np.ndarray
    y0: np.ndarray

    @classmethod
    def from_case(cls, name: str, kind: str, scene: Scene, times: Sequence[Any]) -> Problem:
        """Build from a scene and times (floats, or decimal strings rounded once to float64).

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[3])
        >>> problem = Problem.from_case("p", "k", scene, ["0.1", 2.5])
        >>> problem.times.tolist(), problem.Z.tolist(), problem.y0.tolist()
        ([0.1, 2.5], [[0.0, 1.0], [-4.0, -0.5]], [1.0, 3.0])
        """
        floats = np.array([float(Fraction(tv)) if isinstance(tv, str) else float(tv)
                           for tv in times], dtype=float)
        Z, y0, _ = first_order_system(scene)
        return cls(name, kind, scene, floats, tuple(mpmath.mpf(v) for v in floats),
                   float_matrix(Z, "Z"), float_matrix(y0, "y0").ravel())

    @property
    def n(self) -> int:
        return self.scene.n

    @property
    def x0(self) -> np.ndarray:
        return self.y0[:self.n]


@dataclass
class Outcome:
    """What one timed run returns: x at the times, optional timed phases, a note."""
    values: np.ndarray
    phases: dict[str, float] = field(default_factory=dict)
    note: str = ""
    #: Time measured by the method itself (a worker process); None: the caller's clock.
    seconds: float | None = None


@dataclass(frozen=True)
class Method:
    """A way of computing x(t) that the benchmark times.

    Attributes
    ----------
    name : str
        Short identifier used on the command line and in the CSV.
    label : str
        What is run, for the report.
    ours : bool
        A route of this project (True) or a peer.
    run : callable
        ``run(problem, state) -> Outcome``; the timed part.
    prepare : callable, optional
        ``prepare(problem) -> state``; untimed setup (default: none).
    requires : tuple of str
        Modules that must import for the method to run.
    family : str
        Methods of one family run in order of increasing cost (tighter tolerance);
        once one times out on a case, the rest of its family is skipped there.
    own_limit : bool
        The method runs in a worker process, times itself and enforces its own time
        limit (raising :class:`TimeLimitExceeded`); it is run once, not repeated.
    """
    name: str
    label: str
    ours: bool
    run: Callable[[Problem, Any], Outcome]
    prepare: Callable[[Problem], Any] | None = None
    requires: tuple[str, ...] = ()
    family: str = ""
    own_limit: bool = False

    def close(self) -> None:
        """Release what the method holds (a worker process)."""
        close = getattr(self.run, "close", None)
        if close is not None:
            close()


def missing_modules(method: Method) -> list[str]:
    """The modules of ``method.requires`` that cannot be imported."""
    return [module for module in method.requires if importlib.util.find_spec(module) is None]


# ----------------------------------------------------------------------------- ours


def _timed(function: Callable[[], Any]) -> tuple[Any, float]:

    start = perf_counter()
    value = function()
    return value, perf_counter() - start


def _route_runner(route: str) -> Callable[[Problem, Any], Outcome]:
    """``solve(scene, method=route)`` + ``evaluate(times)`` in float64; the note names the
    route taken (``"auto"`` chooses one)."""
    def run(problem: Problem, state: Any) -> Outcome:
        solution, solve_time = _timed(lambda: solve(problem.scene, method=route))
        values, evaluate_time = _timed(lambda: solution.evaluate(problem.times))
        return Outcome(np.asarray(values, dtype=float),
                       {"solve": solve_time, "evaluate": evaluate_time},
                       f"route: {solution.method}")
    return run


def _run_mp30(problem: Problem, state: Any) -> Outcome:
    solution, solve_time = _timed(lambda: solve(problem.scene))
    values, evaluate_time = _timed(lambda: solution.evaluate(list(problem.mp_times), dps=30))
    return Outcome(np.asarray(values, dtype=object),
                   {"solve": solve_time, "evaluate": evaluate_time})


class Unavailable(Exception):
    """Raised by ``prepare`` when a method cannot run on a problem (reported as skipped)."""


# ----------------------------------------------------------------------------- scipy


def _run_expm(problem: Problem, state: Any) -> Outcome:
    from scipy.linalg import expm

    Z, y0, n = problem.Z, problem.y0, problem.n
    values = np.empty((n, len(problem.times)))
    for col, tv in enumerate(problem.times):
        values[:, col] = (expm(Z * tv) @ y0)[:n]
    return Outcome(values)


def _ivp_runner(solver: str, tolerance: float) -> Callable[[Problem, Any], Outcome]:
    def run(problem: Problem, state: Any) -> Outcome:
        from scipy.integrate import solve_ivp

        Z, y0, n = problem.Z, problem.y0, problem.n
        options = {"jac": lambda t, y: Z} if solver in ("Radau", "BDF", "LSODA") else {}
        times = problem.times
        result = solve_ivp(lambda t, y: Z @ y, (0.0, float(times.max())), y0, method=solver,
                           t_eval=times, rtol=tolerance, atol=tolerance, **options)
        if not result.success:
            raise RuntimeError(f"solve_ivp: {result.message}")
        values = np.empty((n, len(times)))
        values[:, np.argsort(times, kind="stable")] = result.y[:n]
        return Outcome(values, note=f"{result.nfev} f-evals")
    return run


# ----------------------------------------------------------------------------- python-control


def _uniform_from_zero(times: np.ndarray) -> bool:
    if len(times) < 3 or times[0] != 0.0:
        return False
    steps = np.diff(times)
    return bool(np.all(steps > 0) and np.allclose(steps, steps[0], rtol=1e-12, atol=0.0))


def _run_control(problem: Problem, state: Any) -> Outcome:
    import control

    Z, y0, n = problem.Z, problem.y0, problem.n
    output = np.eye(n, len(y0))
    system = control.ss(Z, np.zeros((len(y0), 1)), output, np.zeros((n, 1)))
    times = problem.times
    if _uniform_from_zero(times):
        response = control.initial_response(system, T=times, X0=y0)
        return Outcome(np.asarray(response.outputs).reshape(n, len(times)),
                       note="one call on the uniform grid")
    values = np.empty((n, len(times)))
    for col, tv in enumerate(times):
        if tv == 0.0:
            values[:, col] = problem.x0
            continue
        response = control.initial_response(system, T=[0.0, tv], X0=y0)
        values[:, col] = np.asarray(response.outputs).reshape(n, 2)[:, -1]
    return Outcome(values, note="one call per time (grid not uniform)")


# ----------------------------------------------------------------------------- mpmath


def _transform_coefficients(problem: Problem) -> tuple[list, list[list]]:
    """Δ(λ) and the numerators N_i(λ) of X_i = N_i/Δ as coefficient lists (exact → mpf)."""
    R = resolvent(problem.scene)

    def coefficients(poly: sp.Poly) -> list:
        return [mpmath.mpf(sp.Float(c, 40)._mpf_) if not isinstance(c, sp.Rational)
                else mpmath.mpf(int(c.p)) / int(c.q) for c in poly.all_coeffs()]

    with workdps(40):
        return coefficients(R.determinant), [coefficients(N) for N in R.numerators]


def _invertlaplace_runner(talbot_or_cohen: str) -> Callable[[Problem, Any], Outcome]:
    def run(problem: Problem, state: Any) -> Outcome:
        denominator, numerators = state
        values = np.empty((problem.n, len(problem.times)), dtype=object)
        for i, numerator in enumerate(numerators):
            def X(s, numerator=numerator):
                return mpmath.polyval(numerator, s) / mpmath.polyval(denominator, s)
            for col, tv in enumerate(problem.mp_times):
                with workdps(15):
                    values[i, col] = (mpmath.mpf(problem.x0[i]) if tv == 0 else
                                      mpmath.invertlaplace(X, tv, method=talbot_or_cohen))
        return Outcome(values, note="x(0) = x0 given (t = 0 not invertible)")
    return run


# ----------------------------------------------------------------------------- SymPy


class TimeLimitExceeded(Exception):
    """A run went past its time limit."""


def _sympy_values(results: list, times: np.ndarray) -> np.ndarray:
    """Lambdify SymPy's x_i(t) (Heaviside(t) → 1, as t ≥ 0) and evaluate at ``times``."""
    rows = []
    for result in results:
        expr = result.replace(sp.Heaviside, lambda *args: sp.S.One)
        values = np.asarray(sp.lambdify(TIME, expr, "numpy")(times), dtype=complex)
        rows.append(np.broadcast_to(values, times.shape).real)
    return np.array(rows, dtype=float)


def _sympy_child(connection: Connection) -> None:
    """Worker loop: invert each transform list sent, reply with time and values."""
    connection.send(("ready",))
    while (task := connection.recv()) is not None:
        transforms, times = task
        clear_cache()
        try:
            start = perf_counter()
            results = [sp.inverse_laplace_transform(X, lam, TIME) for X in transforms]
            inverted = perf_counter()
            if any(r.has(sp.InverseLaplaceTransform) for r in results):
                connection.send(("failed", "SymPy left the transform unevaluated"))
                continue
            values = _sympy_values(results, times)
            done = perf_counter()
        except Exception as exc:  # report any SymPy failure to the parent as a result
            connection.send(("failed", f"{type(exc).__name__}: {exc}"[:200]))
            continue
        connection.send(("done", done - start, {"invert": inverted - start,
                                                "evaluate": done - inverted}, values))


class SympyInverter:
    """Runs SymPy's inverse_laplace_transform in a persistent worker process.

    The worker is spawned once (imports are not timed) and replaced after a run is
    killed at its time limit. ``prepare`` gives X_i(λ) from the exact resolvent
    (untimed: it is the input the peer needs); the reported time is the worker's own
    (inversion + lambdify + evaluation), with the SymPy cache cleared before each case.
    """
    STARTUP_LIMIT = 120.0

    def __init__(self, limit: float) -> None:
        self.limit = limit
        self._process: BaseProcess | None = None
        self._connection: Connection | None = None

    def _start(self) -> Connection:
        context = multiprocessing.get_context("spawn")
        connection, child = context.Pipe()
        process = context.Process(target=_sympy_child, args=(child,), daemon=True)
        self._connection, self._process = connection, process
        process.start()
        child.close()
        if not connection.poll(self.STARTUP_LIMIT):
            self.close()
            raise RuntimeError("the SymPy worker process did not start")
        connection.recv()
        return connection

    def __call__(self, problem: Problem, transforms: Any) -> Outcome:
        connection = self._connection
        if connection is None or self._process is None or not self._process.is_alive():
            connection = self._start()
        connection.send((transforms, problem.times))
        if not connection.poll(self.limit):
            self.close()
            raise TimeLimitExceeded(f"killed after {self.limit:g} s")
        message = connection.recv()
        if message[0] == "failed":
            raise RuntimeError(message[1])
        _, seconds, phases, values = message
        return Outcome(values, phases, "Heaviside(t) read as 1", seconds=seconds)

    def close(self) -> None:
        """Stop the worker process (it is started again when needed)."""
        process, connection = self._process, self._connection
        if process is not None:
            if process.is_alive() and connection is not None:
                with contextlib.suppress(OSError):
                    connection.send(None)
                process.join(1.0)
            if process.is_alive():
                process.kill()
            process.join()
        self._process = self._connection = None


def _sympy_transforms(problem: Problem) -> list:
    return list(resolvent(problem.scene).transform())


# ----------------------------------------------------------------------------- registry

#: Tolerances (rtol = atol) for solve_ivp.
IVP_TOLERANCES = (1e-6, 1e-9, 1e-12)
IVP_SOLVERS = ("RK45", "DOP853", "Radau", "LSODA")

#: The methods of ``--quick``.
QUICK_METHODS = ("ours", "ours-modal", "ours-certified", "ours-mp30", "scipy-expm", "ivp-DOP853-1e-09",
                 "ivp-Radau-1e-09", "ivp-LSODA-1e-09", "control-initial", "mpmath-talbot")


def _ivp_methods() -> list[Method]:
    return [Method(f"ivp-{solver}-{tol:.0e}", f"scipy solve_ivp {solver}, rtol = atol = {tol:.0e}",
                   False, _ivp_runner(solver, tol), requires=("scipy",), family=f"ivp-{solver}")
            for solver in IVP_SOLVERS for tol in IVP_TOLERANCES]


def all_methods(*, sympy_limit: float = 10.0) -> tuple[Method, ...]:
    """Every method the benchmark knows, ours first.

    ``sympy_limit`` is the time limit (seconds) of each SymPy inversion. Call
    ``close()`` on the methods when done (it stops SymPy's worker process).

    Examples
    --------
    >>> [m.name for m in all_methods()][:5]
    ['ours', 'ours-modal', 'ours-certified', 'ours-mp30', 'scipy-expm']
    """
    return (
        Method("ours", "solve(scene) + evaluate(times), float64 (the default route)", True,
               _route_runner("auto")),
        Method("ours-modal", 'solve(scene, method="modal") + evaluate(times), float64',
               True, _route_runner("modal")),
        Method("ours-certified", 'solve(scene, method="certified") + evaluate(times), float64',
               True, _route_runner("certified")),
        Method("ours-mp30", "solve(scene) + evaluate(times, dps=30), mpmath", True, _run_mp30),
        Method("scipy-expm", "scipy.linalg.expm(Z t) @ y0, once per time", False, _run_expm,
               requires=("scipy",)),
        *_ivp_methods(),
        Method("control-initial", "python-control initial_response of ss(Z, 0, [I 0], 0)",
               False, _run_control, requires=("control", "scipy")),
        Method("mpmath-talbot", "mpmath.invertlaplace(X_i, t, method='talbot'), 15 digits",
               False, _invertlaplace_runner("talbot"), prepare=_transform_coefficients),
        Method("mpmath-cohen", "mpmath.invertlaplace(X_i, t, method='cohen'), 15 digits",
               False, _invertlaplace_runner("cohen"), prepare=_transform_coefficients),
        Method("sympy-ilt", "sympy.inverse_laplace_transform(X_i, s, t), lambdified, "
               "in a worker process", False, SympyInverter(sympy_limit),
               prepare=_sympy_transforms, own_limit=True),
    )
