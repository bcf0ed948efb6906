"""Assembly of the contact QP from the scenes: stiffness, gap rows, weights, scales, load targeting.

Every expected value comes from elasticity theory or from an independent computation
(scikit-fem assembled here, geometry measured on the mesh), never from a previous run.
"""

from itertools import combinations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from skfem import asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

import signorini
from signorini.references.analytic import contact_modulus, hertz_cylinder_load
from signorini.errors import InputError
from signorini.certification.kkt import certificate
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

BLOCK = {"W": 0.5, "H": 0.2, "E": 70e9, "nu": 0.33, "delta": 1e-4, "nx": 6, "ny": 4}
HERTZ = {"n_contact": 20}
STEEL = {"E": 2.1e11, "R": 0.01}


@pytest.fixture(scope="module")
def block():
    return signorini.at_load(build_problem("block", params=BLOCK))


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params=HERTZ))


@pytest.fixture(scope="module")
def hertz_steel():
    return signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, **STEEL}))


@pytest.fixture(scope="module", params=["block", "hertz"])
def scene(request, block, hertz):
    return {"block": block, "hertz": hertz}[request.param]


def exact(problem):
    solution = solve(problem, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


def full_stiffness(problem):
    """The unconstrained stiffness on the problem's own basis, assembled here (E = 1)."""
    form = linear_elasticity(*lame_parameters(1.0, problem.model.params["nu"]))
    return asm(form, problem.model.basis).tocsr()


def rigid_modes(problem):
    """Two translations and the infinitesimal rotation (−y, x) as full dof vectors."""
    x, y = problem.model.mesh.p
    dofs = problem.model.basis.nodal_dofs
    n_full = problem.model.prescribed.size
    modes = np.zeros((3, n_full))
    modes[0, dofs[0]] = 1.0
    modes[1, dofs[1]] = 1.0
    modes[2, dofs[0]] = -y
    modes[2, dofs[1]] = x
    return modes


def rel_diff(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(a)), np.max(np.abs(b)))


# --- stiffness -------------------------------------------------------------------------------


def test_free_stiffness_is_symmetric(scene):
    asymmetry = abs(scene.K - scene.K.T).max()
    assert asymmetry <= 1e-14 * abs(scene.K).max()


def test_free_stiffness_is_positive_definite(scene):
    K = scene.K.toarray()
    # Cholesky succeeds only for a positive definite matrix
    sla.cholesky(K, lower=True)
    if scene.n <= 400:
        eigenvalues = np.linalg.eigvalsh(K)
        smallest, largest = eigenvalues[0], eigenvalues[-1]
    else:
        smallest = spla.eigsh(scene.K, k=1, sigma=0.0, which="LM", return_eigenvectors=False)[0]
        largest = spla.eigsh(scene.K, k=1, which="LA", return_eigenvectors=False)[0]
    assert smallest > 1e-10 * largest > 0


def test_free_stiffness_is_the_condensed_full_stiffness(scene):
    K_full = full_stiffness(scene)
    free = scene.model.free_dofs
    assert abs(K_full[free][:, free] - scene.K).max() <= 1e-13 * abs(K_full).max()


def test_full_stiffness_has_exactly_three_rigid_modes(scene):
    K_full = full_stiffness(scene)
    scale = abs(K_full).max()
    for mode in rigid_modes(scene):
        assert np.max(np.abs(K_full @ mode)) <= 1e-12 * scale * np.max(np.abs(mode))
    # the six eigenvalues nearest zero: three vanish (the rigid modes), the fourth does not
    eigenvalues = np.sort(spla.eigsh(K_full, k=6, sigma=-1e-3 * scale, which="LM",
                                     return_eigenvectors=False))
    assert np.all(np.abs(eigenvalues[:3]) <= 1e-12 * scale)
    assert eigenvalues[3] > 1e-6 * scale


def test_full_stiffness_null_space_is_three_dimensional_dense(block):
    K_full = full_stiffness(block).toarray()
    eigenvalues = np.linalg.eigvalsh(K_full)
    tiny = np.abs(eigenvalues) <= 1e-12 * eigenvalues[-1]
    assert int(tiny.sum()) == 3


# --- gap rows, gaps and weights ----------------------------------------------------------------


def test_gap_rows_are_unit_normals_towards_the_obstacle(scene):
    row_norms = np.sqrt(np.asarray(scene.N.multiply(scene.N).sum(axis=1)).ravel())
    np.testing.assert_allclose(row_norms, 1.0, rtol=0, atol=1e-14)
    # each row acts on its own node's vertical dof with −1 (the flat y = 0 lies below)
    full = np.zeros((scene.m, scene.model.prescribed.size))
    full[:, scene.model.free_dofs] = scene.N.toarray()
    nodes = [int(np.argmin(np.hypot(*(scene.model.mesh.p - point[:, None]))))
             for point in scene.contact_points]
    y_dofs = scene.model.basis.nodal_dofs[1, nodes]
    np.testing.assert_array_equal(full[np.arange(scene.m), y_dofs], -1.0)
    assert np.count_nonzero(full) == scene.m


def test_initial_gaps_are_heights_above_the_flat(scene):
    # contact nodes' vertical dofs are free, so the gap is not lifted: d = y · L / U
    expected = scene.contact_points[:, 1] * scene.scales.length / scene.scales.displacement
    np.testing.assert_allclose(scene.d, expected, rtol=1e-12, atol=1e-15)
    assert np.all(scene.d >= 0)


def test_block_weights_sum_to_the_half_width(block):
    total = block.weights.sum() * block.scales.weight
    assert total == pytest.approx(BLOCK["W"], rel=1e-13)
    h = BLOCK["W"] / BLOCK["nx"]
    expected = np.full(block.m, h)
    expected[[0, -1]] = h / 2
    np.testing.assert_allclose(block.weights * block.scales.weight, expected, rtol=1e-12)


def test_cylinder_weights_sum_to_the_candidate_arc_plus_half_a_facet(hertz):
    R = hertz.model.params["R"]
    L = hertz.scales.length
    points = hertz.model.mesh.p * L
    centre = np.array([0.0, R])
    boundary = hertz.model.mesh.boundary_nodes()
    radius = np.hypot(points[0, boundary] - centre[0], points[1, boundary] - centre[1])
    arc = boundary[(np.abs(radius - R) < 1e-9 * R) & (points[1, boundary] < R * (1 - 1e-9))]
    arc = arc[np.argsort(points[0, arc])]
    candidates = hertz.contact_points * L
    assert np.allclose(candidates, points[:, arc[:hertz.m]].T, rtol=0, atol=1e-14 * R)
    chords = np.linalg.norm(np.diff(points[:, arc], axis=1), axis=0)
    half_next = 0.5 * chords[hertz.m - 1]
    total = hertz.weights.sum() * hertz.scales.weight
    # exact: the polyline through the candidates plus half the facet beyond the last one
    assert total == pytest.approx(chords[:hertz.m - 1].sum() + half_next, rel=1e-12)
    # and the arc length R θ up to the last candidate, up to half a facet
    arc_length = R * np.arcsin(candidates[-1, 0] / R)
    assert 0.0 < total - arc_length <= half_next * (1 + 1e-6)
    # candidates reach `candidates · a` (a from Hertz's formula for the load)
    a = hertz.model.params["a_over_R"] * R
    assert candidates[-1, 0] <= hertz.model.params["candidates"] * a * (1 + 1e-9)
    assert points[0, arc[hertz.m]] > hertz.model.params["candidates"] * a


# --- the block: a patch test -----------------------------------------------------------------


def test_block_patch_test_uniform_pressure(block):
    solution = exact(block)
    E_star = contact_modulus(BLOCK["E"], BLOCK["nu"])
    expected = E_star * BLOCK["delta"] / BLOCK["H"]
    pressure = solution.lam * block.scales.force / (block.weights * block.scales.weight)
    np.testing.assert_allclose(pressure, expected, rtol=1e-10)


def test_block_patch_test_linear_displacement(block):
    solution = exact(block)
    full = block.model.expand(solution.u) * block.scales.displacement
    x, y = block.model.mesh.p * block.scales.length
    delta, H, nu = BLOCK["delta"], BLOCK["H"], BLOCK["nu"]
    u_x = full[block.model.basis.nodal_dofs[0]]
    u_y = full[block.model.basis.nodal_dofs[1]]
    # uniaxial plane strain: ε_yy = −δ/H, σ_xx = 0 ⇒ ε_xx = ν/(1 − ν) δ/H
    np.testing.assert_allclose(u_y, -delta * y / H, rtol=0, atol=1e-10 * delta)
    np.testing.assert_allclose(u_x, nu / (1 - nu) * delta / H * x, rtol=0, atol=1e-10 * delta)
    # every candidate touches the flat
    np.testing.assert_allclose(block.gap(solution.u), 0.0, atol=1e-12)


def test_block_force_balance(block):
    solution = exact(block)
    contact = block.total_contact_force(solution.lam) * block.scales.force
    applied = block.model.applied_load(solution.u) * block.scales.force
    E_star = contact_modulus(BLOCK["E"], BLOCK["nu"])
    assert contact == pytest.approx(applied, rel=1e-10)
    assert contact == pytest.approx(2 * BLOCK["W"] * E_star * BLOCK["delta"] / BLOCK["H"], rel=1e-10)


def test_hertz_force_balance(hertz):
    solution = exact(hertz)
    contact = hertz.total_contact_force(solution.lam)
    applied = hertz.model.applied_load(solution.u)
    assert contact > 0
    assert contact == pytest.approx(applied, rel=1e-9)


# --- units -----------------------------------------------------------------------------------


@pytest.mark.slow
def test_dimensionless_problem_does_not_depend_on_units(hertz, hertz_steel):
    assert (hertz.n, hertz.m) == (hertz_steel.n, hertz_steel.m)
    assert rel_diff(hertz.K.toarray(), hertz_steel.K.toarray()) < 1e-12
    assert rel_diff(hertz.N.toarray(), hertz_steel.N.toarray()) < 1e-12
    # f and d carry the calibrated δ (root-finding to ~1e-12)
    assert rel_diff(hertz.f, hertz_steel.f) < 1e-10
    assert rel_diff(hertz.d, hertz_steel.d) < 1e-10
    assert rel_diff(hertz.weights, hertz_steel.weights) < 1e-12


def test_scales_follow_the_units(hertz, hertz_steel):
    E, R = STEEL["E"], STEEL["R"]
    assert hertz_steel.scales.length == pytest.approx(R * hertz.scales.length, rel=1e-14)
    assert hertz_steel.scales.displacement == pytest.approx(R * hertz.scales.displacement, rel=1e-12)
    assert hertz_steel.scales.force == pytest.approx(E * R * hertz.scales.force, rel=1e-12)
    assert hertz_steel.scales.pressure == pytest.approx(E * hertz.scales.pressure, rel=1e-12)


def test_physical_pressure_scales_with_E(hertz, hertz_steel):
    one, steel = exact(hertz), exact(hertz_steel)
    p_one = one.lam * hertz.scales.pressure / hertz.weights
    p_steel = steel.lam * hertz_steel.scales.pressure / hertz_steel.weights
    np.testing.assert_array_equal(p_one > 0, p_steel > 0)
    assert rel_diff(p_steel, STEEL["E"] * p_one) < 1e-8


@pytest.mark.parametrize("units", [
    pytest.param({"E": 1.0, "R": 1.0}, id="E=1,R=1"),
    pytest.param(STEEL, id="steel-SI"),
])
@pytest.mark.slow
def test_nondimensionalise_false_gives_the_same_physical_answer(units):
    scaled = signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, **units}))
    raw = signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, **units},
                                          nondimensionalise=False))
    assert raw.scales.force == raw.scales.length == raw.scales.displacement == 1.0
    s_scaled, s_raw = exact(scaled), exact(raw)
    assert certificate(raw, s_raw).worst()[1] < 1e-9
    u_scaled = s_scaled.u * scaled.scales.displacement
    assert rel_diff(u_scaled, s_raw.u) < 1e-8
    p_scaled = s_scaled.lam * scaled.scales.pressure / scaled.weights
    p_raw = s_raw.lam / raw.weights
    assert rel_diff(p_scaled, p_raw) < 1e-8
    assert (raw.total_contact_force(s_raw.lam)
            == pytest.approx(scaled.total_contact_force(s_scaled.lam) * scaled.scales.force,
                             rel=1e-8))


def test_nondimensionalise_false_block_in_SI_units():
    scaled = signorini.at_load(build_problem("block", params=BLOCK))
    raw = signorini.at_load(build_problem("block", params=BLOCK, nondimensionalise=False))
    s_scaled, s_raw = exact(scaled), exact(raw)
    E_star = contact_modulus(BLOCK["E"], BLOCK["nu"])
    p_raw = s_raw.lam / raw.weights
    np.testing.assert_allclose(p_raw, E_star * BLOCK["delta"] / BLOCK["H"], rtol=1e-8)
    assert rel_diff(s_scaled.u * scaled.scales.displacement, s_raw.u) < 1e-8


# --- load targeting --------------------------------------------------------------------------


@pytest.mark.parametrize("values", [
    pytest.param({"P": 0.004}, id="E=1"),
    pytest.param({"P": 3.0e6, **STEEL}, id="steel-SI"),
])
def test_target_load_is_reached(values):
    problem = signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, **values}))
    solution = exact(problem)
    total = problem.total_contact_force(solution.lam) * problem.scales.force
    assert total == pytest.approx(values["P"], rel=1e-8)
    assert problem.model.applied_load(solution.u) * problem.scales.force == pytest.approx(
        values["P"], rel=1e-8)


def test_default_load_is_hertz_load_for_default_a_over_R(hertz):
    solution = exact(hertz)
    R, E, nu = hertz.model.params["R"], hertz.model.params["E"], hertz.model.params["nu"]
    P = hertz_cylinder_load(0.05 * R, R, contact_modulus(E, nu))
    total = hertz.total_contact_force(solution.lam) * hertz.scales.force
    assert total == pytest.approx(P, rel=1e-8)


def test_consistent_a_over_R_and_P_give_the_same_problem():
    a_over_R, nu = 0.1, 0.3
    P = hertz_cylinder_load(a_over_R, 1.0, contact_modulus(1.0, nu))
    by_width = signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, "a_over_R": a_over_R}))
    by_load = signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, "P": P}))
    assert (by_width.n, by_width.m) == (by_load.n, by_load.m)
    assert rel_diff(by_width.K.toarray(), by_load.K.toarray()) < 1e-12
    assert rel_diff(by_width.N.toarray(), by_load.N.toarray()) < 1e-12
    assert rel_diff(by_width.f, by_load.f) < 1e-10
    assert rel_diff(by_width.d, by_load.d) < 1e-10
    assert by_width.model.params["P"] == pytest.approx(P, rel=1e-12)
    assert by_load.model.params["a_over_R"] == pytest.approx(a_over_R, rel=1e-12)


def test_P_and_a_over_R_together_raise():
    with pytest.raises(InputError, match="P") as info:
        signorini.at_load(build_problem("hertz-cylinder", params={**HERTZ, "P": 0.004, "a_over_R": 0.05}))
    assert "a_over_R" in str(info.value)


def test_vectorised_plane_strain_stiffness_is_scikit_fems():
    from skfem import Basis, ElementVector, MeshTri, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from signorini.fem.stiffness import simplex_stiffness

    mesh = MeshTri.init_circle(3)
    mesh = MeshTri(mesh.p * [[2.0], [0.5]], mesh.t)  # stretched: elements of many shapes
    Lambda, Mu = lame_parameters(3.0, 0.3)
    expected = asm(linear_elasticity(Lambda, Mu), Basis(mesh, ElementVector(mesh.elem())))
    difference = abs(simplex_stiffness(mesh, Lambda, Mu) - expected).max()
    assert difference <= 1e-12 * abs(expected).max()


@pytest.mark.slow
def test_vectorised_solid_stiffness_is_scikit_fems(monkeypatch):
    from skfem import Basis, ElementVector, MeshTet, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from signorini.fem import stiffness as assembly

    mesh = MeshTet.init_ball().refined(1)
    mesh = MeshTet(mesh.p * [[1.3], [0.7], [1.1]] + 0.1 * np.sin(mesh.p), mesh.t)  # distorted
    Lambda, Mu = lame_parameters(2.0, 0.3)
    expected = asm(linear_elasticity(Lambda, Mu), Basis(mesh, ElementVector(mesh.elem())))
    monkeypatch.setattr(assembly, "SIMPLEX_BLOCK", 97)  # several blocks, a ragged last one
    difference = abs(assembly.simplex_stiffness(mesh, Lambda, Mu) - expected).max()
    assert difference <= 1e-12 * abs(expected).max()


@pytest.mark.parametrize("axisymmetric", [False, True])
def test_closed_form_contact_weights_are_scikit_fems(axisymmetric):
    from skfem import FacetBasis, LinearForm, MeshTri, asm

    from signorini.fem.assembly import contact_weights

    mesh = MeshTri.init_circle(3)
    mesh = MeshTri(mesh.p + [[1.5], [0.0]], mesh.t)  # r > 0 everywhere
    facets = mesh.boundary_facets()
    nodes = mesh.boundary_nodes()
    basis = FacetBasis(mesh, mesh.elem(), facets=facets, intorder=2)

    @LinearForm
    def weight(v, w):
        return v * w.x[0] if axisymmetric else v

    np.testing.assert_allclose(contact_weights(mesh, facets, nodes, axisymmetric),
                               asm(weight, basis)[nodes], rtol=1e-12)


def test_an_obstacle_away_from_the_origin_gives_the_same_gaps_in_any_units():
    """A flat at height h ≠ 0 under a body of length L ≠ 1: gaps are physical, whatever the scaling."""
    from signorini.fem.assembly import assemble
    from signorini.scenes import get_scene
    from signorini.fem.model import FlatObstacle

    family = get_scene("hertz-cylinder")
    model = family.build(family.parse({"R": 3.0, "n_contact": 12, "delta": 0.01}),
                         {"R", "n_contact", "delta"})
    model.obstacle = FlatObstacle(-0.02)
    scaled, raw = assemble(model), assemble(model, nondimensionalise=False)
    np.testing.assert_allclose(scaled.d * scaled.scales.displacement, raw.d, rtol=1e-12)
    first = np.argmin(raw.contact_points[:, 0] ** 2 + raw.contact_points[:, 1] ** 2)
    assert raw.d[first] == pytest.approx(0.02)  # the flat lies 0.02 below the first point


def _graded_mesh():
    from skfem import MeshTri

    x = np.cumsum(np.r_[0.0, 1.3 ** np.arange(12)])  # cells growing by 30 % from the left
    y = np.cumsum(np.r_[0.0, 0.7 ** np.arange(9)])
    return MeshTri.init_tensor(x / x[-1], y / y[-1])


def _irregular_mesh():
    from skfem import MeshTri

    mesh = MeshTri.init_circle(4)
    shift = 0.2 * np.random.default_rng(3).uniform(-1, 1, mesh.p.shape) / 2 ** 4
    inside = np.ones(mesh.p.shape[1], dtype=bool)
    inside[mesh.boundary_nodes()] = False
    # jittered interior (no two elements alike), in r > 0 for the axisymmetric model
    return MeshTri(mesh.p + shift * inside + [[1.1], [0.0]], mesh.t)


@pytest.mark.parametrize("axisymmetric", [False, True])
@pytest.mark.parametrize("make_mesh", [_graded_mesh, _irregular_mesh])  # graded: nodes on r = 0
def test_triangle_stiffness_has_scikit_fems_pattern_and_entries(make_mesh, axisymmetric):
    from skfem import Basis, ElementVector, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from signorini.fem.assembly import axisymmetric_elasticity
    from signorini.fem.stiffness import node_pairs, simplex_stiffness

    mesh = make_mesh()
    Lambda, Mu = lame_parameters(2.5, 0.35)
    form = (axisymmetric_elasticity if axisymmetric else linear_elasticity)(Lambda, Mu)
    expected = asm(form, Basis(mesh, ElementVector(mesh.elem()))).tocsr()
    K = simplex_stiffness(mesh, Lambda, Mu, axisymmetric)
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))  # sorted within rows, as flagged
    assert K.has_sorted_indices and np.all((np.diff(K.indices) > 0) | (np.diff(rows) > 0))
    largest = np.max(np.abs(expected.data))
    assert abs(K - expected).max() <= 1e-12 * largest
    if axisymmetric:  # the quadrature's sums may cancel to an exact zero where ours leave round-off
        ours, theirs = ({(i, j) for i, j, v in zip(M.row, M.col, M.data) if v != 0}
                        for M in (K.tocoo(), expected.tocoo()))
        assert theirs <= ours
        assert all(abs(K[i, j]) <= 1e-15 * largest for i, j in ours - theirs)
    else:
        np.testing.assert_array_equal(K.indptr, expected.indptr)
        np.testing.assert_array_equal(K.indices, expected.indices)
    assert abs(K - K.T).max() == 0.0  # each off-diagonal block is its mirror's transpose
    # the node pattern holds every node and both ends of every edge, each in its own entry
    nodes, corners = mesh.p.shape[1], mesh.t.shape[0]
    indptr, indices, diagonal, upper, lower, edge_of = node_pairs(mesh.t, nodes)
    assert indices.size == nodes + 2 * mesh.facets.shape[1]
    row_of = np.repeat(np.arange(nodes), np.diff(indptr))
    np.testing.assert_array_equal(np.sort(np.concatenate([diagonal, upper, lower])),
                                  np.arange(indices.size))
    np.testing.assert_array_equal(row_of[diagonal], np.arange(nodes))
    np.testing.assert_array_equal(indices[diagonal], np.arange(nodes))
    np.testing.assert_array_equal(row_of[upper], indices[lower])
    np.testing.assert_array_equal(indices[upper], row_of[lower])
    assert np.all(row_of[upper] < indices[upper])
    for k, (a, b) in enumerate(combinations(range(corners), 2)):
        ends = np.sort(mesh.t[[a, b]], axis=0)
        np.testing.assert_array_equal(row_of[upper[edge_of[k]]], ends[0])
        np.testing.assert_array_equal(indices[upper[edge_of[k]]], ends[1])


@pytest.mark.parametrize("bound", [50, 2 ** 58, 2 ** 62])  # one value sort; too wide: two
def test_sort_order_is_a_stable_argsort_without_an_index_sort(monkeypatch, bound):
    from signorini.fem.topology import sort_order

    rng = np.random.default_rng(5)
    keys = np.concatenate([rng.integers(0, 50, 1000) * (bound // 50),  # ties, and low bits
                           rng.integers(0, bound, 200_000)])  # that differ below the high ones
    expected = np.argsort(keys, kind="stable")
    monkeypatch.setattr(np, "argsort", lambda *a, **k: pytest.fail("an index sort was called"))
    np.testing.assert_array_equal(sort_order(keys, bound), expected)


def _ball():
    from skfem import MeshTet

    return MeshTet.init_ball(2)


@pytest.mark.parametrize("make_mesh", [_irregular_mesh, _ball])
def test_stiffness_reads_the_edges_a_mesh_already_has_and_is_bit_identical(make_mesh):
    """A triangle mesh whose facets were found, or a tetrahedral one whose edges were, gives
    K its pattern (no second sort), and K is the same to the last bit as without them."""
    from signorini.fem.stiffness import mesh_edges, node_pairs, simplex_stiffness
    from signorini.fem.topology import with_edges, with_topology

    fresh, known = make_mesh(), make_mesh()
    assert mesh_edges(fresh) is None
    known = with_topology(known) if known.t.shape[0] == 3 else with_edges(known)
    edges = mesh_edges(known)
    assert edges is not None
    nodes = known.p.shape[1]
    for ours, theirs in zip(node_pairs(known.t, nodes, edges), node_pairs(known.t, nodes)):
        np.testing.assert_array_equal(ours, theirs)
    A, B = simplex_stiffness(fresh, 1.3, 0.7), simplex_stiffness(known, 1.3, 0.7)
    for name in ("data", "indices", "indptr"):
        assert getattr(A, name).tobytes() == getattr(B, name).tobytes()


def test_tetrahedron_gradients_are_the_cross_products_to_the_bit():
    """Written into one array, the gradients are ``np.cross``'s rows over the determinant, and
    the edge matrix times them is the identity."""
    from skfem import MeshTet

    from signorini.fem.stiffness import tetrahedron_gradients

    mesh = MeshTet.init_ball(2)
    x = mesh.p[:, mesh.t]  # (3, 4, elements)
    e1, e2, e3 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    rows = np.stack([np.cross(e2, e3, axis=0), np.cross(e3, e1, axis=0),
                     np.cross(e1, e2, axis=0)], axis=1)
    det = np.einsum("ie,ie->e", e1, rows[:, 0])
    grads, volume = tetrahedron_gradients(mesh.p, mesh.t)
    np.testing.assert_array_equal(grads, np.concatenate([-rows.sum(axis=1, keepdims=True), rows],
                                                        axis=1) / det)
    np.testing.assert_array_equal(volume, np.abs(det) / 6.0)
    edges = np.stack([e1, e2, e3], axis=1)  # (3 components, 3 edges, elements)
    np.testing.assert_allclose(np.einsum("ike,ile->kle", edges, grads[:, 1:]),
                               np.broadcast_to(np.eye(3)[..., None], (3, 3, mesh.t.shape[1])),
                               atol=1e-12)
