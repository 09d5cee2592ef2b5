"""The stiff-and-extreme battery: scenes on which naive float64 evaluation loses digits.

Each :class:`BatteryCase` is a numeric, unforced scene with the times at which it is
checked. The test suite (``tests/bench/test_battery.py``) compares the default float64
``Solution.evaluate`` with a certified ≥ 40-digit reference (the arb matrix exponential
of the first-order system) and asserts an error within 1e-12 of max |x| over the
case's times; the bench measures every method on the same cases.

Every time is a decimal string whose value is exactly a binary64 number (a dyadic
rational written out in full), so float64 evaluation and a decimal reference agree on
the instant: at t = 1e4 a time rounded to binary64 alone would move a unit-frequency
oscillation by up to 1e-12.

Kinds: ``critical``, ``near-critical``, ``separated-real``, ``defective``,
``near-defective``, ``rigid-body``, ``stiffness-ratio``, ``mass-ratio``,
``heavy-damping``, ``light-damping``, ``symmetric``, ``close-frequencies``,
``near-resonance`` (forcing near a natural frequency, the forcing written as an extra
oscillator state so that the scene stays unforced), ``chain`` and ``massless`` (zero
masses held by dashpots: Maxwell and Kelvin-Voigt elements, in :func:`_massless`).

Examples
--------
>>> cases = battery_cases()
>>> len(cases) >= 20
True
>>> case = next(c for c in cases if c.name == "near-critical-above-1e-14")
>>> case.kind, case.scene.n, case.times[:3]
('near-critical', 1, ('0', '1.25', '2.5'))
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from decimal import Decimal

from ..model.scene import Scene

__all__ = ["KINDS", "BatteryCase", "battery_cases"]

#: The kinds of case, in the order of issue 3 item 1.
KINDS = ("critical", "near-critical", "separated-real", "defective", "near-defective",
         "rigid-body", "stiffness-ratio", "mass-ratio", "heavy-damping", "light-damping",
         "symmetric", "close-frequencies", "near-resonance", "chain", "massless")


@dataclass(frozen=True)
class BatteryCase:
    """One battery scene and the times it is checked at.

    Attributes
    ----------
    name : str
        A slug, e.g. ``"near-critical-above-1e-14"``.
    kind : str
        One of :data:`KINDS`.
    description : str
        What makes the case hard.
    scene : Scene
        A numeric, unforced scene with exact (rational) entries.
    times : tuple of str
        Decimal strings, each exactly a binary64 number, in increasing order.
    """

    name: str
    kind: str
    description: str
    scene: Scene
    times: tuple[str, ...]


# ----------------------------------------------------------------------------- times


def _exact(value: float) -> str:
    """The exact decimal expansion of a binary64 number (no exponent for moderate sizes)."""
    text = format(Decimal(value), "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return text or "0"


def _times(stop: float, count: int = 32, *, logs: Iterable[int] = ()) -> tuple[str, ...]:
    """0, h, 2h, ..., count·h plus 2**e for e in logs, with h = stop/count.

    When stop/count is not a short dyadic number (0.04/32) it is rounded down to 8
    significant bits, so every grid point is exact in binary64.
    """
    step = stop / count
    if math.frexp(step)[0] * 2**20 % 1:
        step = _dyadic(step)
    values = {step * k for k in range(count + 1)} | {2.0 ** e for e in logs}
    return tuple(_exact(v) for v in sorted(values))


def _dyadic(value: float) -> float:
    """``value`` rounded down to 8 significant bits (an exactly representable step)."""
    mantissa, exponent = math.frexp(value)
    return math.ldexp(int(mantissa * 256) / 256, exponent)


# ----------------------------------------------------------------------------- builders


def _single(m: str, c: str, k: str, x0: str = "1", v0: str = "0", title: str = "") -> Scene:
    return Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[x0], v0=[v0], title=title)


def _chain(masses: list[str], springs: list[str], dashpots: list[str] | None = None,
           *, x0: list[str] | None = None, v0: list[str] | None = None,
           left_wall: bool = True, right_wall: bool = True, title: str = "") -> Scene:
    """Masses in a line; ``springs`` (and ``dashpots``) run wall-m1, m1-m2, ..., mn-wall.

    Without a wall on a side the first (last) entry of springs/dashpots is dropped.
    """
    n = len(masses)
    names = [f"m{i + 1}" for i in range(n)]
    nodes = (["wall"] if left_wall else []) + names + (["wall"] if right_wall else [])
    links = list(zip(nodes, nodes[1:]))
    springs_map = {f"k{i + 1}": (a, b, v) for i, ((a, b), v) in enumerate(zip(links, springs))
                   if v != "0"}
    dash_map = {f"c{i + 1}": (a, b, v) for i, ((a, b), v) in enumerate(zip(links, dashpots or []))
                if v != "0"}
    return Scene.from_components(
        masses=dict(zip(names, masses)), springs=springs_map, dashpots=dash_map,
        x0=x0 or ["1"] + ["0"] * (n - 1), v0=v0 or ["0"] * n, title=title)


def _ring(count: int, spring: str, ground: str, damping: str = "0", *,
          x0: list[str], v0: list[str] | None = None) -> Scene:
    """``count`` unit masses on a ring, each also grounded: degenerate pairs of modes."""
    names = [f"m{i + 1}" for i in range(count)]
    springs = {f"k{i + 1}": (names[i], names[(i + 1) % count], spring) for i in range(count)}
    springs.update({f"g{i + 1}": ("wall", names[i], ground) for i in range(count)})
    dashpots = {}
    if damping != "0":
        dashpots = {f"c{i + 1}": ("wall", names[i], damping) for i in range(count)}
    return Scene.from_components(masses=dict.fromkeys(names, "1"), springs=springs,
                                 dashpots=dashpots, x0=x0, v0=v0 or ["0"] * count)


# ----------------------------------------------------------------------------- cases


def _critical() -> list[BatteryCase]:
    return [
        BatteryCase("critical-unit", "critical",
                    "x'' + 2x' + x = 0: a double real pole, (1 + t)e^{-t}; eigenvector "
                    "routes give 0.96 relative error",
                    _single("1", "2", "1", "1", "0"), _times(40)),
        BatteryCase("critical-fast", "critical",
                    "critically damped at ω = 1e3 (c = 2e3, k = 1e6) with an opposing "
                    "initial velocity: an overshoot through zero",
                    _single("1", "2000", "1000000", "1", "-5000"), _times(0.04)),
        BatteryCase("critical-two-mass", "critical",
                    "two equal masses, springs and dashpots tuned so that both modes are "
                    "critically damped: double poles -1 and -2",
                    _chain(["1", "1"], ["1", "3/2", "1"], ["2", "1", "2"],
                           x0=["1", "0"], v0=["0", "1"]),
                    _times(30)),
    ]


def _near_critical() -> list[BatteryCase]:
    out = []
    for label, c in (("below-1e-14", "1.99999999999998"), ("above-1e-14", "2.00000000000002"),
                     ("below-1e-8", "1.99999998"), ("above-1e-8", "2.00000002")):
        out.append(BatteryCase(
            f"near-critical-{label}", "near-critical",
            f"x'' + {c}x' + x = 0: |ζ - 1| = {label.split('-', 1)[1]}, a pair of roots "
            "split by 2·sqrt(2|ζ-1|); partial fractions in float64 lose ~1e-10",
            _single("1", c, "1", "1", "0"), _times(40)))
    return out


def _separated_real() -> list[BatteryCase]:
    return [
        BatteryCase("separated-real-c1e6", "separated-real",
                    "m = 1, c = 1e6, k = 1: roots -1e-6 and -1e6; the naive quadratic "
                    "formula gives the slow root with 7.6e-6 error; t up to 1e6",
                    _single("1", "1000000", "1", "1", "0"),
                    _times(1e6, 32, logs=range(-24, 20, 2))),
        BatteryCase("separated-real-velocity", "separated-real",
                    "m = 1, c = 1e6, k = 1 started by a velocity: a fast rise (1e-6 s) "
                    "and a slow creep back (1e6 s)",
                    _single("1", "1000000", "1", "0", "1"),
                    _times(1e6, 32, logs=range(-24, 20, 2))),
    ]


def _defective() -> list[BatteryCase]:
    ep = Scene.from_components(
        masses={"m1": "1", "m2": "1"},
        springs={"k1": ("wall", "m1", "1"), "k2": ("m1", "m2", "1")},
        dashpots={"c1": ("wall", "m1", "2")}, x0=[1, 0], v0=[0, 0])
    near = Scene.from_components(
        masses={"m1": "1", "m2": "1"},
        springs={"k1": ("wall", "m1", "1"), "k2": ("m1", "m2", "1")},
        dashpots={"c1": ("wall", "m1", "2.0000000002")}, x0=[1, 0], v0=[0, 0])
    jordan = Scene.from_normalized(A=[["1", "1"], ["0", "1"]], B=[["1/5", "0"], ["0", "1/5"]],
                                   x0=["0", "1"], v0=["1", "0"])
    return [
        BatteryCase("exceptional-point", "defective",
                    "wall-k1-m1-k2-m2 with a dashpot c = 2 on m1: Δ(λ) = (λ² + λ + 1)², a "
                    "defective complex pair (an exceptional point), t·e^{-t/2} cos terms",
                    ep, _times(60)),
        BatteryCase("jordan-nonsymmetric", "defective",
                    "x'' + x'/5 + [[1, 1], [0, 1]]x = 0: a Jordan block at a lightly "
                    "damped complex pair, secular growth t·e^{-t/10}",
                    jordan, _times(100)),
        BatteryCase("near-exceptional-point", "near-defective",
                    "the exceptional point with c = 2 + 2e-10: two complex pairs 1e-5 "
                    "apart, residues of size 1e5 that cancel",
                    near, _times(60)),
    ]


def _rigid_body() -> list[BatteryCase]:
    return [
        BatteryCase("free-free-chain", "rigid-body",
                    "three masses joined by springs, no walls, net momentum: a double "
                    "pole at 0 (drift a + b·t) beside the vibration",
                    _chain(["1", "2", "1"], ["1", "1"], left_wall=False, right_wall=False,
                           x0=["1", "0", "0"], v0=["1", "0", "0"]), _times(100)),
        BatteryCase("free-body-dashpot", "rigid-body",
                    "one free mass with only a dashpot to the wall: poles 0 and -c/m",
                    Scene.from_components(masses={"m1": "1"},
                                          dashpots={"c1": ("wall", "m1", "1/1000")},
                                          x0=["0"], v0=["1"]),
                    _times(1e4, 32, logs=range(-10, 13, 2))),
        BatteryCase("free-body-slow-dashpot", "rigid-body",
                    "a free mass with a 1e-6 dashpot, looked at for t ≤ 1: "
                    "x = (1 - e^{-ct})/c from residues ±1e6 that cancel",
                    Scene.from_components(masses={"m1": "1"},
                                          dashpots={"c1": ("wall", "m1", "0.000001")},
                                          x0=["0"], v0=["1"]),
                    _times(1, 32, logs=range(-30, 0, 3))),
        BatteryCase("free-free-damped", "rigid-body",
                    "free-free chain with dashpots between the masses: a rigid drift "
                    "plus decaying internal modes",
                    _chain(["1", "1", "1", "1"], ["1", "2", "1"], ["1/10", "0", "1/10"],
                           left_wall=False, right_wall=False,
                           x0=["1", "0", "0", "-1"], v0=["1", "0", "0", "0"]), _times(200)),
    ]


def _ratios() -> list[BatteryCase]:
    return [
        BatteryCase("stiffness-ratio-1e8", "stiffness-ratio",
                    "wall-1e8-m1-1-m2-wall: frequencies near 1e4 and 1, phases ωt up to 1e6",
                    _chain(["1", "1"], ["100000000", "1", "1"], ["0", "1/100", "0"],
                           x0=["1/10000", "1"], v0=["1", "0"]), _times(100, 64)),
        BatteryCase("mass-ratio-1e-6", "mass-ratio",
                    "a 1e-6 mass hanging off a unit mass: one mode near 1e3 rad/s",
                    _chain(["1", "0.000001"], ["1", "1", "0"], ["0", "1/1000000000", "0"],
                           right_wall=True, x0=["1", "0"], v0=["0", "1"]), _times(50, 64)),
        BatteryCase("heavy-damping-1e6", "heavy-damping",
                    "two masses joined by a 1e6 dashpot, springs to both walls: one pole "
                    "near -2e6, the rest slow; t up to 1e6",
                    _chain(["1", "1"], ["1", "0", "1"], ["0", "1000000", "0"],
                           x0=["1", "0"], v0=["0", "1"]),
                    _times(1e6, 32, logs=range(-24, 20, 2))),
        BatteryCase("light-damping-1e-6", "light-damping",
                    "x'' + 1e-6 x' + x = 0 over 1e4 time units: phase ωt = 1e4",
                    _single("1", "0.000001", "1", "1", "0"), _times(1e4, 64)),
        BatteryCase("light-damping-pair", "light-damping",
                    "two-mass chain, dashpot 1e-6 on one wall, over 1e4 time units",
                    _chain(["1", "2"], ["1", "3", "2"], ["0.000001", "0", "0"],
                           x0=["1", "0"], v0=["0", "1"]), _times(1e4, 64)),
    ]


def _symmetric() -> list[BatteryCase]:
    return [
        BatteryCase("ring-of-four", "symmetric",
                    "four unit masses on a ring of springs, each grounded: eigenvalues "
                    "1, 3, 3, 5, a double but non-defective pair (no secular terms)",
                    _ring(4, "1", "1", x0=["1", "0", "0", "0"], v0=["0", "1", "0", "0"]),
                    _times(100)),
        BatteryCase("ring-of-three-damped", "symmetric",
                    "three grounded masses on a ring with equal dashpots: a double damped "
                    "complex pair from the symmetry",
                    _ring(3, "1", "1", "1/10", x0=["1", "0", "0"], v0=["0", "0", "1"]),
                    _times(100)),
        BatteryCase("weakly-coupled-1e-8", "close-frequencies",
                    "two unit oscillators coupled by a 1e-8 spring: frequencies 1e-8 "
                    "apart, a slow beat over 1e4 time units",
                    _chain(["1", "1"], ["1", "0.00000001", "1"], x0=["1", "0"]),
                    _times(1e4, 64)),
    ]


def _resonance(c: str, omega_squared: str) -> Scene:
    """x'' + c x' + x = u with u'' + ω² u = 0, u(0) = 1: forcing cos ωt as an extra state.

    The transform of x has the forced response's poles (±iω beside the natural pair)
    and partial fractions with 1/(1 - ω²) coefficients, yet the scene stays unforced,
    so the arb matrix exponential remains an independent reference.
    """
    return Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[c, 0], [0, 0]],
                               K=[["1", "-1"], ["0", omega_squared]],
                               x0=["0", "1"], v0=["0", "0"], names=("x", "u"))


def _near_resonance() -> list[BatteryCase]:
    near = "1.0000000200000001"  # ω = 1 + 1e-8
    return [
        BatteryCase("near-resonance-1e-8", "near-resonance",
                    "x'' + x = cos ωt, ω = 1 + 1e-8 (forcing as an extra oscillator): "
                    "(cos ωt - cos t)/(1 - ω²) with 5e7 coefficients, t up to 1e4",
                    _resonance("0", near), _times(1e4, 64)),
        BatteryCase("resonance-light-damping-1e-6", "near-resonance",
                    "x'' + 1e-6 x' + x = cos t: exact resonance with light damping, "
                    "poles 5e-7 apart, growth t/2 over 1e4 time units",
                    _resonance("0.000001", "1"), _times(1e4, 64)),
        BatteryCase("near-resonance-damped", "near-resonance",
                    "x'' + 1e-6 x' + x = cos ωt, ω = 1 + 1e-8: both effects at once",
                    _resonance("0.000001", near), _times(1e4, 64)),
        BatteryCase("resonance-exact", "near-resonance",
                    "x'' + x = cos t: a defective pair ±i, secular t·sin t over 1e4",
                    _resonance("0", "1"), _times(1e4, 64)),
    ]


def _chains(large: bool) -> list[BatteryCase]:
    def chain(n: int, damping: str) -> Scene:
        masses = [str(1 + (i % 3)) for i in range(n)]
        return _chain(masses, ["1"] * (n + 1), [damping] + ["0"] * (n - 1) + [damping],
                      x0=["1"] + ["0"] * (n - 1), v0=["0"] * (n - 1) + ["1"])

    out = [
        BatteryCase("chain-8-damped", "chain",
                    "eight masses (1, 2, 3, ...) between walls, dashpots 1/10 at the ends",
                    chain(8, "1/10"), _times(100)),
        BatteryCase("chain-8-undamped", "chain",
                    "eight masses between walls, no damping: sixteen imaginary poles",
                    chain(8, "0"), _times(100)),
    ]
    if large:
        out += [BatteryCase(f"chain-{n}-damped", "chain",
                            f"{n} masses between walls, dashpots 1/10 at the ends",
                            chain(n, "1/10"), _times(100)) for n in (20, 50)]
    return out


def _massless() -> list[BatteryCase]:
    """Massless nodes held by dashpots (Maxwell elements): deg Δ < 2n, x' jumps at 0⁺."""
    zener_fast = Scene.from_components(
        masses={"m": "1", "n": "0"},
        springs={"k1": ("wall", "m", "1"), "k2": ("wall", "n", "10000")},
        dashpots={"c": ("n", "m", "1")}, x0=["1", "0"], v0=["0", "0"])
    zener_slow = Scene.from_components(
        masses={"m": "1", "n": "0"},
        springs={"k1": ("wall", "m", "1"), "k2": ("wall", "n", "3")},
        dashpots={"c": ("n", "m", "1000000")}, x0=["0", "0"], v0=["1", "5"])
    kelvin = Scene.from_components(
        masses={"a": "0", "b": "0", "m": "1/1000"},
        springs={"k1": ("wall", "a", "1"), "k2": ("a", "b", "1"), "k3": ("b", "m", "1")},
        dashpots={"c1": ("wall", "a", "10000"), "c2": ("a", "b", "1/10000")},
        x0=["1", "-1", "0"], v0=["0", "0", "0"])
    return [
        BatteryCase("maxwell-fast-relaxation", "massless",
                    "a unit mass on a standard linear solid (wall spring 1, Maxwell arm "
                    "k = 1e4, c = 1): relaxation time 1e-4 beside a unit oscillation",
                    zener_fast, _times(20, 32, logs=range(-20, 0, 2))),
        BatteryCase("maxwell-stiff-dashpot", "massless",
                    "standard linear solid with c = 1e6: almost elastic, the Maxwell arm "
                    "relaxes over ~3e5 time units; the node's v0 is ignored (it jumps)",
                    zener_slow, _times(1e4, 64, logs=range(-10, 20, 3))),
        BatteryCase("kelvin-chain-separated", "massless",
                    "two massless Kelvin-Voigt stages (c = 1e4 and 1e-4) and a light mass "
                    "1e-3: retardation times 1e4 and 1e-4 beside a fast oscillation",
                    kelvin, _times(1e4, 32, logs=range(-16, 14, 2))),
    ]


_GROUPS: tuple[Callable[[], list[BatteryCase]], ...] = (
    _critical, _near_critical, _separated_real, _defective, _rigid_body, _ratios,
    _symmetric, _near_resonance, _massless)


def battery_cases(*, large: bool = False) -> tuple[BatteryCase, ...]:
    """The battery, in the order of :data:`KINDS`.

    Parameters
    ----------
    large : bool
        Also include chains of 20 and 50 masses (for the modal and certified routes).

    Returns
    -------
    tuple of BatteryCase
    """
    cases = [case for group in _GROUPS for case in group()] + _chains(large)
    return tuple(cases)
