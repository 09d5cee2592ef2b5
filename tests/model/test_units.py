"""Physical units (issue 25): entries with units, exact conversion, dimension checks, answers.

References share no code with the conversion under test: every factor is stated here from
the SI definitions (the international inch is 0.0254 m and the pound 0.45359237 kg since
1959, standard gravity 9.80665 m/s² by the 3rd CGPM, the dyne 1e-5 N), and every scene
written in units is compared with the same scene written in SI by hand.
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.cli import main
from laplace_springs.model.errors import SceneError
from laplace_springs.model.units import (
    attach_units,
    axis_label,
    exact_rational,
    frequencies_to_rad_per_second,
    in_length_unit,
    parse_unit,
    read_scene_units,
    times_to_seconds,
)

pint = pytest.importorskip("pint")
Q_ = pint.get_application_registry().Quantity

INCH = Fraction("0.0254")
POUND = Fraction("0.45359237")
G0 = Fraction("9.80665")

#: Every unit the module documents, with its SI factor from the definitions.
FACTORS = {
    # mass (kg)
    "kg": 1, "g": Fraction(1, 1000), "mg": Fraction(1, 10**6), "t": 1000, "lb": POUND,
    # length (m)
    "m": 1, "cm": Fraction(1, 100), "mm": Fraction(1, 1000), "km": 1000, "µm": Fraction(1, 10**6),
    "um": Fraction(1, 10**6), "in": INCH, "ft": 12 * INCH,
    # time (s)
    "s": 1, "ms": Fraction(1, 1000), "min": 60, "h": 3600,
    # force (N)
    "N": 1, "kN": 1000, "mN": Fraction(1, 1000), "dyn": Fraction(1, 10**5), "lbf": POUND * G0,
    # stiffness (N/m)
    "N/m": 1, "N/cm": 100, "N/mm": 1000, "kN/m": 1000, "lbf/in": POUND * G0 / INCH,
    # damping (N s/m)
    "N*s/m": 1, "N·s/m": 1, "N s/m": 1, "kg/s": 1,
    # velocity (m/s)
    "m/s": 1, "cm/s": Fraction(1, 100), "km/h": Fraction(1000, 3600),
    # frequency, 1/s (cycles are counted apart: see test_hertz_is_a_cycle_per_second)
    "rad/s": 1, "1/s": 1, "Hz": 1, "kHz": 1000,
}


@pytest.mark.parametrize("text", sorted(FACTORS))
def test_every_documented_unit_converts_exactly_to_si(text):
    unit = parse_unit(text)
    assert unit.factor == sp.Rational(FACTORS[text])
    assert unit.factor.is_Rational


def test_definitions_read_back_exactly():
    # the scales pint stores as floats: 1/36 (inch = yard/36), 0.9144 (yard), 64.79891 (grain)
    assert exact_rational(1 / 36) == Fraction(1, 36)
    assert exact_rational(0.9144) == Fraction(1143, 1250)
    assert exact_rational(64.79891) == Fraction(6479891, 100000)
    assert exact_rational(1e-6) == Fraction(1, 10**6)
    assert exact_rational(7) == 7


def test_hertz_is_a_cycle_per_second():
    assert parse_unit("Hz").cycles == 1 and parse_unit("rad/s").cycles == 0
    omegas = frequencies_to_rad_per_second(["1 Hz", "2 rad/s", "60 rpm", "0.5 kHz", 3.0])
    assert omegas == pytest.approx([2 * math.pi, 2.0, 2 * math.pi, 1000 * math.pi, 3.0], rel=1e-15)


def test_random_decimals_convert_exactly():
    rng = random.Random(25)
    for _ in range(200):
        text = rng.choice(["g", "cm", "N/cm", "kN/m", "lb", "in", "ms", "mN"])
        digits = f"{rng.randint(1, 10**9)}e{rng.randint(-12, 6)}"
        kind = parse_unit(text)
        inputs, record = read_scene_units("matrices", {"M": [[f"{digits} {text}" if kind.dimensions ==
                                                             (("[mass]", 1),) else "1 kg"]]}, {})
        if kind.dimensions == (("[mass]", 1),):
            assert inputs["M"][0][0] == sp.Rational(Fraction(digits) * Fraction(FACTORS[text]))


# --- scenes in units against the same scenes in SI ------------------------------------------


def seed_test_in_units(**changes):
    """The seed's Example 5 undamped test, as the seed states it."""
    arguments = {"masses": {"m1": "1 kg", "m2": "0.5 kg"},
                 "springs": {"k1": ("wall", "m1", "200 N/m"), "k2": ("m1", "m2", "150 N/m"),
                             "k3": ("m2", "wall", "300 N/m")},
                 "x0": ["5 cm", "3 cm"], "v0": ["2 m/s", "1 m/s"]}
    arguments.update(changes)
    return ls.Scene.from_components(**arguments)


SEED_TEST_SI = {"masses": {"m1": 1, "m2": "1/2"},
                "springs": {"k1": ("wall", "m1", 200), "k2": ("m1", "m2", 150), "k3": ("m2", "wall", 300)},
                "x0": ["1/20", "3/100"], "v0": [2, 1]}


def same_scene(a, b):
    for field in ("M", "C", "K", "x0", "v0"):
        assert getattr(a, field) == getattr(b, field), field
    assert (a.forcing is None and b.forcing is None) or a.forcing == b.forcing


def test_seed_example5_in_its_units_equals_the_scene_in_si():
    units, si = seed_test_in_units(), ls.Scene.from_components(**SEED_TEST_SI)
    same_scene(units, si)
    assert ls.solve(units).x == ls.solve(si).x  # identical exact solutions
    times = [0.0, 0.4, 4.0]
    assert np.array_equal(ls.solve(units).evaluate(times), ls.solve(si).evaluate(times))


def test_the_same_scene_in_other_units_is_the_same_scene():
    other = seed_test_in_units(masses={"m1": "1000 g", "m2": "500 g"},
                               springs={"k1": ("wall", "m1", "2 N/cm"), "k2": ("m1", "m2", "0.15 kN/m"),
                                        "k3": ("m2", "wall", "3 N/cm")},
                               x0=["50 mm", "0.03 m"], v0=["200 cm/s", "3.6 km/h"])
    same_scene(other, ls.Scene.from_components(**SEED_TEST_SI))


def test_the_seeds_damped_example5_written_in_cm_gives_the_same_closed_form():
    # Mathematica's values (units of N, N/m, m, kg, m/s), displacements written in cm
    units = ls.Scene.from_components(
        masses={"m1": "1 kg", "m2": "800 g"},
        springs={"k1": ("wall", "m1", "400 N/m"), "k2": ("m1", "m2", "3.79 N/cm"), "k3": ("m2", "wall", "100 N/m")},
        dashpots={"mu1": ("wall", "m1", "0.5 N*s/m"), "mu2": ("m1", "m2", "1.4 kg/s"),
                  "mu3": ("m2", "wall", "0.9 N·s/m")},
        x0=["5 cm", "7 cm"], v0=["3 m/s", "2 m/s"])
    si = ls.load_scene("three-dashpots")
    same_scene(units, si)
    assert ls.solve(units, method="exact").x == ls.solve(si, method="exact").x


def test_matrices_and_normalized_forms_take_units():
    units = ls.Scene.from_matrices(M=[["2 kg", 0], [0, "500 g"]], C=[["0.2 N*s/m", 0], [0, 0]],
                                   K=[["3 N/m", "-1 N/m"], ["-1 N/m", "1 N/m"]],
                                   x0=["1 cm", 0], v0=[0, "1 cm/s"], forcing=["10*cos(3*t) mN", 0])
    si = ls.Scene.from_matrices(M=[[2, 0], [0, "1/2"]], C=[["1/5", 0], [0, 0]], K=[[3, -1], [-1, 1]],
                                x0=["1/100", 0], v0=[0, "1/100"], forcing=["cos(3*t)/100", 0])
    same_scene(units, si)
    normal = ls.Scene.from_normalized(A=[["3 1/s**2", "-1 1/s**2"], ["-2 1/s**2", "2 1/s^2"]],
                                      B=[["0.2 1/s", 0], [0, "0.2 1/s"]], x0=["1 m", 0], v0=[0, 0],
                                      forcing=["2 m/s**2", 0])
    assert normal.K.tolist() == [[3, -1], [-2, 2]] and normal.forcing[0] == 2
    assert normal.units.forcing == "acceleration"


def test_quantities_are_accepted():
    scene = seed_test_in_units(masses={"m1": Q_(1, "kg"), "m2": Q_(500, "g")},
                               x0=Q_(np.array([5, 3]), "cm"), v0=[Q_(2, "m/s"), Q_(Fraction(1), "m/s")])
    same_scene(scene, ls.Scene.from_components(**SEED_TEST_SI))
    matrix = ls.Scene.from_matrices(M=Q_(np.diag([1.0, 0.5]), "kg"), K=Q_(np.array([[350, -150], [-150, 450]]), "N/m"),
                                    x0=Q_([5, 3], "cm"), v0=Q_([2, 1], "m/s"))
    same_scene(matrix, ls.Scene.from_components(**SEED_TEST_SI))


def test_forcing_and_support_motion_in_units():
    scene = ls.Scene.from_components(masses={"m": "2 kg"}, springs={"k": ("ground", "m", "8 N/m")},
                                     x0=[0], v0=[0], forcing=["10*cos(3*t) kN"],
                                     support_motion={"ground": "sin(3*t) cm"})
    t = ls.t
    assert scene.forcing[0] == 10000 * sp.cos(3 * t) + 8 * sp.sin(3 * t) / 100
    assert scene.support_motion == (("ground", sp.sin(3 * t) / 100),)


def test_scene_files_with_units(tmp_path):
    path = tmp_path / "units.toml"
    path.write_text('[masses]\nm1 = "1 kg"\nm2 = "500 g"\n[springs]\nk1 = ["wall", "m1", "2 N/cm"]\n'
                    'k2 = ["m1", "m2", "150 N/m"]\nk3 = ["m2", "wall", "300 N/m"]\n'
                    '[initial]\nx0 = ["5 cm", "30 mm"]\nv0 = ["2 m/s", "1 m/s"]\n'
                    '[forcing]\nm1 = "cos(t) N"\n', encoding="utf-8")
    scene = ls.load_scene(path)
    same_scene(scene, ls.Scene.from_components(**SEED_TEST_SI, forcing=["cos(t)", 0]))
    bundled = ls.load_scene("example5-in-units")
    same_scene(bundled, ls.Scene.from_components(**SEED_TEST_SI))


def test_declared_si_takes_bare_numbers():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=["5 cm"], v0=[0], units="SI")
    assert scene.x0[0] == sp.Rational(1, 20) and scene.units.declared == "SI"
    assert axis_label("position", scene) == "Position (m)"
    with pytest.raises(SceneError, match="units must be None"):
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0], units="imperial")


def test_a_scene_without_units_is_read_as_before():
    inputs = {"M": [[1, 0], [0, "1/2"]], "x0": ["0.05", 0], "v0": np.array([1.0, 2.0])}
    given, record = read_scene_units("matrices", inputs, {})
    assert record is None and all(given[key] is inputs[key] for key in inputs)
    scene = ls.Scene.from_components(**SEED_TEST_SI)
    assert scene.units is None
    with pytest.raises(SceneError, match="unexpected 'kg'|unknown name 'kg'"):
        ls.Scene.from_matrices(M=[["1 * kg"]], x0=[0], v0=[0])


# --- dimension mistakes --------------------------------------------------------------------


@pytest.mark.parametrize("changes, fragments", [
    ({"masses": {"m1": "1 N/m", "m2": "0.5 kg"}},
     ["mass 'm1'", "'1 N/m'", "[mass] / [time] ** 2", "expected a mass, [mass]"]),
    ({"springs": {"k1": ("wall", "m1", "2 kg"), "k2": ("m1", "m2", "150 N/m"), "k3": ("m2", "wall", "300 N/m")}},
     ["spring 'k1'", "'2 kg'", "dimension [mass] ", "expected a stiffness, [mass] / [time] ** 2"]),
    ({"x0": ["5 s", "3 cm"]}, ["x0[0]", "'5 s'", "dimension [time]", "expected a length, [length]"]),
    ({"v0": ["2 m", "1 m/s"]}, ["v0[0]", "'2 m'", "dimension [length] ", "expected a velocity"]),
    ({"forcing": ["10*cos(3*t) m", 0]}, ["forcing[0]", "'10*cos(3*t) m'", "dimension [length]", "expected a force"]),
    ({"x0": [0.05, "3 cm"]}, ["x0[0]", "0.05", "no unit (dimension found: none)", "expected a length"]),
    ({"masses": {"m1": 1, "m2": "0.5 kg"}}, ["mass 'm1'", "1 has no unit", "expected a mass"]),
    ({"x0": ["5 cm", "3 apples"]}, ["x0[1]", "'3 apples'", "unit 'apples'"]),
    ({"x0": ["5 degC", "3 cm"]}, ["x0[0]", "offset"]),
    ({"x0": ["5 cm**20", "3 cm"]}, ["x0[0]", "exponent"]),
    ({"x0": ["5 __import__('os')", "3 cm"]}, ["x0[0]", "a unit is letters"]),
    ({"dashpots": {"c": ("m1", "m2", "1.4 N/m")}}, ["dashpot 'c'", "'1.4 N/m'", "expected a damping"]),
])
def test_dimension_mistakes_name_the_entry_value_and_dimensions(changes, fragments):
    with pytest.raises(SceneError) as caught:
        seed_test_in_units(**changes)
    for fragment in fragments:
        assert fragment in str(caught.value), (fragment, str(caught.value))


def test_zero_and_parameters_need_no_unit():
    scene = seed_test_in_units(x0=["5 cm", 0], v0=[0, "0"])
    assert scene.x0[1] == 0 and scene.v0[0] == 0
    symbolic = seed_test_in_units(springs={"k1": ("wall", "m1", "k"), "k2": ("m1", "m2", "150 N/m"),
                                           "k3": ("m2", "wall", "300 N/m")}, parameters=["k"])
    assert dict(symbolic.units.parameters)["k"] == (("[mass]", 1), ("[time]", -2))
    assert symbolic.subs({"k": "2 N/cm"}).K == seed_test_in_units().K
    with pytest.raises(SceneError, match=r"parameter 'k': '200' has no unit .* expected a stiffness"):
        symbolic.subs({"k": "200"})
    with pytest.raises(SceneError, match=r"parameter 'k': '2 kg' has dimension \[mass\]"):
        symbolic.subs({"k": "2 kg"})
    plain = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    with pytest.raises(SceneError, match="written without units"):
        plain.subs({"k": "2 N/m"})


def test_updates_keep_the_scenes_units():
    scene = seed_test_in_units()
    assert scene.with_initial(x0=["1 cm", "2 mm"]).x0 == sp.Matrix([sp.Rational(1, 100), sp.Rational(1, 500)])
    assert scene.with_initial(x0=scene.v0).x0 == scene.v0  # SymPy values: the scene's own numbers
    with pytest.raises(SceneError, match=r"x0\[0\]: 1 has no unit"):
        scene.with_initial(x0=[1, 0])
    assert scene.with_forcing(["2 N", 0]).forcing[0] == 2
    with pytest.raises(SceneError, match="written without units"):
        ls.Scene.from_components(**SEED_TEST_SI).with_initial(x0=["1 cm", 0])


# --- answers in units ------------------------------------------------------------------------


def test_times_with_units_are_exact_seconds():
    assert times_to_seconds(["0.5 s", "250 ms", "2 min", 1, "0.1"]) == [sp.Rational(1, 2), sp.Rational(1, 4),
                                                                       120, 1, "0.1"]
    sol = ls.solve(seed_test_in_units())
    plain = sol.evaluate([0.5, 0.25, 120.0])
    assert np.array_equal(sol.evaluate(["0.5 s", "250 ms", "2 min"]), plain)
    assert np.array_equal(sol.evaluate(Q_(np.array([500.0, 250.0]), "ms")), plain[:, :2])
    with pytest.raises(ValueError, match=r"times\[0\]: '1 m' has dimension \[length\]"):
        sol.evaluate(["1 m"])


def test_evaluate_returns_quantities_on_request():
    sol = ls.solve(seed_test_in_units())
    times = [0.0, 0.4, 4.0]
    metres = sol.evaluate(times)
    quantity = sol.evaluate(times, units=True)
    assert str(quantity.units) == "meter" and np.array_equal(quantity.magnitude, metres)
    assert np.allclose(sol.evaluate(times, units="cm").magnitude, 100 * metres, rtol=1e-15, atol=0)
    velocity = sol.evaluate(times, derivative=1, units=True)
    assert str(velocity.units) == "meter / second"
    assert velocity.magnitude[:, 0] == pytest.approx([2.0, 1.0], rel=1e-14)
    values, bounds = sol.evaluate(times, units="mm", return_error=True)
    assert str(bounds.units) == "millimeter" and np.all(bounds.magnitude >= 0)
    digits = sol.evaluate([0.4], dps=40, units="cm")
    with mpmath.workdps(40):
        assert abs(digits.magnitude[0, 0] - 100 * sol.evaluate([0.4], dps=40)[0, 0]) < mpmath.mpf(10) ** -35
    with pytest.raises(SceneError, match="expected a length"):
        sol.evaluate(times, units="kg")
    with pytest.raises(SceneError, match="written without units"):
        ls.solve(ls.Scene.from_components(**SEED_TEST_SI)).evaluate(times, units=True)
    # the acceptance probe's reading: a Quantity converts to metres
    assert np.max(np.abs(quantity.to("m").magnitude - metres)) == 0


def test_a_scene_in_centimetres_moves_in_centimetres():
    scene = seed_test_in_units(forcing=["cos(2*t) N", 0])
    in_cm = in_length_unit(scene, "cm")
    times = [0.3, 1.7]
    assert np.allclose(ls.solve(in_cm).evaluate(times), 100 * ls.solve(scene).evaluate(times), rtol=1e-13)
    assert "x \\text{ in cm" in ls.solve(in_cm).latex()
    quantity = ls.solve(in_cm).evaluate(times, units=True)
    assert str(quantity.units) == "centimeter"


def test_attach_units_converts_mpmath_values_at_their_precision():
    scene = seed_test_in_units()
    with mpmath.workdps(50):
        third = mpmath.mpf(1) / 3
    out = attach_units(np.array([[third]], dtype=object), scene, 0, "mm")
    with mpmath.workdps(50):
        assert abs(out.magnitude[0, 0] - 1000 * third) < mpmath.mpf(10) ** -45


def test_modes_and_frequency_response_in_hertz():
    scene = ls.Scene.from_matrices(M=[["1 kg"]], C=[["0.4 kg/s"]], K=[["4 N/m"]], x0=[0], v0=[0])
    (mode,) = ls.modes(scene)
    assert mode.natural_frequency == 2 and mode.natural_frequency_hz == 1 / sp.pi
    assert sp.simplify(mode.damped_frequency_hz - sp.sqrt(4 - sp.Rational(4, 100)) / (2 * sp.pi)) == 0  # ω_d = √(k/m − (c/2m)²)
    reference = 1 / abs(4 - 4 + 0.4j * 2)  # H(iω) = 1/(k − mω² + icω) at ω = 2
    H = ls.frequency_response(scene, ["1/pi Hz", Q_(2, "rad/s")])
    assert abs(H[:, 0, 0]) == pytest.approx([reference, reference], rel=1e-14)


def test_labels_and_latex_say_the_units():
    from matplotlib.figure import Figure

    from laplace_springs.output.plots import plot_motion, plot_phase

    sol = ls.solve(seed_test_in_units())
    ax = plot_motion(sol, Figure().subplots(), t_end=4.0)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("Time (s)", "Position (m)")
    ax = plot_phase(sol, Figure().subplots())
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("Position (m)", "Velocity (m/s)")
    ax = plot_motion(ls.solve(in_length_unit(seed_test_in_units(), "cm")), Figure().subplots())
    assert ax.get_ylabel() == "Position (cm)"
    assert r"&\text{with } x \text{ in m and } t \text{ in s}" in sol.latex()
    plain = ls.solve(ls.Scene.from_components(**SEED_TEST_SI))
    assert "with } x" not in plain.latex()
    assert plot_motion(plain, Figure().subplots()).get_xlabel() == "Time"


def test_the_diagram_shows_values_with_units():
    from matplotlib.figure import Figure

    ax = ls.draw_scene(seed_test_in_units(), Figure().subplots(), show_values=True)
    texts = {t.get_text() for t in ax.texts}
    assert r"$k_{1} = 200\,\mathrm{N/m}$" in texts and r"$m_{2} = \frac{1}{2}\,\mathrm{kg}$" in texts


# --- the seed's helpers ------------------------------------------------------------------------


def test_spring_constant_from_a_load_and_a_deflection():
    k = ls.spring_constant("5 N", "2 cm")  # the seed: "k = 250 N/m"
    assert k.magnitude == 250 and str(k.units) == "newton / meter"
    assert ls.spring_constant(Q_(1, "lbf"), "1 in").magnitude == POUND * G0 / INCH
    with pytest.raises(SceneError, match="load: '5' has no unit"):
        ls.spring_constant("5", "2 cm")
    with pytest.raises(SceneError, match="is zero"):
        ls.spring_constant("5 N", "0 cm")
    spring = seed_test_in_units(springs={"k1": ("wall", "m1", k), "k2": ("m1", "m2", "150 N/m"),
                                         "k3": ("m2", "wall", "300 N/m")})
    assert spring.K[0, 0] == 250 + 150


def test_natural_frequency_and_damping_ratio():
    with mpmath.workdps(30):
        expected = mpmath.sqrt(mpmath.mpf(250) / mpmath.mpf("0.5")) / (2 * mpmath.pi)
    f = ls.natural_frequency("2.5 N/cm", "500 g")
    assert str(f.units) == "hertz" and f.magnitude == pytest.approx(float(expected), rel=1e-15)
    omega = ls.natural_frequency("250 N/m", "0.5 kg", unit="rad/s")
    assert omega.magnitude == pytest.approx(math.sqrt(500), rel=1e-15)
    assert ls.damping_ratio("1.4 N*s/m", "400 N/m", "1 kg") == sp.Rational(7, 200)  # 1.4/(2·20)
    assert ls.damping_ratio("40 kg/s", "4 N/cm", "1000 g") == 1  # critical: c = 2√(km)
    with pytest.raises(SceneError, match="expected a damping"):
        ls.damping_ratio("1.4 N/m", "400 N/m", "1 kg")


# --- the command line ----------------------------------------------------------------------------


def run(capsys, *args):
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_times_params_and_units(capsys, tmp_path):
    path = tmp_path / "k.toml"
    path.write_text('[parameters]\nk = "stiffness of the first spring"\n[masses]\nm1 = "1 kg"\nm2 = "0.5 kg"\n'
                    '[springs]\nk1 = ["wall", "m1", "k"]\nk2 = ["m1", "m2", "150 N/m"]\n'
                    'k3 = ["m2", "wall", "300 N/m"]\n[initial]\nx0 = ["5 cm", "3 cm"]\nv0 = ["2 m/s", "1 m/s"]\n',
                    encoding="utf-8")
    code, out, err = run(capsys, "solve", str(path), "--param", "k=2N/cm", "--at", "0,0.4s,4000ms")
    assert code == 0, err
    reference = ls.solve(seed_test_in_units()).evaluate([0.0, 0.4, 4.0])
    rows = [line.split() for line in out.splitlines()[1:4]]
    assert np.allclose([[float(v) for v in row[1:]] for row in rows], reference.T, rtol=1e-11)
    assert out.splitlines()[-1] == "x in m, t in s"
    code, out, _ = run(capsys, "solve", str(path), "--param", "k=200N/m", "--at", "0", "--unit", "cm")
    assert code == 0 and out.splitlines()[1].split()[1:] == ["5", "3"] and "x in cm" in out
    code, out, err = run(capsys, "solve", str(path), "--param", "k=200")
    assert code == 2 and "has no unit" in err
    code, out, err = run(capsys, "solve", str(path), "--param", "k=200N/m", "--at", "1m")
    assert code == 2 and "expected a time" in err
    code, out, _ = run(capsys, "response", "example5-in-units", "--at", "1Hz")
    assert code == 0 and "Hz" in out
