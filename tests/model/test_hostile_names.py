"""Hostile names (issue 22): masses named like other coordinates, and parameters named like
the toolkit's own symbols.

Masses named ``x2``, ``x1`` in that order: coordinate ``x1`` is the mass ``x2``. A force,
an initial value or an output named ``x1`` must reach the mass ``x1`` (coordinate 2) on
every path: ``from_components``, ``with_forcing``, ``with_initial``, a scene file, the
command line, moving supports, frequency responses, sweeps. The expected placement is
written out by hand (the column with the entry at index 1), not computed by the package.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.cli import main
from laplace_springs.model.errors import SceneError
from laplace_springs.model.scene_files import scene_from_toml_text
from laplace_springs.model.symbols import RESERVED_NAMES

t = ls.t
COS = sp.cos(t)
#: Mass x2 (1 kg) first, mass x1 (2 kg) second: coordinate x1 is mass x2.
MASSES = {"x2": 1, "x1": 2}
SPRINGS = {"k1": ("wall", "x2", 3), "k2": ("x2", "x1", 1)}
DRIVEN_X1 = sp.Matrix([0, COS])  # a force on the mass x1, by hand


def swapped(**kwargs):
    return ls.Scene.from_components(masses=MASSES, springs=SPRINGS, **kwargs)


SCENE_FILE = """
[masses]
x2 = 1
x1 = 2
[springs]
k1 = ["wall", "x2", 3]
k2 = ["x2", "x1", 1]
[initial]
x0 = {x1 = "1/2"}
[forcing]
x1 = "cos(t)"
"""


def test_a_force_named_x1_lands_on_the_mass_x1_on_every_path(tmp_path):
    path = tmp_path / "swapped.toml"
    path.write_text(SCENE_FILE)
    loaded = ls.load_scene(path)
    columns = {
        "from_components": swapped(forcing={"x1": "cos(t)"}).forcing,
        "with_forcing": swapped().with_forcing({"x1": "cos(t)"}).forcing,
        "with_forcing (SymPy)": swapped().with_forcing({"x1": COS}).forcing,
        "scene file": loaded.forcing,
    }
    for path_name, column in columns.items():
        assert sp.Matrix(column) == DRIVEN_X1, path_name
    assert loaded.x0.T.tolist() == [[0, sp.Rational(1, 2)]]
    assert swapped().with_initial(x0={"x1": 1}).x0.T.tolist() == [[0, 1]]
    assert swapped(x0={"x1": 1}, v0={"x2": 3}).v0.T.tolist() == [[3, 0]]


def test_a_moving_support_drives_the_mass_it_is_attached_to():
    scene = ls.Scene.from_components(masses=MASSES, springs={"k1": ("wall", "x2", 3), "k2": ("x1", "ground", 5)},
                                     support_motion={"ground": "sin(t)"})
    assert sp.Matrix(scene.forcing) == sp.Matrix([0, 5 * sp.sin(t)])


def test_the_command_line_resolves_names_like_the_library(capsys, tmp_path):
    path = tmp_path / "swapped.toml"
    path.write_text(SCENE_FILE.replace('[forcing]\nx1 = "cos(t)"\n', ""))
    assert main(["solve", str(path), "--forcing", "x1=cos(t)", "--at", "0.5,2"]) == 0
    table = [line.split() for line in capsys.readouterr().out.splitlines()[1:]]
    by_hand = ls.Scene.from_matrices(M=[[1, 0], [0, 2]], K=[[4, -1], [-1, 1]], x0=[0, "1/2"], v0=[0, 0],
                                     forcing=[0, "cos(t)"])
    expected = ls.solve(by_hand).evaluate([0.5, 2.0])
    values = np.array([[float(v) for v in row[1:]] for row in table]).T
    assert np.allclose(values, expected, rtol=1e-10, atol=1e-12)
    assert main(["solve", str(path), "--formula", "--coordinates", "x1"]) == 0
    shown = capsys.readouterr().out
    assert "x2(t)" in shown and "x1(t)" not in shown  # mass x1 is coordinate x2


def test_outputs_named_x1_are_the_mass_x1():
    scene = swapped(dashpots={"c": ("x1", "wall", "1/2")})
    H = ls.frequency_response(scene, [0.7])[0]
    by_mass = ls.transmissibility(ls.Scene.from_components(
        masses=MASSES, springs={"k1": ("ground", "x2", 3), "k2": ("x2", "x1", 1)}), [0.7], outputs=["x1"])
    assert by_mass.shape[0] == 1 or by_mass.shape[-1] == 1
    # |X/U| of mass x1 (coordinate 2) for ground - 3 - x2 - 1 - x1, by hand: K = [[4,-1],[-1,1]]
    w2 = 0.49
    D = np.array([[4 - w2, -1], [-1, 1 - 2 * w2]])
    expected = abs(np.linalg.solve(D, [3, 0])[1])
    assert np.isclose(float(np.ravel(by_mass)[0]), expected, rtol=1e-12)
    assert H.shape == (2, 2)


def test_the_same_coordinate_twice_and_unknown_names_are_refused():
    pair = ls.Scene.from_components(masses={"m1": 1, "m2": 1}, springs={"k": ("wall", "m1", 1)},
                                    dashpots={"c": ("m1", "m2", 1)})
    for attempt in (lambda: pair.with_forcing({"m1": 1, "x1": 2}),
                    lambda: pair.with_initial(x0={"x1": 1, "m1": 2}),
                    lambda: ls.Scene.from_components(masses={"m1": 1, "m2": 1}, springs={"k": ("wall", "m1", 1)},
                                                     dashpots={"c": ("m1", "m2", 1)}, v0={"m1": 1, "x1": 2})):
        with pytest.raises(SceneError, match=r"name the same coordinate \(mass 'm1' \(coordinate x1\)\)"):
            attempt()
    with pytest.raises(SceneError, match=r"unknown mass or coordinate 'x3'; masses are x2, x1; "
                                         r"coordinates are x1, x2"):
        swapped().with_initial(v0={"x3": 1})
    with pytest.raises(SceneError, match=r"unknown coordinate 'm1'; coordinates are x1"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0={"m1": 1}, v0=[0])


def test_a_massless_node_is_named_as_the_user_wrote_it():
    with pytest.raises(SceneError, match=r"mass 'm2' \(coordinate x2\) has zero mass and no spring"):
        ls.Scene.from_components(masses={"m1": 1, "m2": 0}, springs={"k": ("wall", "m1", 1)})
    with pytest.raises(SceneError, match=r"coordinate b has zero mass"):
        ls.Scene.from_matrices(M=[[1, 0], [0, 0]], K=[[1, 0], [0, 0]], x0=[0, 0], v0=[0, 0],
                               names=["a", "b"])


# ----------------------------------------------------------------------------
# parameters named like the toolkit's symbols
# ----------------------------------------------------------------------------

_ENTRY_POINTS = {
    "from_matrices, list": lambda name: ls.Scene.from_matrices(
        M=[[1]], K=[[name]], x0=[1], v0=[0], parameters=[name]),
    "from_matrices, mapping": lambda name: ls.Scene.from_matrices(
        M=[[1]], K=[[1]], C=[[name]], x0=[1], v0=[0], parameters={name: "real"}),
    "a Symbol in the data": lambda name: ls.Scene.from_matrices(
        M=[[1]], K=[[sp.Symbol(name, positive=True)]], x0=[1], v0=[0]),
    "from_components": lambda name: ls.Scene.from_components(
        masses={"m": 1}, springs={"k": ("wall", "m", name)}, parameters=[name]),
    "forcing": lambda name: ls.Scene.from_matrices(
        M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=[f"{name}*cos(2*t)"], parameters=[name]),
    "laplace": lambda name: ls.laplace(f"{name}*t", parameters=[name]),
    "scene file": lambda name: scene_from_toml_text(
        f'[parameters]\n{name} = "real"\n[masses]\nm = 1\n[springs]\nk = ["wall", "m", "{name}"]\n'),
    "from_state_space": lambda name: ls.from_state_space([[0, 1], [name, 0]], parameters=[name]),
}


@pytest.mark.parametrize("entry_point", sorted(_ENTRY_POINTS))
@pytest.mark.parametrize("name", sorted(RESERVED_NAMES))
def test_reserved_names_are_refused_everywhere_naming_what_to_rename(name, entry_point):
    expected = rf"'{name}' cannot be a parameter name: it is .*rename"
    if (name, entry_point) == ("t", "a Symbol in the data"):  # a Symbol named t is the time
        expected = r"K\[0,0\]: the time t may appear only in forcing"
    with pytest.raises(ValueError, match=expected):
        _ENTRY_POINTS[entry_point](name)


def test_omega_s_and_lam_were_silently_mixed_before():
    """The issue's findings: with other names the results are the textbook ones."""
    scene = ls.Scene.from_matrices(M=[[1]], K=[["w0"]], x0=[1], v0=[0], parameters=["w0"])
    H = ls.frequency_response(scene)[0, 0]
    assert sp.simplify(H - 1 / (sp.Symbol("w0", positive=True) - ls.omega**2)) == 0
    stiff = ls.Scene.from_matrices(M=[[1]], C=[["c0"]], K=[["k0"]], x0=[1], v0=[0], parameters=["c0", "k0"])
    G = ls.transfer_function(stiff)[0, 0]
    c0, k0 = sp.symbols("c0 k0", positive=True)
    assert sp.simplify(G - 1 / (ls.s**2 + c0 * ls.s + k0)) == 0
