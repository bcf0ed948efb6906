"""Signed-distance obstacles: normals and gaps, their units, a rotated patch test, the reverse Hertz."""

import numpy as np
import pytest
from skfem import MeshTri

import signorini
from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.obstacles import Circle, FlatPunch, HalfPlane, ScaledQuery, SignedDistance
from signorini.certification.comparison import compare
from signorini.references.pressure import compare_reverse_hertz, contact_profile, load_resultant
from signorini.scenes import build_problem
from signorini.fem.model import FlatObstacle, SceneModel
from signorini.solvers.registry import solve

RNG = np.random.default_rng(7)


def test_half_plane_is_the_flat_of_the_core():
    points = RNG.uniform(-1, 1, (20, 2))
    n_flat, g_flat = FlatObstacle(0.25).normals_and_gaps(points)
    n, g = HalfPlane((3.0, 0.25), (0.0, -2.0)).normals_and_gaps(points)
    np.testing.assert_allclose(n, n_flat)
    np.testing.assert_allclose(g, g_flat)


def test_circle_normals_point_to_the_centre_and_gaps_are_distances():
    centre = np.array([0.3, -2.0])
    points = RNG.uniform(-1, 1, (30, 2))
    n, g = Circle(tuple(centre), 1.5).normals_and_gaps(points)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    to_centre = centre - points
    np.testing.assert_allclose(n, to_centre / np.linalg.norm(to_centre, axis=1)[:, None])
    np.testing.assert_allclose(g, np.linalg.norm(to_centre, axis=1) - 1.5)
    # the gap is the distance along n: moving by g along n lands on the circle
    np.testing.assert_allclose(np.linalg.norm(points + g[:, None] * n - centre, axis=1), 1.5)


def test_numerical_gradient_matches_the_analytic_one():
    circle = Circle((0.0, -1.0), 1.0)
    numeric = SignedDistance(circle.signed_distance)
    points = np.column_stack([np.linspace(-0.4, 0.4, 9), np.zeros(9)])
    n_a, g_a = circle.normals_and_gaps(points)
    n_n, g_n = numeric.normals_and_gaps(points)
    np.testing.assert_allclose(g_n, g_a, atol=1e-10)
    np.testing.assert_allclose(n_n, n_a, atol=1e-8)


def test_a_level_set_that_is_not_a_distance_gives_first_order_gaps():
    # φ = 3(y − 0.1) has |∇φ| = 3: the gap is still y − 0.1 and the normal (0, −1)
    obstacle = SignedDistance(lambda p: 3.0 * (p[:, 1] - 0.1), gradient=lambda p: np.tile([0.0, 3.0], (len(p), 1)))
    points = RNG.uniform(0, 1, (5, 2))
    n, g = obstacle.normals_and_gaps(points)
    np.testing.assert_allclose(g, points[:, 1] - 0.1)
    np.testing.assert_allclose(n, np.tile([0.0, -1.0], (5, 1)))


def test_a_vanishing_gradient_is_an_input_error():
    obstacle = SignedDistance(lambda p: np.zeros(len(p)), gradient=lambda p: np.zeros_like(p))
    with pytest.raises(InputError, match="no normal"):
        obstacle.normals_and_gaps(np.zeros((2, 2)))
    with pytest.raises(InputError, match="radius"):
        Circle((0.0, 0.0), -1.0)


@pytest.mark.parametrize("radius", [0.0, 0.2])
def test_punch_face_edge_and_corner(radius):
    punch = FlatPunch(half_width=1.0, corner_radius=radius)
    x = np.array([0.0, 0.5, 1.0])
    n, g = punch.normals_and_gaps(np.column_stack([x, np.zeros(3)]))
    np.testing.assert_allclose(g, 0.0, atol=1e-15)
    np.testing.assert_allclose(n, np.tile([0.0, -1.0], (3, 1)))  # the edge itself takes the face's normal
    # above the face, the gap is the height
    n, g = punch.normals_and_gaps(np.array([[0.3, 0.7]]))
    assert g[0] == pytest.approx(0.7)
    if radius:
        # on the rounded corner the normal points to the corner's centre (1, −r)
        point = np.array([[1.0 + 0.5 * radius, 0.0]])
        n, g = punch.normals_and_gaps(point)
        offset = point[0] - [1.0, -radius]
        assert g[0] == pytest.approx(np.linalg.norm(offset) - radius)
        np.testing.assert_allclose(n[0], -offset / np.linalg.norm(offset))
        numeric = SignedDistance(punch.signed_distance).normals_and_gaps(point)
        np.testing.assert_allclose(numeric[0], n, atol=1e-7)


def test_scaled_query_answers_in_the_unit_it_is_asked_in():
    physical = np.array([[0.0, 0.0], [0.004, 0.0], [0.01, 0.0]])
    circle = Circle((0.0, -0.05), 0.05)
    wrapped = ScaledQuery(circle, physical, 0.01)
    n1, g1 = wrapped.normals_and_gaps(physical)
    n2, g2 = wrapped.normals_and_gaps(physical / 0.01)
    np.testing.assert_allclose(n1, n2)
    np.testing.assert_allclose(g2 * 0.01, g1)
    with pytest.raises(ValueError):
        wrapped.normals_and_gaps(physical + 1.0)


def _rotated_block(theta: float, obstacle_factory, delta=0.01, n=6):
    """A whole block [−1, 1] × [0, 1] rotated by θ, top clamped and pushed along −n, ν = 0."""
    mesh = MeshTri.init_tensor(np.linspace(-1, 1, 2 * n + 1), np.linspace(0, 1, n + 1))
    c, s = np.cos(theta), np.sin(theta)
    rotation = np.array([[c, -s], [s, c]])
    x, y = mesh.p
    bottom = np.nonzero(np.abs(y) < 1e-12)[0]
    top = np.nonzero(np.abs(y - 1) < 1e-12)[0]
    facets = mesh.boundary_facets()
    on_bottom = np.all(np.isin(mesh.facets[:, facets], bottom), axis=0)
    mesh = MeshTri(rotation @ mesh.p, mesh.t)
    down = rotation @ np.array([0.0, -1.0])
    model = SceneModel(
        mesh=mesh, E=3.0, nu=0.0,
        dirichlet=[(0, top, delta * down[0]), (1, top, delta * down[1])],
        contact_nodes=bottom, contact_facets=facets[on_bottom],
        obstacle=obstacle_factory(mesh.p[:, bottom].T, tuple(down)), load_dofs=(1, top),
        length_scale=1.0, params={"E": 3.0, "nu": 0.0})
    return model


@pytest.mark.parametrize("theta", [0.0, 0.3, -1.1])
@pytest.mark.parametrize("nondimensionalise", [True, False])
def test_rotated_block_on_a_rotated_flat_has_uniform_pressure(theta, nondimensionalise):
    """Patch test of the normal rows: with ν = 0 the pressure is E δ / H whatever the angle."""
    model = _rotated_block(theta, lambda points, down: HalfPlane((0.0, 0.0), down))
    problem = assemble(model, nondimensionalise=nondimensionalise)
    solution = solve(problem, "pdas", tol=1e-10)
    profile = contact_profile(problem, solution)
    assert np.all(profile.active)
    np.testing.assert_allclose(profile.pressure, 3.0 * 0.01 / 1.0, rtol=1e-10)
    # the same through a general signed-distance function with numerical normals
    down = np.array(model.obstacle.normal)
    sdf = SignedDistance(lambda p: -(p @ down))
    model_sdf = _rotated_block(theta, lambda points, d: sdf)
    other = solve(assemble(model_sdf, nondimensionalise=nondimensionalise), "pdas", tol=1e-10)
    np.testing.assert_allclose(other.lam, solution.lam, rtol=1e-8)


# --- the reverse Hertz: a block pressed onto a rigid cylinder ---------------------------------

SMALL = {"n_contact": 32, "grading": 0.5}


@pytest.fixture(scope="module")
def reverse():
    problem = signorini.at_load(build_problem("reverse-hertz", params=SMALL))
    return problem, solve(problem, "pdas", tol=1e-10)


def test_reverse_hertz_rows_follow_the_cylinder(reverse):
    problem, _ = reverse
    N = problem.N.toarray()
    points = problem.contact_points * problem.scales.length
    R = problem.model.params["R"]
    for row, (x, y) in zip(N, points):
        entries = row[row != 0]
        expected = np.array([-x, -R]) / np.hypot(x, R)
        if x > 0:  # the symmetry node has u_x prescribed: only its y entry remains
            np.testing.assert_allclose(entries, expected, rtol=1e-10)
        else:
            np.testing.assert_allclose(entries, [-1.0])
    # initial gaps are the distances to the circle, in units of the displacement scale
    gaps = np.hypot(points[:, 0], R) - R
    assert problem.d.max() * problem.scales.displacement > 0.5 * gaps.max()


def test_reverse_hertz_force_balance_and_tilted_normals(reverse):
    problem, solution = reverse
    resultant = load_resultant(problem, solution.lam)
    profile = contact_profile(problem, solution)
    assert resultant == pytest.approx(profile.applied_load, rel=1e-9)
    # the total normal force exceeds the vertical load by the tilt, but only slightly (a/R = 0.02)
    assert profile.total_force > resultant
    assert profile.total_force == pytest.approx(resultant, rel=1e-3)


def test_reverse_hertz_matches_hertz_at_the_default_mesh():
    problem = signorini.at_load(build_problem("reverse-hertz"))
    hertz = compare_reverse_hertz(problem, solve(problem, "pdas", tol=1e-10))
    assert hertz.p0_rel < 0.01 and hertz.a_rel < 0.01 and hertz.pressure_l2_rel < 0.03
    assert hertz.force_balance < 1e-9


def test_reverse_hertz_whole_block_is_symmetric_and_equals_the_half(reverse):
    half_problem, half = reverse
    problem = signorini.at_load(build_problem("reverse-hertz", params={"half": 0, **SMALL}))
    whole = solve(problem, "pdas", tol=1e-10)
    profile = contact_profile(problem, whole)
    x, p = problem.contact_points[:, 0] * problem.scales.length, profile.pressure
    order, mirror = np.argsort(x), np.argsort(-x)
    np.testing.assert_allclose(p[order], p[mirror], rtol=1e-8, atol=1e-10 * p.max())
    half_profile = contact_profile(half_problem, half)
    right = x >= 0
    np.testing.assert_allclose(np.sort(x[right]), half_profile.x, atol=1e-10)
    np.testing.assert_allclose(p[right][np.argsort(x[right])], half_profile.pressure, rtol=1e-7)
    assert load_resultant(problem, whole.lam) == pytest.approx(load_resultant(half_problem, half.lam),
                                                               rel=1e-8)


def test_reverse_hertz_uzawa_agrees_with_pdas(reverse):
    problem, exact = reverse
    uzawa = solve(problem, "uzawa", tol=1e-10)
    assert uzawa.status == "converged"
    difference = compare(problem, exact, uzawa)
    assert difference.lam_rel < 1e-6 and difference.misclassified == 0
