"""Large scenes: sparse storage, loading in linear time, and the size limits (issue 11).

Expected values are independent of the code under test: a chain's stiffness and damping
matrices are tridiagonal with the entries written out by hand (2k on the diagonal, -k
beside it), a mesh's are summed here from the generator's own list of springs, and the
motion of a small chain stored sparse is compared with the 30-digit matrix exponential
of ``laplace_springs.bench.reference`` applied to the same chain stored dense.
"""

from __future__ import annotations

import time
import tomllib
from collections import Counter
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion
from laplace_springs.limits import limits, using_limits
from laplace_springs.model import scene as scene_module
from laplace_springs.model import scene_files
from laplace_springs.model.errors import SceneError
from laplace_springs.model.scene import (
    ExactSparseMatrix,
    Scene,
)
from laplace_springs.model.scene_files import load_scene, scene_from_toml_text
from laplace_springs.numeric.first_order import scene_arrays

R = sympy.Rational


# --- generators of scene files --------------------------------------------------------


def chain_toml(n: int, stiffness: str = "2", damping: str | None = "1/10") -> str:
    """wall - m1 - ... - mn - wall: unit masses, a spring (and a dashpot) on every link;
    m1 displaced by 1, mn given velocity 1/2."""
    nodes = ["wall", *(f"m{i}" for i in range(1, n + 1)), "wall"]
    links = list(zip(nodes, nodes[1:]))
    lines = [f'title = "{n}-mass chain"', "[masses]"]
    lines += [f'm{i} = "1"' for i in range(1, n + 1)]
    lines.append("[springs]")
    lines += [f'k{i} = ["{a}", "{b}", "{stiffness}"]' for i, (a, b) in enumerate(links, 1)]
    if damping is not None:
        lines.append("[dashpots]")
        lines += [f'c{i} = ["{a}", "{b}", "{damping}"]' for i, (a, b) in enumerate(links, 1)]
    lines += ["[initial]", 'x0 = {m1 = "1"}', f'v0 = {{m{n} = "1/2"}}']
    return "\n".join(lines) + "\n"


def mesh_pairs(masses: int, springs: int) -> list[tuple[int, int]]:
    """``springs`` pairs of mass indices: i to i + d (mod masses) for d = 1, 2, ..."""
    pairs: list[tuple[int, int]] = []
    offset = 1
    while len(pairs) < springs:
        pairs += [(i, (i + offset) % masses) for i in range(min(masses, springs - len(pairs)))]
        offset += 1
    return pairs


def mesh_toml(masses: int, springs: int) -> str:
    """``masses`` unit masses on a ring, one tied to the wall, and ``springs`` springs of
    stiffness 1 + (label mod 3) from ``mesh_pairs``."""
    lines = ['title = "mesh"', "[masses]"]
    lines += [f"m{i} = 1" for i in range(masses)]
    lines += ["[springs]", 'w = ["wall", "m0", "1"]']
    lines += [f'k{label} = ["m{i}", "m{j}", {1 + label % 3}]'
              for label, (i, j) in enumerate(mesh_pairs(masses, springs))]
    lines += ["[initial]", 'x0 = {m0 = "1"}']
    return "\n".join(lines) + "\n"


def tridiagonal(n: int, diagonal: R, beside: R) -> dict[tuple[int, int], R]:
    entries = {(i, i): diagonal for i in range(n)}
    entries.update({(i, i + 1): beside for i in range(n - 1)})
    entries.update({(i + 1, i): beside for i in range(n - 1)})
    return entries


# --- the chain: exact entries, sparse storage -----------------------------------------


def test_chain_beyond_the_dense_threshold_is_sparse_with_tridiagonal_entries():
    n = limits().dense_storage_max_coordinates + 44
    scene = scene_from_toml_text(chain_toml(n))
    assert all(isinstance(m, ExactSparseMatrix) for m in (scene.M, scene.C, scene.K))
    assert isinstance(scene.K, sympy.ImmutableSparseMatrix)
    assert scene.K.todok() == tridiagonal(n, R(4), R(-2))
    assert scene.C.todok() == tridiagonal(n, R(1, 5), R(-1, 10))
    assert scene.M.todok() == {(i, i): 1 for i in range(n)}
    assert len(scene.K.todok()) == 3 * n - 2
    assert scene.x0[0] == 1 and scene.v0[n - 1] == R(1, 2) and sum(scene.x0) == 1
    assert scene.is_damped and repr(scene) == f"<Scene '{n}-mass chain': {n} coordinates, damped>"


def test_chain_at_the_dense_threshold_stays_dense():
    scene = scene_from_toml_text(chain_toml(limits().dense_storage_max_coordinates))
    assert all(type(m) is sympy.ImmutableMatrix for m in (scene.M, scene.C, scene.K))


def test_ten_thousand_mass_chain_loads_in_linear_time(tmp_path):
    """A guard against quadratic loading: 10,000 masses, 20,002 components. Measured
    about 2 s; the dense matrices before ran out of 4 GiB after 85 s."""
    path = tmp_path / "chain.toml"
    path.write_text(chain_toml(10_000), encoding="utf-8")
    start = time.perf_counter()
    scene = load_scene(path)
    assert time.perf_counter() - start < 30
    assert scene.n == 10_000 and len(scene.components) == 20_002
    assert len(scene.K.todok()) == len(scene.C.todok()) == 3 * 10_000 - 2
    assert scene.K[5000, 5000] == 4 and scene.K[5000, 5001] == -2 and scene.K[0, 9999] == 0


def test_thirty_thousand_springs_on_a_thousand_masses():
    pairs = mesh_pairs(1000, 30_000)
    start = time.perf_counter()
    scene = scene_from_toml_text(mesh_toml(1000, 30_000))
    assert time.perf_counter() - start < 30  # measured about 1.5 s; 16 s before
    expected: Counter[tuple[int, int]] = Counter({(0, 0): 1})  # the wall spring
    for label, (i, j) in enumerate(pairs):
        k = 1 + label % 3
        expected[(i, i)] += k
        expected[(j, j)] += k
        expected[(i, j)] -= k
        expected[(j, i)] -= k
    assert scene.K.todok() == {key: R(value) for key, value in expected.items() if value}
    assert len(scene.components) == 30_001 and not scene.is_damped


def test_many_parallel_springs_sum_into_one_entry():
    springs = {f"k{i}": ("m1", "m2", "k") for i in range(20_000)}
    scene = Scene.from_components(masses={"m1": 1, "m2": 1}, springs=springs,
                                  parameters=["k"])
    k = sympy.Symbol("k", positive=True)
    assert scene.K.tolist() == [[20_000 * k, -20_000 * k], [-20_000 * k, 20_000 * k]]


# --- the sparse path gives the same motion ----------------------------------------------


def small_chain() -> Scene:
    return Scene.from_components(
        masses={"m1": 1, "m2": "3/2", "m3": 2},
        springs={"k1": ("wall", "m1", 3), "k2": ("m1", "m2", 1), "k3": ("m2", "m3", 2),
                 "k4": ("m3", "wall", "1/2")},
        dashpots={"c1": ("m1", "m2", "1/10"), "c2": ("m3", "ground", "1/5")},
        x0={"m1": 1, "m3": "-1/2"}, v0={"m2": "1/3"})


@pytest.fixture
def sparse_storage(set_limits):
    """Every scene of more than one coordinate stored sparse."""
    set_limits(dense_storage_max_coordinates=1)


@pytest.mark.parametrize("method", ["auto", "exact", "modal", "certified"])
def test_sparse_storage_solves_like_the_reference(sparse_storage, method):
    dense = Scene.from_matrices(M=sympy.diag(1, R(3, 2), 2), C=[[R(1, 10), R(-1, 10), 0],
                                [R(-1, 10), R(1, 10), 0], [0, 0, R(1, 5)]],
                                K=[[4, -1, 0], [-1, 3, -2], [0, -2, R(5, 2)]],
                                x0=[1, 0, R(-1, 2)], v0=[0, R(1, 3), 0])
    assert type(dense.K) is ExactSparseMatrix  # the fixture is active
    scene = small_chain()
    assert isinstance(scene.K, ExactSparseMatrix) and scene.K == dense.K and scene.C == dense.C
    times = [0.0, 0.37, 1.3, 4.1]
    with monkeypatch_dense():
        reference_scene = small_chain()
    assert type(reference_scene.K) is sympy.ImmutableMatrix
    reference = reference_motion(reference_scene, times, dps=30)
    values = ls.solve(scene, method=method).evaluate(times)
    expected = np.array([[float(mpmath.mpf(x)) for x in row] for row in reference])
    assert np.max(np.abs(values - expected)) < 1e-12


def monkeypatch_dense():
    """Dense storage again inside the fixture (a context manager)."""
    return using_limits(dense_storage_max_coordinates=256)


def test_sparse_normalized_and_subs(sparse_storage):
    scene = Scene.from_components(masses={"m1": 2, "m2": "m"},
                                  springs={"k1": ("wall", "m1", "k"), "k2": ("m1", "m2", 4)},
                                  dashpots={"c": ("m2", "wall", 1)}, parameters=["m", "k"])
    m, k = sympy.symbols("m k", positive=True)
    A, B = scene.normalized()
    assert isinstance(A, ExactSparseMatrix)
    assert sympy.Matrix(A) == sympy.Matrix([[(k + 4) / 2, -2], [-4 / m, 4 / m]])
    assert sympy.Matrix(B) == sympy.Matrix([[0, 0], [0, 1 / m]])
    fixed = scene.subs({"m": 8, "k": 2})
    assert isinstance(fixed.K, ExactSparseMatrix) and fixed.parameters == ()
    assert fixed.K.tolist() == [[6, -4], [-4, 4]] and fixed.M.tolist() == [[2, 0], [0, 8]]


def test_sparse_checks_of_the_mass_matrix(sparse_storage):
    # a massless node held by a dashpot: a regular pencil
    held = Scene.from_components(masses={"m1": 1, "m2": 0}, springs={"k": ("wall", "m1", 1)},
                                 dashpots={"c": ("m1", "m2", 1), "g": ("m2", "wall", 1)})
    assert held.M.todok() == {(0, 0): 1}
    with pytest.raises(SceneError, match="mass 'm2' \\(coordinate x2\\) has zero mass and no spring or dashpot"):
        Scene.from_components(masses={"m1": 1, "m2": 0}, springs={"k": ("wall", "m1", 1)})
    with pytest.raises(SceneError, match=r"motion along \[0, 1, -1\] \(coordinate x2, coordinate x3\)"):
        Scene.from_matrices(M=[[1, 0, 0], [0, 0, 0], [0, 0, 0]], x0=[0] * 3, v0=[0] * 3,
                            C=[[0, 0, 0], [0, 1, 1], [0, 1, 1]])
    # det(λ²M + λC) ≡ 0 (a zero row) although M, C, K share no null vector
    with pytest.raises(SceneError, match=r"identically zero.*vanishes at λ = 3/7, 5/7, 1,"):
        Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 1], [0, 0]], x0=[0, 0], v0=[0, 0])
    with pytest.raises(SceneError, match="indefinite .*a pivot -3"):
        Scene.from_matrices(M=[[1, 2], [2, 1]], x0=[0, 0], v0=[0, 0])
    semidefinite = Scene.from_matrices(M=[[1, 1], [1, 1]], K=[[1, 0], [0, 2]], x0=[0, 0], v0=[0, 0])
    assert semidefinite.M.todok() == {(0, 0): 1, (0, 1): 1, (1, 0): 1, (1, 1): 1}
    with pytest.raises(SceneError, match="finite"):
        Scene.from_matrices(M=sympy.ImmutableSparseMatrix(2, 2, {(0, 0): 1, (1, 1): sympy.oo}),
                            x0=[0, 0], v0=[0, 0])


def test_massless_nodes_of_a_large_chain():
    n = limits().dense_storage_max_coordinates + 100
    held = chain_toml(n).replace('m100 = "1"', 'm100 = "0"')
    assert scene_from_toml_text(held).M.todok().get((99, 99)) is None  # m100 is coordinate 99
    loose = chain_toml(n, damping=None).replace('m100 = "1"', 'm100 = "0"').replace(
        'm101 = "1"', 'm101 = "0"')
    loose = loose.replace('k100 = ["m99", "m100", "2"]', 'k100 = ["m99", "wall", "2"]')
    loose = loose.replace('k102 = ["m101", "m102", "2"]', 'k102 = ["m102", "wall", "2"]')
    with pytest.raises(SceneError, match=r"the motion \[1, 1\] of mass 'm100' \(coordinate x100\), "
                                         r"mass 'm101' \(coordinate x101\) \(the others at rest\) "
                                         r"meets no mass, dashpot or spring"):
        scene_from_toml_text(loose)


def test_banded_mass_matrix_of_a_large_scene():
    """A consistent (tridiagonal, positive definite) mass matrix of 2,000 coordinates,
    given as a SymPy sparse matrix: read from its nonzero entries, checked exactly."""
    n = 2000
    M = sympy.SparseMatrix(n, n, {**{(i, i): R(2, 3) for i in range(n)},
                                  **{(i, i + 1): R(1, 6) for i in range(n - 1)},
                                  **{(i + 1, i): R(1, 6) for i in range(n - 1)}})
    K = sympy.SparseMatrix(n, n, {(i, i): 1 for i in range(n)})
    start = time.perf_counter()
    scene = Scene.from_matrices(M=M, K=K, x0=[0] * n, v0=[0] * n)
    assert time.perf_counter() - start < 30  # about 1 s
    assert scene.M.todok()[(5, 6)] == R(1, 6) and len(scene.M.todok()) == 3 * n - 2
    indefinite = M.copy()
    indefinite[7, 8] = indefinite[8, 7] = 1
    with pytest.raises(SceneError, match="indefinite"):
        Scene.from_matrices(M=indefinite, K=K, x0=[0] * n, v0=[0] * n)


def test_exact_sparse_matrix_behaves_as_sympy_sparse():
    entries = {(0, 0): R(2), (0, 2): R(-1, 3), (2, 0): sympy.Symbol("k")}
    ours = ExactSparseMatrix.from_dok(3, 3, entries)
    theirs = sympy.ImmutableSparseMatrix(3, 3, entries)
    assert ours == theirs and ours.todok() == theirs.todok() and ours.T == theirs.T
    assert (ours * ours).todok() == (theirs * theirs).todok()
    assert isinstance(ours * ours, ExactSparseMatrix)
    import pickle
    assert pickle.loads(pickle.dumps(ours)) == ours


# --- solve on large scenes: a refusal at once, with the reason -----------------------


def test_numeric_routes_refuse_scenes_beyond_their_size_at_once():
    n = 2 * limits().general_modal_max_coordinates
    # a dashpot from m1 to the ground besides those on the links: damping that is not
    # classical, for the general modal route only, which holds dense 2n x 2n matrices
    text = chain_toml(n).replace("[dashpots]\n", '[dashpots]\nground = ["m1", "wall", "1/3"]\n')
    scene = scene_from_toml_text(text)
    start = time.perf_counter()
    with pytest.raises(ls.LimitError, match=rf"coordinates {n:,} > Limits.general_modal_max_coordinates"):
        ls.solve(scene, method="modal")
    with pytest.raises(SceneError, match="Limits.general_modal_max_coordinates"):
        scene_arrays(scene)
    assert time.perf_counter() - start < 10
    # without it: dashpots 1/10 beside springs 2 on every link, C = K/20 (Rayleigh damping),
    # solved on the Chebyshev route without dense matrices
    scene = scene_from_toml_text(chain_toml(n))
    start = time.perf_counter()
    sol = ls.solve(scene, method="modal")
    values, bounds = sol.evaluate([0, "1/2"], return_error=True)
    velocity = sol.evaluate([0], derivative=1)
    assert time.perf_counter() - start < 10
    assert values[0, 0] == 1 and np.all(values[1:, 0] == 0) and velocity[-1, 0] == 0.5
    assert np.max(bounds) < 1e-12
    # t = 1/2 on the first masses: the first 30 masses alone (a wall after m30 and no push
    # from mn change x1(1/2) by about (1/2)^60/60!) by scipy's dense matrix exponential
    import scipy.linalg

    m = 30
    K = 2 * (2 * np.eye(m) - np.eye(m, k=1) - np.eye(m, k=-1))
    Z = np.block([[np.zeros((m, m)), np.eye(m)], [-K, -K / 20]])
    reference = (scipy.linalg.expm(Z / 2) @ np.eye(2 * m)[:, 0])[:5]
    assert np.max(np.abs(values[:5, 1] - reference)) < 1e-13


# --- limits --------------------------------------------------------------------------


def test_limits_are_documented():
    doc = scene_files.__doc__
    assert "Limits.max_file_bytes" in doc and "16 MiB" in doc and limits().max_file_bytes == 16 * 2**20
    for field in ("max_coordinates", "max_components", "max_matrix_input_size"):
        assert f"Limits.{field}" in doc and f"({getattr(limits(), field):,})" in doc


def no_parsing(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the text was parsed")
    monkeypatch.setattr(scene_files.tomllib, "loads", refuse)


def test_too_many_masses_refused_before_parsing(monkeypatch):
    text = chain_toml(limits().max_coordinates + 1, damping=None)
    no_parsing(monkeypatch)
    start = time.perf_counter()
    with pytest.raises(SceneError, match=r"big.toml: \[masses\]: 100,001 masses, more than the limit "
                                         r"100,000 \(Limits.max_coordinates\)"):
        scene_from_toml_text(text, source="big.toml")
    assert time.perf_counter() - start < 5  # about 0.05 s


def test_too_many_components_refused_before_parsing(monkeypatch):
    masses = "[masses]\n" + "".join(f"m{i} = 1\n" for i in range(100))
    springs = "[springs]\n" + "".join(f'k{i} = ["m{i % 100}", "wall", 1]\n'
                                      for i in range(limits().max_components // 2 + 1))
    dashpots = "[dashpots]\n" + "".join(f'c{i} = ["m{i % 100}", "wall", 1]\n'
                                        for i in range(limits().max_components // 2))
    no_parsing(monkeypatch)
    with pytest.raises(SceneError, match=r"\[springs\] and \[dashpots\]: 300,001 components, more "
                                         r"than the limit 300,000 \(Limits.max_components\)"):
        scene_from_toml_text(masses + springs + dashpots)


def test_counts_checked_exactly_after_parsing_and_before_conversion(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("an entry was converted")
    monkeypatch.setattr(scene_module, "to_exact", refuse)
    inline = "masses = {" + ", ".join(f"m{i} = 1" for i in range(limits().max_coordinates + 1)) + "}\n"
    with pytest.raises(SceneError, match=r"masses: 100,001 masses, more than the limit 100,000"):
        scene_from_toml_text(inline)
    with pytest.raises(SceneError, match=r"springs and dashpots: 300,001 components"):
        Scene.from_components(masses={"m": 1},
                              springs=[(f"k{i}", "m", "wall", 1) for i in range(limits().max_components + 1)])
    with pytest.raises(SceneError, match=r"M: 100,001 coordinates, more than the limit 100,000"):
        Scene.from_matrices(M=sympy.SparseMatrix(limits().max_coordinates + 1, limits().max_coordinates + 1, {}),
                            x0=[], v0=[])


def test_matrix_forms_are_limited_and_point_at_components(monkeypatch):
    n = limits().max_matrix_input_size + 1
    row = "[" + ", ".join(["0"] * n) + "]"
    text = "[matrices]\nM = [" + ",\n".join([row] * n) + "]\n"
    no_parsing(monkeypatch)
    with pytest.raises(SceneError, match=r"\[matrices\] M: 501 entries in its first row, more than "
                                         r"the limit 500 \(Limits.max_matrix_input_size\); describe .* "
                                         r"masses, springs and dashpots"):
        scene_from_toml_text(text)
    monkeypatch.undo()
    with pytest.raises(SceneError, match=r"A: 501 rows given entry by entry, more than the limit "
                                         r"500 \(Limits.max_matrix_input_size\); describe .*from_components"):
        Scene.from_normalized(A=np.zeros((n, n)), x0=[0] * n, v0=[0] * n)
    with pytest.raises(SceneError, match="Limits.max_matrix_input_size"):
        Scene.from_matrices(M=[[1] * n] * n, x0=[0] * n, v0=[0] * n)


def test_file_size_is_limited_before_reading_it_all(tmp_path):
    path = tmp_path / "huge.toml"
    path.write_bytes(b"# " + b"x" * limits().max_file_bytes + b"\n")
    with pytest.raises(SceneError, match=r"more than 16,777,216 bytes, the limit Limits.max_file_bytes"):
        load_scene(path)
    with pytest.raises(SceneError, match=r"Limits.max_file_bytes"):
        scene_from_toml_text("#" * (limits().max_file_bytes + 1))


@pytest.mark.skipif(not __import__("os").path.exists("/dev/zero"), reason="needs /dev/zero")
def test_an_endless_file_is_refused(set_limits, tmp_path):
    # an endless device is refused before it is read; a regular file is read up to the limit
    with pytest.raises(SceneError, match="'/dev/zero': it is a character device, not a regular file"):
        load_scene("/dev/zero")
    set_limits(max_file_bytes=1000)
    (tmp_path / "big.toml").write_text("# " + "x" * 2000 + "\n")
    with pytest.raises(SceneError, match="more than 1,000 bytes, the limit Limits.max_file_bytes"):
        load_scene(tmp_path / "big.toml")


def test_deeply_nested_toml_is_a_scene_error():
    with pytest.raises(SceneError, match="nested too deeply"):
        scene_from_toml_text("x = " + "[" * 10_000 + "]" * 10_000)


def test_counts_read_from_the_text_match_the_parsed_tables():
    text = mesh_toml(40, 300) + '[dashpots]\nc1 = [\n  "m1",\n  "m2",\n  1,\n]\n# c9 = 1\n\n' \
        + "c2 = ['m3', 'wall', 2]  # a comment\n\"quoted\" = [\"m4\", \"wall\", 1]\n"
    counts = scene_files._section_lines(text)
    parsed = tomllib.loads(text)
    assert counts["masses"] == len(parsed["masses"]) == 40
    assert counts["springs"] == len(parsed["springs"]) == 301
    assert counts["dashpots"] == len(parsed["dashpots"]) == 3
    assert counts["initial"] == 1
    assert scene_from_toml_text(text).n == 40


def test_sizes_in_messages_are_shortened():
    masses = {f"m{i}": 1 for i in range(500)}
    with pytest.raises(SceneError) as info:
        Scene.from_components(masses=masses, springs={"k": ("m1", "nowhere", 1)})
    assert "m0, m1, m2" in str(info.value) and "(500 in all)" in str(info.value)
    assert len(str(info.value)) < 400


def test_fractions_convert_alike_in_both_storages(sparse_storage):
    sparse = Scene.from_matrices(M=[[Fraction(1, 3), 0], [0, 1]], K=[[0.2, 0], [0, "1/5"]],
                                 x0=[0, 0], v0=[0, 0])
    with monkeypatch_dense():
        dense = Scene.from_matrices(M=[[Fraction(1, 3), 0], [0, 1]], K=[[0.2, 0], [0, "1/5"]],
                                    x0=[0, 0], v0=[0, 0])
    assert sparse.K == dense.K == sympy.Matrix([[R(1, 5), 0], [0, R(1, 5)]])
    assert sparse.M == dense.M
