"""Contact rows between two P1 faces: node-to-segment and mortar (signorini.fem.mortar)."""

import numpy as np
import pytest
from skfem import MeshTri

import signorini
from signorini.errors import InputError
from signorini.fem.mortar import Face, couple, mortar, node_to_segment
from signorini.fem.topology import facets_on


def block_face(x: np.ndarray, bottom: float, top: float, on: float) -> Face:
    """The face y = ``on`` of a one-layer block [x₀, x₋₁] × [bottom, top] with nodes ``x``."""
    mesh = MeshTri.init_tensor(np.asarray(x, dtype=float), np.array([bottom, top]))
    return Face.of(mesh, facets_on(mesh, np.flatnonzero(np.isclose(mesh.p[1], on))))


def spacing(count: int, seed: int) -> np.ndarray:
    """``count`` elements on [0, 1] of random lengths (between 0.5 and 1.5 of the mean)."""
    lengths = np.random.default_rng(seed).uniform(0.5, 1.5, count)
    return np.concatenate([[0.0], np.cumsum(lengths) / lengths.sum()])


@pytest.mark.parametrize("basis", ["dual", "standard"])
@pytest.mark.parametrize("slave_count, master_count", [(7, 12), (12, 7), (5, 33)])
def test_on_a_flat_face_the_rows_of_M_sum_to_those_of_D(basis, slave_count, master_count):
    slave = block_face(spacing(slave_count, 1), 0.0, 1.0, 0.0)
    master = block_face(spacing(master_count, 2), -1.0, 0.0, 0.0)
    rows = mortar(slave, master, basis)
    assert rows.m == slave_count + 1
    D_sums, M_sums = rows.D.sum(axis=1).A1, rows.M.sum(axis=1).A1
    np.testing.assert_allclose(M_sums, D_sums, rtol=0, atol=1e-14)
    np.testing.assert_allclose(D_sums, slave.weights(), rtol=1e-13)  # ∫ ψₛ = ∫ φₛ
    # each slave node's own coefficient is its weight, and D has nothing else
    np.testing.assert_allclose(rows.D.diagonal(), rows.weights, rtol=1e-13)
    assert np.abs(rows.D.toarray() - np.diag(D_sums)).max() < 1e-14


def test_the_dual_basis_is_biorthogonal_and_the_standard_one_is_not():
    slave = block_face(np.linspace(0, 1, 5), 0.0, 1.0, 0.0)
    master = block_face(np.linspace(0, 1, 5), -1.0, 0.0, 0.0)
    dual, standard = mortar(slave, master, "dual"), mortar(slave, master, "standard")
    # matching faces: M is D's pattern for the dual basis, the consistent mass for the standard
    np.testing.assert_allclose(dual.M.toarray(), dual.D.toarray(), atol=1e-15)
    h = 0.25
    assert standard.M[1, 0] == pytest.approx(h / 6) and standard.M[1, 1] == pytest.approx(2 * h / 3)


@pytest.mark.parametrize("discretisation", ["nts", "mortar", "mortar-standard"])
def test_a_uniform_gap_is_every_row_s_gap_after_scaling(discretisation):
    slave = block_face(spacing(9, 3), 0.02, 1.0, 0.02)
    master = block_face(spacing(6, 4), -1.0, 0.0, 0.0)
    rows = couple(slave, master, discretisation).scaled()
    np.testing.assert_allclose(rows.gap, 0.02, rtol=1e-12)
    # the slave's outward normal is (0, -1): n on its own node, -φ n on the master's
    assert np.allclose(rows.slave_rows[:, 1::2].sum(axis=1).A1, -1.0)
    assert np.allclose(rows.master_rows[:, 1::2].sum(axis=1).A1, 1.0)


def test_on_matching_faces_node_to_segment_and_dual_mortar_are_the_same_rows():
    x = spacing(10, 5)
    slave = block_face(x, 0.01, 1.0, 0.01)  # a gap of 0.01 between the faces
    master = block_face(x, -1.0, 0.0, 0.0)
    nts, dual = node_to_segment(slave, master).scaled(), mortar(slave, master, "dual").scaled()
    np.testing.assert_array_equal(nts.slave, dual.slave)
    for a, b in ((nts.slave_rows, dual.slave_rows), (nts.master_rows, dual.master_rows)):
        assert abs(a - b).max() < 1e-12
    np.testing.assert_allclose(nts.gap, dual.gap, rtol=0, atol=1e-12)
    np.testing.assert_allclose(nts.weights, dual.weights, rtol=1e-12)


def test_on_matching_meshes_both_discretisations_give_the_same_answer():
    params = {"mesh_ratio": 1.0, "nx": 8, "E2": 4.0, "nu2": 0.2}
    answers = {}
    for discretisation in ("nts", "mortar"):
        problem = signorini.build_problem("two-block-patch",
                                          params={**params, "discretisation": discretisation})
        answers[discretisation] = problem, signorini.solve(problem, "pdas")
    (nts, a), (dual, b) = answers["nts"], answers["mortar"]
    assert abs(nts.N - dual.N).max() < 1e-12 and np.abs(nts.d - dual.d).max() < 1e-12
    assert a.converged and b.converged
    scale = np.abs(a.solution.u).max()
    assert np.abs(a.solution.u - b.solution.u).max() < 1e-10 * scale
    assert np.abs(a.solution.lam - b.solution.lam).max() < 1e-10 * np.abs(a.solution.lam).max()


def test_slave_nodes_beyond_the_master_face_get_no_row():
    slave = block_face(np.linspace(0.0, 2.0, 9), 0.0, 1.0, 0.0)  # twice as wide
    master = block_face(np.linspace(0.0, 1.0, 4), -1.0, 0.0, 0.0)
    for rows in (node_to_segment(slave, master), mortar(slave, master)):
        assert np.all(slave.points[0, rows.slave] <= 1.0 + 1e-12)
        assert rows.m == 5


def test_faces_that_do_not_face_each_other_are_refused():
    slave = block_face(np.linspace(0.0, 1.0, 4), 0.0, 1.0, 1.0)  # the top face, normal +y
    master = block_face(np.linspace(0.0, 1.0, 4), -1.0, 0.0, 0.0)  # normal +y as well
    with pytest.raises(InputError, match="slave"):
        mortar(slave, master)
    with pytest.raises(InputError, match="discretisation"):
        couple(slave, master, "segment-to-segment")


def test_a_face_lists_its_nodes_in_order_along_it():
    grid = MeshTri.init_tensor(np.linspace(0.0, 1.0, 7), np.linspace(0.0, 1.0, 3))
    order = np.random.default_rng(6).permutation(grid.p.shape[1])  # nodes numbered at random
    mesh = MeshTri(grid.p[:, order], np.argsort(order)[grid.t])
    face = Face.of(mesh, facets_on(mesh, np.flatnonzero(np.isclose(mesh.p[1], 0.0))))
    assert np.all(np.diff(face.points[0]) > 0) or np.all(np.diff(face.points[0]) < 0)
    np.testing.assert_allclose(face.normals, [[0.0] * 6, [-1.0] * 6], atol=1e-15)  # outward
