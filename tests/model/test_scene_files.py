"""Tests of TOML scene files and of the bundled seed scenes.

Expected matrices: the seed's printed A = [[3, -1], [-2, 2]] (Example 1) and
B = 0.2 I (Example 2), the public acceptance scenes (shared/acceptance/scenes.py,
copied here as printed there) for Examples 2, 3 and 5, and for Example 4 the
seed's M^-1-free equations with b = 0.5, delta = 0.1 written out by hand.
"""

from __future__ import annotations

import tomllib
from fractions import Fraction
from importlib import resources
from pathlib import Path

import pytest
import sympy

from laplace_springs.model.errors import SceneError
from laplace_springs.model.scene_files import bundled_scenes, load_scene, scene_from_toml_text

R = sympy.Rational


def exact(rows):
    """A matrix from decimal strings, converted independently of the code under test."""
    return sympy.Matrix([[R(Fraction(entry)) for entry in row] for row in rows])


def column(*entries):
    return sympy.Matrix([R(Fraction(entry)) for entry in entries])


BUNDLED = {
    "vertical-pair": {
        "M": [["1", "0"], ["0", "1/2"]],
        "C": [["0", "0"], ["0", "0"]],
        "K": [["3", "-1"], ["-1", "1"]],  # acceptance seed1-vertical-pair
        "x0": ("1", "0"),
        "v0": ("0", "1"),
        "layout": "vertical",
    },
    "vertical-pair-damped": {  # acceptance seed2-vertical-pair-damped
        "M": [["1", "0"], ["0", "1/2"]],
        "C": [["0.2", "0"], ["0", "0.1"]],
        "K": [["3", "-1"], ["-1", "1"]],
        "x0": ("1", "0"),
        "v0": ("0", "0"),
        "layout": "vertical",
    },
    "wall-pair": {  # acceptance seed3-wall-pair
        "M": [["1", "0"], ["0", "2/3"]],
        "C": [["0", "0"], ["0", "0"]],
        "K": [["0.38", "-0.08"], ["-0.08", "0.28"]],
        "x0": ("-0.08", "0.4"),
        "v0": ("0.15", "-0.3"),
        "layout": "horizontal",
    },
    "wall-pair-dashpot": {  # seed Example 4: C = [[delta + b, -b], [-b, delta + b]], K = diag(k1, k3)
        "M": [["1", "0"], ["0", "2"]],
        "C": [["0.6", "-0.5"], ["-0.5", "0.6"]],
        "K": [["1", "0"], ["0", "2"]],
        "x0": ("0.1", "0.3"),
        "v0": ("0.2", "-0.5"),
        "layout": "horizontal",
    },
    "example5-in-units": {  # the seed's Example 5 undamped test, in SI by hand: 5 cm = 1/20 m
        "M": [["1", "0"], ["0", "1/2"]],
        "C": [["0", "0"], ["0", "0"]],
        "K": [["350", "-150"], ["-150", "450"]],
        "x0": ("1/20", "3/100"),
        "v0": ("2", "1"),
        "layout": "horizontal",
    },
    "three-dashpots": {  # acceptance seed5-three-dashpots
        "M": [["1", "0"], ["0", "0.8"]],
        "C": [["1.9", "-1.4"], ["-1.4", "2.3"]],
        "K": [["779", "-379"], ["-379", "479"]],
        "x0": ("0.05", "0.07"),
        "v0": ("3", "2"),
        "layout": "horizontal",
    },
}


# --- bundled scenes ----------------------------------------------------------------


def test_bundled_scene_names_and_titles():
    scenes = bundled_scenes()
    assert list(scenes) == sorted(BUNDLED)
    assert all(isinstance(title, str) and title for title in scenes.values())
    assert scenes["vertical-pair"].startswith("Example 1")
    assert scenes["three-dashpots"].startswith("Example 5")


@pytest.mark.parametrize("name", sorted(BUNDLED))
def test_bundled_scene_matrices(name):
    expected = BUNDLED[name]
    scene = load_scene(name)
    for field in ("M", "C", "K"):
        assert getattr(scene, field) == exact(expected[field]), field
    assert scene.x0 == column(*expected["x0"])
    assert scene.v0 == column(*expected["v0"])
    assert scene.layout == expected["layout"]
    assert scene.title == bundled_scenes()[name]
    assert scene.mass_names == ("m1", "m2")
    assert scene.components  # built from components


def test_bundled_example1_and_2_reproduce_the_seeds_normalised_matrices():
    A, B = load_scene("vertical-pair").normalized()
    assert sympy.Matrix([[3, -1], [-2, 2]]) == A
    A, B = load_scene("vertical-pair-damped").normalized()
    assert sympy.Matrix([[3, -1], [-2, 2]]) == A
    assert sympy.eye(2) / 5 == B


def test_bundled_component_labels_follow_the_seed():
    labels = {name: {c.label for c in load_scene(name).components} for name in BUNDLED}
    assert labels["wall-pair-dashpot"] == {"k1", "k3", "b", "delta1", "delta2"}
    assert labels["three-dashpots"] == {"k1", "k2", "k3", "mu1", "mu2", "mu3"}


@pytest.mark.parametrize(
    ("name", "phrases"),
    [
        ("vertical-pair", ["Example 1", "-k2/m2"]),
        ("vertical-pair-damped", ["Example 2", "10 l^3", "50 + 5 l + 25 l^2"]),
        ("wall-pair", ["Example 3", "-k2 x1"]),
        ("wall-pair-dashpot", ["Example 4", "k3", "delta = 0.1", "no value for delta"]),
        ("three-dashpots", ["Example 5", "-mu2"]),
    ],
)
def test_bundled_descriptions_cite_the_seed_and_its_misprints(name, phrases):
    text = (resources.files("laplace_springs.model") / "scenes" / f"{name}.toml").read_text(encoding="utf-8")
    description = tomllib.loads(text)["description"]
    for phrase in phrases:
        assert phrase in description, phrase


def test_unknown_bundled_name_lists_the_bundled_ones():
    with pytest.raises(SceneError, match=r"unknown scene 'vertical-pear'; bundled scenes: example5-in-units, three-dashpots, vertical-pair"):
        load_scene("vertical-pear")


# --- the component form ------------------------------------------------------------

COMPONENT_FILE = """
title = "Hanging pair"
layout = "vertical"
description = "Two masses"
[masses]
m1 = "1"
m2 = 0.5
[springs]
k1 = ["ceiling", "m1", 2]
k2 = ["m1", "m2", "k"]
[dashpots]
c1 = ["air", "m1", 0.2]
[initial]
x0 = {m2 = "1/3"}
v0 = ["0", 1.5]
[parameters]
k = "stiffness of the lower spring"
"""


def test_component_form():
    scene = scene_from_toml_text(COMPONENT_FILE)
    k = sympy.Symbol("k", positive=True)
    assert scene.title == "Hanging pair" and scene.layout == "vertical"
    assert sympy.diag(1, R(1, 2)) == scene.M
    assert sympy.Matrix([[2 + k, -k], [-k, k]]) == scene.K
    assert sympy.Matrix([[R(1, 5), 0], [0, 0]]) == scene.C  # TOML float 0.2 -> 1/5
    assert scene.x0 == sympy.Matrix([0, R(1, 3)])
    assert scene.v0 == sympy.Matrix([0, R(3, 2)])


def test_missing_initial_table_means_rest():
    scene = scene_from_toml_text('[masses]\nm1 = 1\n[springs]\nk = ["wall", "m1", 1]')
    assert scene.x0 == sympy.zeros(1, 1) and scene.v0 == sympy.zeros(1, 1)
    assert scene.title == "" and scene.layout == "horizontal"


# --- the matrix forms --------------------------------------------------------------


def test_matrix_form():
    scene = scene_from_toml_text(
        """
        title = "seed 5 as matrices"
        names = ["x", "y"]
        [matrices]
        M = [["1", "0"], ["0", "0.8"]]
        C = [[1.9, -1.4], [-1.4, 2.3]]
        K = [[779, -379], [-379, 479]]
        [initial]
        x0 = ["0.05", "0.07"]
        v0 = [3, 2]
        """
    )
    for field in ("M", "C", "K"):
        assert getattr(scene, field) == exact(BUNDLED["three-dashpots"][field])
    assert scene.names == ("x", "y")
    assert scene.components == ()


def test_normalized_form_with_default_initial_data():
    scene = scene_from_toml_text("[normalized]\nA = [[3, -1], [-2, 2]]\nB = [[0.2, 0], [0, 0.2]]")
    assert sympy.eye(2) == scene.M
    assert sympy.Matrix([[3, -1], [-2, 2]]) == scene.K
    assert sympy.eye(2) / 5 == scene.C
    assert scene.x0 == sympy.zeros(2, 1)


# --- loading from paths ------------------------------------------------------------


def test_load_scene_from_a_path(tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(COMPONENT_FILE, encoding="utf-8")
    for argument in (path, str(path)):
        assert load_scene(argument).title == "Hanging pair"


def test_load_scene_missing_file(tmp_path):
    with pytest.raises(SceneError, match=r"cannot read scene file .*missing\.toml"):
        load_scene(tmp_path / "missing.toml")
    with pytest.raises(SceneError, match="cannot read scene file"):
        load_scene("../no/such/place")


def test_errors_in_a_file_name_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[masses]\nm1 = 1\nm2 = "-1"\n', encoding="utf-8")
    with pytest.raises(SceneError, match=r"bad\.toml: mass 'm2' must be positive, got -1"):
        load_scene(path)


@pytest.mark.parametrize(
    "entry",
    [
        '[masses]\nm1 = "{code}"',
        '[masses]\nm1 = 1\n[springs]\nk1 = ["wall", "m1", "{code}"]',
        '[masses]\nm1 = 1\n[initial]\nx0 = ["{code}"]',
        '[matrices]\nM = [["{code}"]]',
    ],
)
def test_code_in_a_number_is_refused_and_never_run(tmp_path, entry):
    target = tmp_path / "pwned"
    code = f"__import__('os').system('touch {target}')"
    path = tmp_path / "attack.toml"
    path.write_text(entry.replace("{code}", code), encoding="utf-8")
    with pytest.raises(SceneError, match=r"attack\.toml: .*expected a number"):
        load_scene(path)
    assert not target.exists()


def test_code_in_a_title_is_only_text(tmp_path):
    target = tmp_path / "pwned"
    code = f"__import__('os').system('touch {target}')"
    path = tmp_path / "attack.toml"
    path.write_text(f'title = "{code}"\n[masses]\nm1 = 1', encoding="utf-8")
    assert load_scene(path).title == code
    assert not target.exists()


# --- errors ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('title = "x"\nbad = = 1', r"demo\.toml: malformed TOML: .*line 2, column 7"),
        ("[masses\nm1 = 1", r"demo\.toml: malformed TOML"),
        ('titel = "x"\n[masses]\nm1 = 1', r"demo\.toml: unknown key 'titel' at the top level; allowed keys: title"),
        ("[masses]\nm1 = 1\n[springz]", r"unknown key 'springz' at the top level"),
        ("[masses]\nm1 = 1\n[initial]\nxo = [1]", r"unknown key 'xo' in \[initial\]; allowed keys: x0, v0"),
        ('[matrices]\nM = [[1]]\nKK = [[1]]', r"unknown key 'KK' in \[matrices\]; allowed keys: M, C, K"),
        ('[normalized]\nA = [[1]]\nC = [[1]]', r"unknown key 'C' in \[normalized\]"),
        ('[matrices]\nK = [[1]]', r"\[matrices\] needs M"),
        ('[normalized]\nB = [[1]]', r"\[normalized\] needs A"),
        ('title = "x"', r"needs exactly one of \[masses\], \[matrices\], \[normalized\], \[equations\]; found none"),
        ('[masses]\nm1 = 1\n[matrices]\nM = [[1]]', r"found \[masses\], \[matrices\]"),
        ('[matrices]\nM = [[1]]\n[springs]\nk = ["wall", "m1", 1]', r"key 'springs' does not belong with \[matrices\]"),
        ('names = ["a"]\n[masses]\nm1 = 1', r"key 'names' does not belong with \[masses\]"),
        ('names = "a"\n[matrices]\nM = [[1]]', r"'names' must be an array of strings"),
        ('masses = 3', r"'masses' must be a table"),
        ('title = 3\n[masses]\nm1 = 1', r"'title' must be a string, got 3"),
        ('description = ["x"]\n[masses]\nm1 = 1', r"'description' must be a string"),
        ('layout = "sideways"\n[masses]\nm1 = 1', r"layout must be one of horizontal, vertical"),
        ('[masses]\nm1 = true', r"mass 'm1': expected a number, got True"),
        ('[masses]\nm1 = nan', r"mass 'm1': expected a finite number, got nan"),
        ('[masses]\nm1 = inf', r"expected a finite number, got inf"),
        ('[masses]\nm1 = 1\n[springs]\nk = ["wall", "m2", 1]', r"spring 'k': unknown node 'm2'"),
        ('[matrices]\nM = [[1, 0], [0, 1]]\n[initial]\nx0 = [1]', r"x0 has 1 entries, expected 2"),
        ('[matrices]\nM = [[1, 2]]', r"M must be a non-empty square matrix"),
        ('[matrices]\nM = [["1/0"]]', r"M\[0,0\]: .*division by zero"),
    ],
)
def test_file_errors(text, message):
    with pytest.raises(SceneError, match=message):
        scene_from_toml_text(text, source="demo.toml")


def test_bundled_files_are_exactly_the_bundled_scenes_in_component_form():
    folder = resources.files("laplace_springs.model") / "scenes"
    entries = [entry for entry in folder.iterdir() if entry.name.endswith(".toml")]
    assert sorted(Path(entry.name).stem for entry in entries) == sorted(BUNDLED)
    for entry in entries:
        assert "masses" in tomllib.loads(entry.read_text(encoding="utf-8")), entry.name
