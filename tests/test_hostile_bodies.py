"""Two bodies and the certificate, attacked as a hostile user would.

"converged" must mean right for the model and the model adequate: a QP with no minimum is never
converged, whichever factorisation the method hands the certificate; a perturbed or wrongly
signed answer of a two-body problem is never certified.
"""

import numpy as np
import pytest

import signorini
from signorini import ContactProblem

#: a coarse pair of unlike cylinders: small, non-matching faces, every part of the two-body path
PAIR = {"n_contact": 8, "grading": 0.6, "mesher": "triangle", "E2": 3.0, "R2": 2.0}


def saddle_qp():
    """K = diag(1, −1): ½uᵀKu − fᵀu falls without bound as u₁ → −∞, yet both rows are active at
    the KKT point (0.5, 1), so a factorisation with both dofs pinned succeeds."""
    return ContactProblem.from_qp(np.diag([1.0, -1.0]), [1.0, 0.0], np.eye(2), [0.5, 1.0])


@pytest.mark.parametrize("method", ["qp-clarabel", "cvxpy"])
def test_an_indefinite_qp_is_not_converged_through_a_polished_answer(method):
    pytest.importorskip("clarabel", reason="the polished backends need Clarabel")
    result = signorini.solve(saddle_qp(), method)
    assert result.status != "converged"
    assert np.isinf(result.certificate.duality_gap)
    assert "positive semidefinite" in result.message


def test_an_indefinite_qp_is_not_certified_on_a_pinned_factorisation():
    from signorini.numerics.active_set import PinnedFactor
    from signorini.problem.contact import ContactSolution
    from signorini.certification.kkt import certificate
    problem = saddle_qp()
    answer = ContactSolution(method="given", u=np.array([0.5, 1.0]), lam=np.array([0.5, 1.0]),
                             status="converged", factor=PinnedFactor(problem.K, np.array([0, 1])))
    cert = certificate(problem, answer)
    assert not cert.passed(1e-8) and np.isinf(cert.duality_gap)


def test_a_qp_with_no_minimum_is_judged_indefinite_once(monkeypatch):
    """The certificate that finds no minimum says so to its own fallback: the eigenvalue check
    (and, past the dense size, a shifted factorisation) runs once, not once more on the way out."""
    from signorini.certification import kkt
    from signorini.numerics.active_set import PinnedFactor
    from signorini.problem.contact import ContactSolution
    calls = []
    monkeypatch.setattr(kkt, "indefinite", lambda K: calls.append(K) or True)
    problem = saddle_qp()
    answer = ContactSolution(method="given", u=np.array([0.5, 1.0]), lam=np.array([0.5, 1.0]),
                             status="converged", factor=PinnedFactor(problem.K, np.array([0, 1])))
    assert np.isinf(kkt.certificate(problem, answer).duality_gap)
    assert len(calls) == 1


def test_a_singular_qp_held_by_its_contact_keeps_its_verdict():
    """K = [[1, −1], [−1, 1]] leaves a rigid mode that the active row holds: the answer is unique,
    and a singular K that is not indefinite keeps the other residuals' verdict."""
    problem = ContactProblem.from_qp(np.array([[1.0, -1.0], [-1.0, 1.0]]), [0.0, 1.0],
                                     [[0.0, 1.0]], [1.0])
    cert = signorini.certificate(problem, u=np.array([1.0, 1.0]), force=np.array([1.0]))
    assert cert.passed(1e-8)


@pytest.fixture(scope="module")
def pair():
    return signorini.solve("hertz-two-cylinders", "pdas", params=PAIR, tol=1e-12)


def test_the_pair_is_certified_as_solved(pair):
    assert pair.status == "converged"
    assert signorini.certificate(pair.problem, u=pair.u, force=pair.force).passed(1e-10)


@pytest.mark.parametrize("attack", ["u", "force", "sign", "inactive"])
def test_a_spoiled_answer_of_two_bodies_is_not_certified(pair, attack):
    rng = np.random.default_rng(3)
    u, force = pair.u.copy(), pair.force.copy()
    if attack == "u":
        u += 1e-6 * np.abs(u).max() * rng.standard_normal(u.size)
    elif attack == "force":
        force *= 1 + 1e-6 * rng.standard_normal(force.size)
    elif attack == "sign":
        force = -force
    else:
        force[~pair.active] = 1e-7 * force.max()
    cert = signorini.certificate(pair.problem, u=u, force=force)
    assert not cert.passed(1e-8)
    if attack in ("force", "inactive"):  # the forward error sees the force it was given
        true = np.abs(force - pair.force).max() / np.abs(force).max()
        assert cert.force_error >= 0.5 * true


def test_contact_that_reaches_the_last_row_short_of_the_slave_face_is_not_converged():
    """A flat upper cylinder on a thin lower one: the slave face (three half-widths) reaches past
    the lower cylinder, so its outer candidates have no row. Pushed ten times harder than the
    target, the contact reaches the last row: the zone may go on where the QP has no rows."""
    params = {"n_contact": 8, "grading": 0.6, "mesher": "triangle", "R1": 100.0, "R2": 0.1,
              "candidates": 3.0, "a_over_R": 0.5}
    problem = signorini.build_problem("hertz-two-cylinders", params=params)
    matched = signorini.solve(problem, "pdas")
    assert matched.status == "converged"  # the contact ends inside the rows
    push = matched.problem.model.push
    pushed = signorini.solve(problem.pushed(10 * push.scale, load=10 * push.load), "pdas")
    last = np.argmax(pushed.problem.contact_points[:, 0])
    assert pushed.active[last]
    assert pushed.status == "model_inadequate", pushed.message


def test_a_mesh_ratio_that_leaves_the_slave_face_no_element_is_refused():
    """round(0.04 · 10) = 0 elements: refused, not silently raised to one (the record would say
    0.04 while the mesh had 0.1)."""
    with pytest.raises(signorini.errors.InputError, match="mesh_ratio"):
        signorini.build_problem("two-block-patch", params={"mesh_ratio": 0.04})


def grid_laplacian(side):
    """The 5-point Laplacian on a side × side grid (SPD, side² dofs)."""
    import scipy.sparse as sp
    T = sp.diags([-np.ones(side - 1), 2 * np.ones(side), -np.ones(side - 1)], [-1, 0, 1])
    return (sp.kron(T, sp.eye(side)) + sp.kron(sp.eye(side), T)).tocsr()


def test_a_slightly_indefinite_qp_beyond_dense_eigenvalues_is_not_converged():
    """900 dofs (past dense eigenvalues): the Laplacian shifted so that its lowest eigenvalue is
    −10⁻⁶ of the lowest positive one's size, −5·10⁻⁸ of its diagonal, far above round-off. A
    Rayleigh quotient does not reach it in a few dozen steps; the QP still has no minimum."""
    pytest.importorskip("sksparse.cholmod", reason="the shifted factorisation is CHOLMOD's")
    from scipy.sparse.linalg import eigsh
    import scipy.sparse as sp
    L = grid_laplacian(30)
    lowest = eigsh(L, k=1, sigma=0, which="LM")[0][0]
    K = (L - (1 + 1e-5) * lowest * sp.eye(L.shape[0])).tocsr()
    rows = np.arange(40)
    N = sp.csr_matrix((np.ones(rows.size), (rows, rows)), shape=(rows.size, K.shape[0]))
    f = np.zeros(K.shape[0])
    f[rows] = 1.0
    result = signorini.solve(ContactProblem.from_qp(K, f, N, np.zeros(rows.size)), "qp-osqp")
    assert result.status != "converged", result.message
    assert np.isinf(result.certificate.duality_gap)


@pytest.mark.parametrize("nu1, nu2", [(0.3, 0.49), (0.49, 0.3)])
def test_either_body_of_a_pair_that_locks_is_warned_of(nu1, nu2):
    """Plain P1 with ν = 0.49 locks whichever body has it: the master's material is warned of as
    the slave's is."""
    from signorini.certification.adequacy import warnings
    problem = signorini.build_problem("hertz-two-cylinders", params={
        **PAIR, "E2": 1.0, "R2": 1.0, "nu1": nu1, "nu2": nu2, "volumetric": "element"})
    assert any("ν = 0.49" in said for said in warnings(problem))


def test_a_push_too_small_for_the_sphere_pairs_graded_mesh_is_refused():
    """hertz-two-spheres grades its meshes for √(δ R*): δ = 1e-300 asked Triangle for a mesh
    graded to 1e-150 R and crashed the process. Refused in one line, as hertz-sphere refuses it."""
    with pytest.raises(signorini.errors.InputError, match="delta"):
        signorini.build_problem("hertz-two-spheres", params={"delta": 1e-300, "n_contact": 8})


def test_a_push_too_small_for_double_precision_is_refused_on_cylinders_too():
    """δ = 1e-300 on two cylinders: the gaps, divided by δ, left even the first point of contact
    open, and the answer was converged with nothing in contact while the bodies were pushed
    together."""
    with pytest.raises(signorini.errors.InputError, match="delta"):
        signorini.build_problem("hertz-two-cylinders", params={"delta": 1e-300, **PAIR})


def test_dual_mortar_rows_of_a_slave_face_the_master_covers_in_part_hold():
    """The lower block moved half its width aside: the slave segment over the master's end is
    covered in part. The whole segment's dual basis gave its node ∫ ψₛ φₛ = 0 there, the row
    divided by it asked for a gap of −1, and pdas's answer broke it. Biorthogonal on the covered
    part, every row holds and the answer is certified; its node ends the rows where the slave
    goes on facing the master, so the zone there is watched."""
    import dataclasses
    from signorini.scenes.two_block_patch import FAMILY, build
    params = {param.name: param.default for param in FAMILY.params}
    model = build({**params, "delta": 0.02}, {"delta"})
    lower = model.master
    moved = dataclasses.replace(lower, mesh=type(lower.mesh)(lower.mesh.p + [[0.5], [0.0]],
                                                             lower.mesh.t))
    problem = dataclasses.replace(model, master=moved).assemble()
    result = signorini.solve(problem, "pdas")
    assert result.certificate.passed(1e-8)
    assert result.status == "model_inadequate"
    assert np.all(result.force >= 0)


@pytest.mark.parametrize("spoil", ["force", "u"])
def test_an_answer_edited_in_place_is_judged_again(spoil):
    """The certificate kept on a solution was returned for the same arrays whatever their values:
    an answer scaled in place by 1 % still passed."""
    result = signorini.solve("two-block-patch", "pdas")
    solution = result.solution
    assert signorini.certificate(result.problem, solution).passed(1e-8)
    if spoil == "force":
        solution.lam *= 1.01
    else:
        solution.u[:] = 0.0
    assert not signorini.certificate(result.problem, solution).passed(1e-8)
