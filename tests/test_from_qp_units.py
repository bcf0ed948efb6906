"""A QP of your own in any units: ``ContactProblem.from_qp`` keeps it; methods see it scaled.

The user's problem is built here with scikit-fem, as a user would: half a block (symmetry
plane x = 0) pressed by a prescribed displacement of its top onto a rigid cylinder, condensed
with ``skfem.condense``, handed over as K, f, N, d, weights and contact points — in SI,
in mm–MPa and dimensionless. Every QP route, in its default form, must be certified at 1e-9
and agree with pdas, and every output must come back in the user's units.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm, condense
from skfem.models.elasticity import lame_parameters, linear_elasticity

import signorini
from signorini.solvers.base import Method
from signorini.solvers.registry import REGISTRY, get_method

#: the routes the problem statement names, in their default forms
ROUTES = ("qp-osqp", "qp-clarabel", "cvxpy", "uzawa", "uzawa-nesterov", "pdas")
TOL = 1e-9
#: how close every route's λ must come to pdas's (relative, ∞-norm)
AGREE = 1e-6
#: (label, length unit in metres, E in the unit of stress): the same body three times
UNITS = (("SI", 1e-3, 2.1e11), ("mm-MPa", 1.0, 2.1e5), ("dimensionless", 0.1, 1.0))


def half_block(length: float, E: float, refine: int = 3, nu: float = 0.3):
    """K, f, N, d, weights and contact points of half a block (half-width and height
    10·length) pushed 0.05·length onto a rigid cylinder of radius 50·length."""
    a, h, R, push = 10 * length, 10 * length, 50 * length, 0.05 * length
    cells = 2 ** (refine + 1)
    mesh = MeshTri.init_tensor(np.linspace(0, a, cells + 1), np.linspace(0, h, cells + 1))
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    K = asm(linear_elasticity(*lame_parameters(E, nu)), basis)
    top = basis.get_dofs(lambda x: np.isclose(x[1], h))
    symmetry = basis.get_dofs(lambda x: np.isclose(x[0], 0.0))
    prescribed = np.zeros(basis.N)
    prescribed[top.nodal["u^2"]] = -push
    D = np.unique(np.concatenate([top.nodal["u^1"], top.nodal["u^2"], symmetry.nodal["u^1"]]))
    K_free, f, _, free = condense(K, np.zeros(basis.N), x=prescribed, D=D)
    bottom = np.flatnonzero(np.isclose(mesh.p[1], 0.0))
    bottom = bottom[np.argsort(mesh.p[0, bottom])]
    x = mesh.p[0, bottom]
    m = bottom.size
    # the body moves down onto the cylinder: −u_y ≤ R − √(R² − x²)
    rows = sp.csr_matrix((-np.ones(m), (np.arange(m), 2 * bottom + 1)), shape=(m, basis.N))
    gap = R - np.sqrt(R ** 2 - x ** 2)
    d = gap - rows[:, D] @ prescribed[D]
    weights = np.zeros(m)
    weights[:-1] += 0.5 * np.diff(x)
    weights[1:] += 0.5 * np.diff(x)
    return K_free, f, rows[:, free], d, weights, mesh.p[:, bottom].T


def require(method: str) -> None:
    for module in get_method(method).requires:
        pytest.importorskip(module, reason=f"{method} needs {module}")


def user_problem(length: float, E: float, refine: int = 3):
    K, f, N, d, weights, points = half_block(length, E, refine)
    problem = signorini.ContactProblem.from_qp(K, f, N, d, weights=weights, contact_points=points)
    return problem, (K, f, N, d)


def lam_distance(result, exact) -> float:
    return float(np.max(np.abs(result.force - exact.force)) / np.max(np.abs(exact.force)))


@pytest.mark.parametrize("label, length, E", UNITS, ids=[u[0] for u in UNITS])
def test_every_route_is_certified_in_any_units(label, length, E):
    problem, _ = user_problem(length, E)
    exact = signorini.solve(problem, "pdas", tol=TOL)
    assert exact.converged and exact.active.sum() >= 2
    for method in ROUTES:
        require(method)
        result = signorini.solve(problem, method, tol=TOL)
        assert result.converged, (label, method, result.message)
        assert result.certificate.passed(TOL), (label, method)
        assert lam_distance(result, exact) <= AGREE, (label, method, lam_distance(result, exact))
        assert np.array_equal(result.active, exact.active), (label, method)


@pytest.mark.slow
def test_every_route_is_certified_on_a_fine_mesh_in_mm_and_mpa():
    problem, _ = user_problem(1.0, 2.1e5, refine=5)
    assert problem.n > 8000
    exact = signorini.solve(problem, "pdas", tol=TOL)
    for method in ROUTES:
        require(method)
        result = signorini.solve(problem, method, tol=TOL)
        assert result.converged, (method, result.message)
        assert lam_distance(result, exact) <= AGREE, (method, lam_distance(result, exact))


def test_outputs_are_in_the_users_units_and_meet_the_users_kkt():
    answers = {}
    for label, length, E in UNITS:
        problem, (K, f, N, d) = user_problem(length, E)
        result = signorini.solve(problem, "pdas", tol=TOL)
        u, lam = result.u, result.force
        # the KKT conditions of the arrays the user handed over, in the user's units
        imbalance = K @ u - f + N.T @ lam
        assert np.max(np.abs(imbalance)) <= 1e-9 * np.max(np.abs(N.T @ lam))
        assert np.max(N @ u - d) <= 1e-12 * np.max(np.abs(d))
        np.testing.assert_allclose(result.gap, d - N @ u, atol=1e-12 * np.max(np.abs(d)))
        np.testing.assert_allclose(result.displacement, u)
        np.testing.assert_allclose(result.pressure[result.active],
                                   (lam / problem.weights / problem.scales.weight)[result.active])
        answers[label] = (length, E, result)
    # one body in three unit systems: forces per unit thickness scale as E·length, u as length
    L0, E0, base = answers["SI"]
    for length, E, result in answers.values():
        np.testing.assert_allclose(result.u / length, base.u / L0, rtol=1e-8, atol=1e-12 * np.abs(base.u / L0).max())
        np.testing.assert_allclose(result.total_force / (E * length), base.total_force / (E0 * L0), rtol=1e-8)


def test_the_problem_a_built_in_method_sees_is_of_order_one():
    """The problem holds the user's arrays; a built-in method is handed a scaled view of them,
    made per run (the problem keeps no scaled copy). A :class:`Method` given to solve is run
    as declared (here a scaled one), without entering any table."""
    seen = []

    def spy(problem, *, tol, max_iter, **options):
        seen.append(problem)
        return get_method("pdas").function(problem, tol=tol, max_iter=max_iter)

    spec = Method(name="spy-of-order-one", function=spy, summary="records its problem",
                  family="active set")
    for _, length, E in UNITS:
        problem, (K, f, N, d) = user_problem(length, E)
        assert problem.K is not None and (problem.K != sp.csr_matrix(K)).nnz == 0
        assert problem.scales == signorini.Scales()
        result = signorini.solve(problem, spec, tol=TOL)
        view = seen[-1]
        assert view is not problem and result.converged and result.method == spec.name
        assert np.mean(view.K.diagonal()) == pytest.approx(1.0)
        assert 0.1 <= max(np.abs(view.d).max(), np.abs(view.f).max()) <= 10
        assert np.mean(view.weights) == pytest.approx(1.0)
        # the answer is mapped back: the user's own KKT conditions hold
        assert np.max(np.abs(K @ result.u - f + N.T @ result.force)) <= \
            1e-9 * np.max(np.abs(N.T @ result.force))
    assert spec.name not in REGISTRY


def test_the_qp_survives_save_and_load(tmp_path):
    problem, (K, f, N, d) = user_problem(1.0, 2.1e5)
    problem.save(tmp_path / "p.npz")
    again = signorini.ContactProblem.load(tmp_path / "p.npz")
    assert again.scales == problem.scales == signorini.Scales()
    assert np.array_equal(again.f, f) and np.array_equal(again.d, d)
    assert (again.K != K).nnz == 0 and (again.N != N).nnz == 0
    first, second = signorini.solve(problem, "pdas"), signorini.solve(again, "pdas")
    np.testing.assert_allclose(second.force, first.force)


def test_a_certificate_from_arrays_in_the_users_units():
    problem, _ = user_problem(1.0, 2.1e5)
    result = signorini.solve(problem, "pdas", tol=TOL)
    cert = signorini.certificate(problem, u=result.u, force=result.force)
    assert cert.passed(TOL) and signorini.certificate(problem, result.solution).passed(TOL)
    assert cert.stationarity == pytest.approx(result.certificate.stationarity, abs=1e-13)
    off = signorini.certificate(problem, u=result.u, force=1.01 * result.force)
    assert not off.passed(TOL) and off.passed(0.1)
    # the same arrays in the wrong units are not an answer
    assert not signorini.certificate(problem, u=result.u * 1e3, force=result.force).passed(1e-3)


@pytest.mark.parametrize("call, words", [
    (lambda p, r: signorini.certificate(p, u=r.u), "both u= "),
    (lambda p, r: signorini.certificate(p, r.solution, u=r.u, force=r.force), "not both"),
    (lambda p, r: signorini.certificate(p, u=r.u[:-1], force=r.force), "u must have"),
    (lambda p, r: signorini.certificate(p, u=r.u, force="forces"), "force"),
    (lambda p, r: r.certificate.passed(0), "tol must be a positive number"),
    (lambda p, r: r.certificate.passed("1e-9"), "tol must be a positive number"),
])
def test_a_certificate_refuses_bad_input(call, words):
    problem, _ = user_problem(1.0, 2.1e5, refine=1)
    result = signorini.solve(problem, "pdas")
    with pytest.raises(signorini.InputError, match=words):
        call(problem, result)


def test_contact_coordinates_of_a_users_qp_keep_their_sign():
    """Points given on x < 0 come back as given (a scene's x stays its distance from the axis)."""
    K, f, N, d, weights, points = half_block(1.0, 2.1e5, refine=2)
    mirrored = points * np.array([-1.0, 1.0])
    problem = signorini.ContactProblem.from_qp(K, f, N, d, weights=weights, contact_points=mirrored)
    result = signorini.solve(problem, "pdas")
    np.testing.assert_array_equal(result.x, mirrored[:, 0])
    assert result.to_dict()["contact"]["x"] == mirrored[:, 0].tolist() and result.x.min() < 0
    scene = signorini.solve("hertz-cylinder", "pdas")
    assert scene.x.min() >= 0.0
