"""Refuse at once what the exact route cannot finish, before any symbolic work.

The exact route builds the adjugate of λ²M + λC + K, factors Δ(λ) over the field of the
coefficients and computes residues in the number field of each factor. A rational
factor of degree above
:attr:`~laplace_springs.limits.Limits.max_exact_factor_degree` cannot finish
there (its exact terms cost about the fourth power of the degree), nor can a symbolic
scene whose Δ has a factor that large (its adjugate alone is out of reach). The
partial-fraction engine refuses the first right after factoring; :func:`screen_scene`
refuses both before the adjugate is even built, from exact rational arithmetic at
numbers. (A symbolic factor of degree ≥ 3 below the limit is no longer refused: its
terms are a sum over its roots, :mod:`laplace_springs.exact.root_sums`.)

* Δ and the numerators N_i of X_i = N_i/Δ are computed at numeric values p of the
  parameters, by python-flint determinants and solves at integer λ and interpolation
  (milliseconds for 2 coordinates, under a second for 40).
* Specialising parameters is a ring homomorphism, so each irreducible factor Q of Δ over
  ℚ(params) specialises to a product of irreducible factors of Δ(p) over ℚ: an
  irreducible factor f of Δ(p) of degree > Limits.max_exact_factor_degree lies in a factor Q
  of Δ at least that large.
* Q's principal parts vanish (the pole cancels and nothing is refused) only if Q^m
  divides every numerator of every piece; then f divides every numerator at p. So a
  refusal needs a numerator at p that f does not divide. A forced scene's piece with
  delay τ has numerators adj(λ)·E(F_τ + [τ = 0] r) over Δ·E, E the inputs' common
  denominator; every supported input has denominator factors of degree ≤ 2, which f
  cannot divide, so the same test holds with E taken at p.

* A numeric scene (not free with rational entries, whose roots are named) is refused
  too when a factor of degree ≥ 3 that stays has roots SymPy's ``CRootOf`` would number
  only after more work than :attr:`~laplace_springs.limits.Limits.max_exact_isolation`
  (:mod:`laplace_springs.exact.isolation`: a pair of masses of 1e-300 on springs of 1
  driven by cos t ran for minutes), naming the scene's smallest and largest entries.

* Where the planner chooses (:func:`exact_refusal`, not :func:`screen_scene`), a numeric
  scene whose entries mix more than
  :attr:`~laplace_springs.limits.Limits.max_exact_irrationals` irrational numbers
  (√5 − 1, e and π/3 on one mass) is declined on cost: its exact terms ran for 20 s to a
  coefficient of 180,000 characters, where the numeric engines serve it in milliseconds.

Each other refusal is therefore one the engine would make (or, for a symbolic scene, one
whose adjugate would not finish); anything the screen cannot decide (entries that are
not rational functions of the parameters, Δ(p) ≡ 0) goes on to the engine, which
decides exactly. Scenes above :attr:`~laplace_springs.limits.Limits.max_exact_coordinates` are refused on size alone.
"""

from __future__ import annotations

import weakref
from typing import Any

import flint
import sympy as sp

from ..limits import limits
from ..model.errors import InversionError
from ..model.forcing import input_transform
from ..model.numbers import generic_values
from ..model.scene import Scene
from ..model.symbols import lam
from .named_roots import free_rational
from .partial_fractions import isolation_obstacle
from .rational import RationalPencil, fmpq_of, initial_vector, rational_pencil, solve_at_integers

__all__ = ["screen_scene", "exact_refusal", "has_exact_form"]


_Vector = list[flint.fmpq_poly]


def _rational(expr: sp.Expr, point: dict) -> tuple[flint.fmpq_poly, flint.fmpq_poly] | None:
    """A rational function of λ at ``point`` as (numerator, denominator) over ℚ, or None."""
    numerator, denominator = sp.fraction(sp.together(expr.xreplace(point)))
    polys = []
    for part in (numerator, denominator):
        try:
            poly = sp.Poly(part, lam)
        except sp.PolynomialError:
            return None
        coeffs = []
        for c in reversed(poly.all_coeffs()):
            value = fmpq_of(c)
            if value is None:
                return None
            coeffs.append(value)
        polys.append(flint.fmpq_poly(coeffs))
    if polys[1] == 0:
        return None
    return polys[0], polys[1]


def _right_hand_sides(scene: Scene, pencil: RationalPencil, point: dict) -> list[_Vector] | None:
    """The vectors w with X = adj(λ)·w/(Δ·E) for each piece (one per delay), at ``point``.

    Free scene: w = r(λ) = M(λ x0 + v0) + C x0. Forced: per delay τ, w = E·(F_τ + [τ = 0] r)
    with E the lcm of the inputs' denominators at ``point``; None when an input is not
    rational there, or E has an irreducible factor of degree ≥ 3 (which no supported
    input gives: the refusals below rely on it).
    """
    free = initial_vector(scene, pencil, point)
    if free is None:
        return None
    if not scene.is_forced:
        return [free]
    assert scene.forcing is not None
    parts: dict[sp.Expr, dict[int, tuple[flint.fmpq_poly, flint.fmpq_poly]]] = {sp.S.Zero: {}}
    for j, f in enumerate(scene.forcing):
        for tau, R in input_transform(f, f"forcing[{j}]", lam).parts:
            fraction = _rational(R, point)
            if fraction is None:
                return None
            parts.setdefault(tau, {})[j] = fraction
    vectors = []
    for tau, inputs in parts.items():
        E = flint.fmpq_poly([1])
        for _, den in inputs.values():
            E = E * den / E.gcd(den)
        _, factors = E.factor()
        if any(g.degree() > 2 for g, _ in factors):
            return None
        w = [E * inputs[j][0] / inputs[j][1] if j in inputs else flint.fmpq_poly([0])
             for j in range(scene.n)]
        if tau == 0:
            w = [wj + E * rj for wj, rj in zip(w, free)]
        vectors.append(w)
    return vectors


def screen_scene(scene: Scene) -> None:
    """Raise InversionError at once when the exact route cannot finish for ``scene``
    (the reason :func:`exact_refusal` gives).

    Examples
    --------
    A damped chain of 13 masses driven by a step: Δ(λ) is irreducible of degree 26, beyond
    the written-out form that forced scenes take (the free motion is solved in named
    numbers).

    >>> import sympy as sp
    >>> n = 13
    >>> K = sp.zeros(n, n)
    >>> for i in range(n):
    ...     K[i, i] = 2 + (i % 2)
    ...     if i + 1 < n:
    ...         K[i, i + 1] = K[i + 1, i] = -1
    >>> scene = Scene.from_matrices(M=sp.diag(*range(1, n + 1)), C=sp.eye(n) / 20, K=K,
    ...                             x0=[1] + [0] * (n - 1), v0=[0] * n,
    ...                             forcing=["Heaviside(t - 1)"] + [0] * (n - 1))
    >>> screen_scene(scene)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.InversionError: Δ(λ) = det(λ²M + λC + K) has an irreducible factor of degree 26 > Limits.max_exact_factor_degree = 24: ...
    """
    why = _screened(scene)[0]
    if why is not None:
        raise InversionError(why)


def exact_refusal(scene: Scene) -> str | None:
    """Why the planner does not take the exact route for ``scene``, or None (milliseconds).

    See the module notes: every refusal here but one is one the partial-fraction engine
    would make after building the resolvent and factoring Δ(λ) (or a symbolic adjugate
    that would not finish); the other is on cost, where the numeric engines serve
    (entries mixing more than Limits.max_exact_irrationals irrational numbers: an
    explicit method="exact" and ``x`` still build those). The answer is kept with the
    scene for the limits in force: the planner reads it for small forced scenes and the
    exact engine's build again.
    """
    return _screened(scene)[1]


def _screened(scene: Scene) -> tuple[str | None, str | None]:
    """(the build's refusal, the planner's), computed once per scene and limits."""
    current = limits()
    found = _SCREENED.get(scene)
    if found is None or found[0] is not current:
        build = _refusal(scene)
        found = _SCREENED[scene] = (current, build, build or _mixed_refusal(scene))
    return found[1], found[2]


#: scene -> (the limits in force, its screen): kept as long as the scene lives.
_SCREENED: weakref.WeakKeyDictionary[Scene, tuple[Any, str | None, str | None]] = \
    weakref.WeakKeyDictionary()


def _mixed_refusal(scene: Scene) -> str | None:
    """The planner's refusal of a numeric scene mixing too many irrational numbers."""
    if free_rational(scene):
        return None
    mixed = irrational_numbers(scene)
    if len(mixed) <= limits().max_exact_irrationals:
        return None
    return (f"the entries mix {len(mixed)} irrational numbers ({', '.join(map(str, mixed))}) "
            f"> Limits.max_exact_irrationals = {limits().max_exact_irrationals}: exact terms in "
            "them can take SymPy minutes and be unreadable; the numeric engines serve the "
            "scene (method='exact' still builds them)")


def irrational_numbers(scene: Scene) -> list[sp.Expr]:
    """The distinct irrational numbers the entries of M, C and K are built from: π, e,
    and each radical (√5 and ∛2, not √5 − 1 and √5/2), by name.

    >>> from laplace_springs.model.scene import Scene
    >>> irrational_numbers(Scene.from_matrices(M=[[sp.sqrt(5) - 1]], C=[[sp.E]],
    ...                                        K=[[sp.sqrt(5) * sp.pi]], x0=[1], v0=[0]))
    [E, pi, sqrt(5)]
    """
    found: set[sp.Expr] = set()
    for matrix in (scene.M, scene.C, scene.K):
        for entry in matrix.values():
            if entry.is_number and not entry.is_Rational:
                found |= {a for a in entry.atoms(sp.NumberSymbol, sp.Pow, sp.Function)
                          if not a.is_Rational and (not a.is_Pow or not a.exp.is_Integer)}
    return sorted(found, key=str)


def _refusal(scene: Scene) -> str | None:
    """:func:`exact_refusal`, computed."""
    n = scene.n
    if n > limits().max_exact_coordinates:
        return (
            f"the exact route takes at most Limits.max_exact_coordinates = {limits().max_exact_coordinates} "
            f"coordinates (its exact adjugate costs about n**4: 30 coordinates take 14 s); "
            f"this scene has {n}. The numeric routes (method='modal' or 'certified') take "
            "larger free numeric scenes, within their own limits")
    if free_rational(scene):
        return None  # named roots: exact terms at any degree and size (exact/named_roots.py)
    symbols = set().union(*(m.free_symbols for m in (scene.M, scene.C, scene.K)))
    if 2 * n <= limits().max_exact_factor_degree and symbols:
        return None  # no factor of Δ can be too large; symbolic ones are sums over roots
    everything = set(scene.free_symbols)  # with those of x0, v0 and the forcing
    entries = [e for m in (scene.M, scene.C, scene.K, scene.x0, scene.v0) for e in m]
    if everything and not all(e.is_rational_function(*everything) for e in entries):
        return None
    point = generic_values(everything) if everything else {}
    pencil = rational_pencil(scene, point)
    vectors = _right_hand_sides(scene, pencil, point) if pencil is not None else None
    found = solve_at_integers(pencil, vectors) if pencil is not None and vectors is not None else None
    if found is None:
        return None
    delta, pieces = found
    _, factors = delta.factor()
    staying = [f for f, _ in factors
               if f.degree() >= 3 and any(N % f != 0 for numerators in pieces for N in numerators)]
    stays = [f.degree() for f in staying if f.degree() > limits().max_exact_factor_degree]
    if not stays:
        return None if symbols else _isolation_refusal(scene, staying)
    if not symbols:
        way = ("ls.solve(scene) (method='exo': the inputs' own dynamics joined to the scene)"
               if scene.is_forced else "ls.solve(scene, method='modal') or method='certified'")
        return (
            f"Δ(λ) = det(λ²M + λC + K) has an irreducible factor of degree {max(stays)} > "
            f"Limits.max_exact_factor_degree = {limits().max_exact_factor_degree}: exact terms cost about the "
            "fourth power of the degree (degree 24: 1.2 s per coordinate, 40: 10 s); the "
            f"numeric routes evaluate any degree: {way}")
    names = ", ".join(sorted(symbol.name for symbol in symbols))
    largest = max(stays)
    shown = f"{largest}" if largest == 2 * n else f"at least {largest}"
    return (
        f"Δ(λ) = det(λ²M + λC + K) has an irreducible factor of degree {shown} "
        f"> Limits.max_exact_factor_degree = {limits().max_exact_factor_degree} (seen at "
        f"generic values of {names}): too large for exact terms whether its coefficients "
        f"are symbolic or not; substitute numbers for {names} and use the numeric routes "
        "(method='modal' or 'certified'), which evaluate any degree")


def _isolation_refusal(scene: Scene, factors: list[flint.fmpq_poly]) -> str | None:
    """Why SymPy cannot number the roots of one of these factors of Δ(λ) in reasonable
    time (:func:`~laplace_springs.exact.partial_fractions.isolation_obstacle`), naming
    the scene's smallest and largest entries; None when it can."""
    for f in factors:
        coeffs = [sp.Rational(int(c.p), int(c.q)) for c in reversed(f.coeffs())]
        why = isolation_obstacle(coeffs, cause=_extreme_entries(scene))
        if why is not None:
            return f"Δ(λ) = det(λ²M + λC + K) has an {why}"
    return None


def _extreme_entries(scene: Scene) -> str:
    """'M[0,0] = 1e-300 and K[0,0] = 2 are entries of this scene': its smallest and
    largest nonzero entries of M, C and K in size."""
    found = [(abs(value), f"{name}[{i},{j}] = {float(value):.3g}")
             for name, matrix in (("M", scene.M), ("C", scene.C), ("K", scene.K))
             for i in range(matrix.rows) for j in range(matrix.cols)
             if (value := matrix[i, j]) != 0 and value.is_number]
    if not found:
        return "the scene's entries"
    smallest = min(found, key=lambda entry: entry[0])[1]
    largest = max(found, key=lambda entry: entry[0])[1]
    return f"{smallest} and {largest} are entries of this scene"


def has_exact_form(scene: Scene) -> bool:
    """Whether ``x`` of a solution of ``scene`` is its exact closed form on every route: up
    to Limits.exact_form_max_coordinates coordinates, or Limits.exact_named_form_max_coordinates
    for a free scene with rational entries (named numbers), or any size with symbols.

    >>> has_exact_form(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    True
    """
    if scene.n <= limits().exact_form_max_coordinates or scene.free_symbols:
        return True
    return scene.n <= limits().exact_named_form_max_coordinates and free_rational(scene)
