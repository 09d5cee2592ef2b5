"""Sampled force histories as forcing entries: validation, CSV reading, scene files."""

from __future__ import annotations

import numpy as np
import pytest

from laplace_springs.model.errors import SceneError
from laplace_springs.model.sampled import Sampled, sampled, sampled_from_csv
from laplace_springs.model.scene import Scene
from laplace_springs.model.scene_files import load_scene


@pytest.mark.parametrize("times, values, kind, message", [
    ([0, 1, 1], [0, 0, 0], "linear", r"times\[2\] = 1.0 follows times\[1\] = 1.0"),
    ([0, float("nan")], [0, 0], "linear", r"times\[1\] = nan is not finite"),
    ([0, 1], [0, float("inf")], "linear", r"values\[1\] = inf is not finite"),
    ([0, 1, 2], [0, 1], "linear", "same length"),
    ([0], [1], "zoh", "at least 2 samples"),
    ([-1, 1], [0, 0], "linear", r"times\[0\] = -1.0 is negative"),
    ([0, 1], [0, 1], "cubic", "kind must be one of"),
    ([0, "x"], [0, 1], "linear", r"times\[1\] = 'x' is not a number"),
])
def test_bad_data_is_a_scene_error_naming_the_entry(times, values, kind, message):
    with pytest.raises(SceneError, match=message):
        sampled(times, values, kind)


def test_interpolant_is_zero_outside_the_span():
    f = sampled([1, 2, 4], [2, 4, 0])
    assert f([0.5, 1, 1.5, 3, 4, 5]).tolist() == [0, 2, 3, 2, 0, 0]
    g = sampled([1, 2, 4], [2, 4, 0], "zoh")
    assert g([0.5, 1, 1.5, 3, 3.999, 4]).tolist() == [0, 2, 2, 4, 4, 0]


def test_scene_keeps_sampled_entries_apart():
    f = sampled([0, 1], [1, 1])
    scene = Scene.from_components(masses={"m1": 1, "m2": 1},
                                  springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1)},
                                  forcing={"m1": "cos(t)", "m2": f})
    assert scene.sampled == (None, f) and scene.forcing[0] != 0 and scene.forcing[1] == 0
    assert scene.is_forced and "sampled" in repr(scene) and "sampled" in scene._repr_latex_()
    assert scene.with_forcing(None).sampled is None
    assert scene.with_forcing({"m1": f}).sampled == (f, None)


def test_csv_column_is_read_as_floats(tmp_path):
    path = tmp_path / "force.csv"
    path.write_text("# measured\nt,F,other\n0,0.5,x\n0.1,-2e-3,y\n\n0.2,1_0,z\n")
    f = Sampled.from_csv(path, time="t", value="F")
    assert f.times.tolist() == [0, 0.1, 0.2] and f.values.tolist() == [0.5, -0.002, 10.0]
    assert sampled.from_csv(path, value="F", kind="zoh").kind == "zoh"
    with pytest.raises(SceneError, match="say which column"):
        sampled_from_csv(path)
    with pytest.raises(SceneError, match="no column 'G'"):
        sampled_from_csv(path, value="G")
    path.write_text("t,F\n0,1\n1,__import__('os')\n")
    with pytest.raises(SceneError, match=r"line 3, column 'F'.*is not a number"):
        sampled_from_csv(path)
    path.write_text("t,F\n0,1\n0,2\n")
    with pytest.raises(SceneError, match=r"force.csv: .*times\[1\] = 0.0 follows"):
        sampled_from_csv(path)


def test_scene_file_points_at_a_csv_relative_to_itself(tmp_path):
    folder = tmp_path / "data"
    folder.mkdir()
    (folder / "force.csv").write_text("t,F\n0,0\n1,2\n2,0\n")
    (tmp_path / "scene.toml").write_text(
        '[masses]\nm1 = 1\nm2 = 2\n[springs]\nk1 = ["wall", "m1", 4]\nk2 = ["m1", "m2", 1]\n'
        '[forcing]\nm1 = "cos(t)"\nm2 = { csv = "data/force.csv", time = "t", value = "F", kind = "zoh" }\n')
    scene = load_scene(tmp_path / "scene.toml")
    assert scene.sampled[0] is None and scene.sampled[1].kind == "zoh"
    assert scene.sampled[1].values.tolist() == [0, 2, 0]
    (tmp_path / "bad.toml").write_text('[masses]\nm1 = 1\n[springs]\nk1 = ["wall", "m1", 4]\n'
                                       '[forcing]\nm1 = { csv = "data/force.csv", colour = "red" }\n')
    with pytest.raises(SceneError, match="unknown key 'colour'"):
        load_scene(tmp_path / "bad.toml")
    (tmp_path / "missing.toml").write_text('[masses]\nm1 = 1\n[springs]\nk1 = ["wall", "m1", 4]\n'
                                           '[forcing]\nm1 = { csv = "nope.csv" }\n')
    with pytest.raises(SceneError, match="cannot read CSV file"):
        load_scene(tmp_path / "missing.toml")


def test_arrays_are_frozen():
    f = sampled([0, 1], [1, 2])
    with pytest.raises(ValueError):
        f.values[0] = 5
    assert np.asarray(f.times).dtype == float
