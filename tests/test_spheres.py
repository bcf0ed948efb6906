"""Hertz's sphere, axisymmetric and 3D: assembly, patch tests, symmetry, force balance, accuracy.

Expected values come from elasticity theory (uniform dilation, uniaxial stress) and Hertz's
solution (Johnson 1985, §4.2); the sphere results are those of ``validation/hertz_sphere.py``.
"""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from skfem import Basis, ElementTriP1, ElementVector, MeshTet, MeshTri, asm
from skfem.models.elasticity import lame_parameters

import signorini
from signorini.references.analytic import contact_modulus, hertz_sphere_load, hertz_sphere_peak, hertz_sphere_radius
from signorini.errors import InputError
from signorini.fem.assembly import assemble, axisymmetric_elasticity
from signorini.references.pressure import contact_profile, radial_distance
from signorini.scenes import build_problem
from signorini.fem.model import FlatObstacle, SceneModel
from signorini.solvers.registry import solve

VALIDATION = Path(__file__).resolve().parents[1] / "validation"


@pytest.fixture(scope="module")
def spheres():
    spec = importlib.util.spec_from_file_location("hertz_sphere", VALIDATION / "hertz_sphere.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def exact(problem):
    solution = solve(problem, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


# --- the axisymmetric form -------------------------------------------------------------------


def test_axisymmetric_energy_of_a_uniform_dilation_is_exact():
    # u = ε (r, z): ε_rr = ε_zz = ε_θθ = ε, so a(u, u) = ε² (6μ + 9λ) ∫ r dA, ∫ r dA = W²H/2
    W, H, eps, E, nu = 2.0, 3.0, 1e-3, 5.0, 0.3
    mesh = MeshTri.init_tensor(np.linspace(0, W, 7), np.linspace(0, H, 5))
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    K = asm(axisymmetric_elasticity(*lame_parameters(E, nu)), basis)
    Lambda, Mu = lame_parameters(E, nu)
    u = np.zeros(basis.N)
    u[basis.nodal_dofs[0]] = eps * mesh.p[0]
    u[basis.nodal_dofs[1]] = eps * mesh.p[1]
    assert u @ K @ u == pytest.approx(eps ** 2 * (6 * Mu + 9 * Lambda) * W ** 2 * H / 2, rel=1e-12)
    # an axial translation is rigid; a radial one is not (it stretches the hoops)
    axial = np.zeros(basis.N)
    axial[basis.nodal_dofs[1]] = 1.0
    radial = np.zeros(basis.N)
    radial[basis.nodal_dofs[0]] = 1.0
    assert np.max(np.abs(K @ axial)) <= 1e-12 * abs(K).max()
    assert radial @ K @ radial > 1e-3 * abs(K).max()


def test_axisymmetric_stiffness_is_symmetric(spheres):
    K = spheres.axisymmetric.K
    assert abs(K - K.T).max() <= 1e-14 * abs(K).max()


# --- patch tests: uniaxial stress, exact for P1 ------------------------------------------------


def _cylinder_on_flat(W=0.4, H=0.3, E=70e9, nu=0.33, delta=1e-4):
    """A solid cylinder of radius W and height H on a frictionless flat, axisymmetric."""
    mesh = MeshTri.init_tensor(np.linspace(0, W, 9), np.linspace(0, H, 7))
    r, z = mesh.p
    tol = 1e-12
    bottom = np.nonzero(np.abs(z) < tol)[0]
    facets = mesh.boundary_facets()
    on_bottom = np.all(np.isin(mesh.facets[:, facets], bottom), axis=0)
    top = np.nonzero(np.abs(z - H) < tol)[0]
    return SceneModel(
        mesh=mesh, E=E, nu=nu,
        dirichlet=[(0, np.nonzero(np.abs(r) < tol)[0], 0.0), (1, top, -delta)],
        contact_nodes=bottom[np.argsort(r[bottom])], contact_facets=facets[on_bottom],
        obstacle=FlatObstacle(0.0), load_dofs=(1, top), length_scale=H,
        force_multiplicity=2 * np.pi, params={"E": E, "nu": nu}, axisymmetric=True)


def test_axisymmetric_patch_test_uniaxial_stress():
    # free lateral surface and frictionless base: σ_zz = −Eδ/H, p = Eδ/H (E, not E*),
    # and the whole cylinder carries P = πW²·Eδ/H
    W, H, E, delta = 0.4, 0.3, 70e9, 1e-4
    problem = assemble(_cylinder_on_flat(W, H, E, delta=delta))
    solution = exact(problem)
    profile = contact_profile(problem, solution)
    p = E * delta / H
    np.testing.assert_allclose(profile.pressure, p, rtol=1e-9)
    assert profile.total_force == pytest.approx(np.pi * W ** 2 * p, rel=1e-10)
    assert profile.applied_load == pytest.approx(profile.total_force, rel=1e-10)
    # per radian: forces in units of E·U·L, weights ∫ φ r ds in units of L², Σw = W²/2
    s = problem.scales
    assert s.force == pytest.approx(E * s.displacement * s.length, rel=1e-14)
    assert problem.weights.sum() * s.weight == pytest.approx(W ** 2 / 2, rel=1e-12)
    assert np.sum(solution.lam) * s.force == pytest.approx(profile.total_force / (2 * np.pi), rel=1e-12)


def test_three_d_patch_test_uniaxial_stress():
    # the quarter [0, W]² × [0, H] of a 2W × 2W block, symmetry planes x = 0 and y = 0
    W, H, E, nu, delta = 0.5, 0.2, 2.1e11, 0.3, 1e-5
    grid = np.linspace(0, W, 5)
    mesh = MeshTet.init_tensor(grid, grid, np.linspace(0, H, 4))
    x, y, z = mesh.p
    tol = 1e-12
    bottom = np.nonzero(np.abs(z) < tol)[0]
    facets = mesh.boundary_facets()
    on_bottom = np.all(np.isin(mesh.facets[:, facets], bottom), axis=0)
    top = np.nonzero(np.abs(z - H) < tol)[0]
    model = SceneModel(
        mesh=mesh, E=E, nu=nu,
        dirichlet=[(0, np.nonzero(np.abs(x) < tol)[0], 0.0), (1, np.nonzero(np.abs(y) < tol)[0], 0.0),
                   (2, top, -delta)],
        contact_nodes=bottom, contact_facets=facets[on_bottom], obstacle=FlatObstacle(0.0),
        load_dofs=(2, top), length_scale=H, force_multiplicity=4.0, params={"E": E, "nu": nu})
    problem = assemble(model)
    assert problem.N.shape[1] == problem.n and problem.contact_points.shape[1] == 3
    solution = exact(problem)
    profile = contact_profile(problem, solution)
    p = E * delta / H
    np.testing.assert_allclose(profile.pressure, p, rtol=1e-9)
    assert profile.total_force == pytest.approx((2 * W) ** 2 * p, rel=1e-10)
    assert profile.applied_load == pytest.approx(profile.total_force, rel=1e-10)
    assert problem.weights.sum() * problem.scales.weight == pytest.approx(W ** 2, rel=1e-12)


# --- the sphere scenes -------------------------------------------------------------------------


def test_axisymmetric_sphere_within_one_percent_of_hertz(spheres):
    h = spheres.hertz_axisymmetric
    assert spheres.axisymmetric.n <= 20_000
    assert h.p0_rel < 0.01
    assert h.a_rel < 0.01
    assert h.pressure_l2_rel < 0.01


def test_three_d_quarter_within_three_percent_of_hertz(spheres):
    h = spheres.hertz_three_d
    assert h.p0_rel < 0.03
    assert h.a_rel < 0.03
    assert h.pressure_l2_rel < 0.06
    # contact candidates only near the contact: within `candidates` (1.3) contact radii
    problem = spheres.three_d
    rho = radial_distance(problem.contact_points) * problem.scales.length
    assert rho.max() <= 1.3 * spheres.PARAMS["a_over_R"] * spheres.PARAMS["R"] * (1 + 1e-9)
    assert h.edge_margin > 1.2


@pytest.mark.parametrize("model", ["axisymmetric", "three_d"])
def test_force_balance_and_load_targeting(spheres, model):
    problem, solution = getattr(spheres, model), getattr(spheres, f"exact_{model}")
    profile = contact_profile(problem, solution)
    params = spheres.PARAMS
    E_star = contact_modulus(params["E"], params["nu"])
    target = hertz_sphere_load(params["a_over_R"] * params["R"], params["R"], E_star)
    # ∫ p dA = Σ pᵢ wᵢ (times the copies of the model) = P = the reaction of the loaded cut
    w = problem.weights * problem.scales.weight
    assert problem.force_multiplicity * np.sum(profile.pressure * w) == pytest.approx(target, rel=1e-9)
    assert profile.total_force == pytest.approx(target, rel=1e-9)
    assert profile.applied_load == pytest.approx(target, rel=1e-8)


@pytest.mark.parametrize("model", ["axisymmetric", "three_d"])
def test_exact_methods_agree(spheres, model):
    uzawa = getattr(spheres, f"uzawa_{model}")
    agreement = getattr(spheres, f"agreement_{model}")
    assert uzawa.status == "converged"
    assert agreement.lam_rel < 1e-6
    assert agreement.misclassified == 0


def test_three_d_pressure_is_axisymmetric(spheres):
    # pressure against radius along the two symmetry planes: the same curve
    along_x, along_y = spheres.plane_profiles
    p0 = spheres.hertz_three_d.p0_ref
    assert along_x.x.size == along_y.x.size >= 10
    np.testing.assert_allclose(along_x.x, along_y.x, rtol=0, atol=1e-12 * spheres.PARAMS["R"])
    assert np.max(np.abs(along_x.pressure - along_y.pressure)) < 1e-3 * p0
    np.testing.assert_array_equal(along_x.active, along_y.active)


def test_models_agree_with_each_other(spheres):
    ax, td = spheres.hertz_axisymmetric, spheres.hertz_three_d
    assert abs(td.a / ax.a - 1) < 0.03
    assert abs(td.p0 / ax.p0 - 1) < 0.03
    # node by node inside 0.9 a, the 3D pressures scatter about the axisymmetric p(r)
    problem, solution = spheres.three_d, spheres.exact_three_d
    r_ax = radial_distance(spheres.axisymmetric.contact_points) * spheres.axisymmetric.scales.length
    p_ax = contact_profile(spheres.axisymmetric, spheres.exact_axisymmetric).pressure
    rho = radial_distance(problem.contact_points) * problem.scales.length
    inside = rho < 0.9 * ax.a_ref
    deviation = (contact_profile(problem, solution).pressure - np.interp(rho, r_ax, p_ax)) / ax.p0_ref
    assert np.max(np.abs(deviation[inside])) < 0.10
    assert np.sqrt(np.mean(deviation[inside] ** 2)) < 0.05


def test_sphere_formulas_are_consistent():
    P, R, E_star = 3.0, 0.02, 1.1e11
    a = hertz_sphere_radius(P, R, E_star)
    assert hertz_sphere_load(a, R, E_star) == pytest.approx(P, rel=1e-14)
    # ∫ p₀√(1 − r²/a²) 2πr dr = (2/3)πa²p₀ = P
    assert 2 / 3 * np.pi * a ** 2 * hertz_sphere_peak(P, a) == pytest.approx(P, rel=1e-14)


def test_dimensionless_answer_does_not_depend_on_units():
    coarse = {"n_contact": 12, "a_over_R": 0.05}
    one = signorini.at_load(build_problem("hertz-sphere", params=coarse))
    steel = signorini.at_load(build_problem("hertz-sphere", params={**coarse, "E": 2.1e11, "R": 0.01}))
    # force = E·U·L with U ∝ R and L = R
    assert steel.scales.force == pytest.approx(2.1e11 * 0.01 ** 2 * one.scales.force, rel=1e-12)
    lam_one, lam_steel = exact(one).lam, exact(steel).lam
    assert np.max(np.abs(lam_one - lam_steel)) < 1e-8 * np.max(np.abs(lam_one))


@pytest.mark.parametrize("scene", ["hertz-sphere", "hertz-sphere-3d"])
def test_a_prescribed_load_is_met(scene):
    problem = signorini.at_load(build_problem(scene, params={"P": 2e-4, "n_contact": 6}))
    solution = exact(problem)
    assert problem.total_contact_force(solution.lam) * problem.scales.force == pytest.approx(2e-4, rel=1e-9)


@pytest.mark.parametrize("scene", ["hertz-sphere", "hertz-sphere-3d"])
def test_conflicting_or_excessive_loads_are_refused(scene):
    with pytest.raises(InputError, match="give only one of"):
        signorini.at_load(build_problem(scene, params={"P": 1e-3, "delta": 1e-3}))
    with pytest.raises(InputError, match="a/R"):
        signorini.at_load(build_problem(scene, params={"P": 1.0}))


def test_prescribed_delta_is_recorded():
    problem = signorini.at_load(build_problem("hertz-sphere", params={"delta": 0.002, "n_contact": 8}))
    assert problem.model.params["delta"] == 0.002 and problem.model.params["P"] is None
    assert problem.total_contact_force(exact(problem).lam) > 0
