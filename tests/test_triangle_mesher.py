"""``mesher=triangle``: the Hertz discs meshed by Shewchuk's Triangle (signorini.scenes.triangulated).

Its meshes have near-equilateral triangles, arc nodes on the circle, the same shape in any
units, a size guard that covers them, and Hertz's a and p₀ within 0.2 % at the scenes'
defaults (docs/mesher.md measures them against the relaxed and bisection meshes).
"""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.scenes.families import get_scene
from signorini.scenes.meshing import graded_quarter_disc
from signorini.scenes.size import estimate_dofs

SCENES = ("hertz-cylinder", "hertz-sphere")
TRIANGLE = {"mesher": "triangle"}


def smallest_angles(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The smallest angle of each triangle, in degrees."""
    corners = p[:, t]  # (2, 3, triangles)
    angles = []
    for i in range(3):
        u = corners[:, (i + 1) % 3] - corners[:, i]
        v = corners[:, (i + 2) % 3] - corners[:, i]
        cosine = np.sum(u * v, axis=0) / (np.linalg.norm(u, axis=0) * np.linalg.norm(v, axis=0))
        angles.append(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))
    return np.min(angles, axis=0)


@pytest.mark.parametrize("scene", SCENES)
def test_the_default_scenes_meshed_by_triangle_solve_within_a_fifth_of_a_percent_of_hertz(scene):
    result = signorini.solve(scene, params=TRIANGLE, tol=1e-10)
    assert result.status == "converged", result.message
    hertz = result.hertz
    assert abs(hertz.a / hertz.a_ref - 1) < 2e-3 and abs(hertz.p0 / hertz.p0_ref - 1) < 2e-3, hertz


@pytest.mark.parametrize("n_contact, grading", [(40, 0.15), (60, 0.15), (10, 0.6), (80, 0.07)])
def test_no_triangle_has_an_angle_below_28_degrees(n_contact, grading):
    mesh = graded_quarter_disc(1.0, 0.05, n_contact, grading, mesher="triangle").mesh
    assert smallest_angles(mesh.p, mesh.t).min() >= 28.0
    bisection = graded_quarter_disc(1.0, 0.05, n_contact, grading, mesher="bisection").mesh
    assert np.median(smallest_angles(mesh.p, mesh.t)) > np.median(smallest_angles(bisection.p, bisection.t))


@pytest.mark.parametrize("R", [1.0, 0.02])
def test_the_arc_candidates_lie_on_the_circle_sorted_from_the_first_point_of_contact(R):
    disc = graded_quarter_disc(R, 0.05, 40, 0.15, candidate_extent=2.0, mesher="triangle")
    x, y = disc.mesh.p[:, disc.candidates]
    assert np.max(np.abs(np.hypot(x, y - R) - R)) <= 1e-12 * R
    assert np.all(np.diff(x) > 0) and x[0] == 0.0 and y[0] == 0.0
    assert x[-1] <= 2.0 * 0.05 * R * (1 + 1e-9) and len(x) > 2 * 40  # n_contact elements across a


@pytest.mark.parametrize("scene", SCENES)
def test_the_mesh_is_the_same_in_two_sets_of_units(scene):
    """a/R computed from the load in the second set differs in its last bit (0.049999999999999996
    against 0.05); Triangle's mesh is built from it to 12 digits."""
    family = get_scene(scene)
    meshes = []
    for units in ({"R": 1.0, "E": 1.0}, {"R": 0.003, "E": 3e9}):  # a/R differs there in its last bit
        values = {**TRIANGLE, **units}
        mesh = family.build(family.parse(values), set(values)).mesh
        meshes.append((mesh.p / units["R"], mesh.t))
    (p1, t1), (p2, t2) = meshes
    assert np.array_equal(t1, t2)
    np.testing.assert_allclose(p1, p2, rtol=0, atol=1e-12)


def test_a_bad_mesher_is_refused_naming_the_parameter_and_the_choices():
    with pytest.raises(InputError) as refused:
        signorini.solve("hertz-cylinder", params={"mesher": "gmsh"})
    for word in ("mesher", "gmsh", "relaxed", "bisection", "triangle"):
        assert word in str(refused.value), refused.value
    with pytest.raises(ValueError, match=r"mesher='gmsh'.*relaxed, bisection, triangle"):
        graded_quarter_disc(1.0, 0.05, 40, 0.15, mesher="gmsh")


#: the size guard's graded cases (tests/test_size_guard.py): grading 0.05..2 and a coarse contact
GRADED = [{"grading": g} for g in (0.05, 0.1, 0.3, 0.6, 1.0, 2.0)] + [{"grading": 0.1, "n_contact": 10}]


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("values", GRADED, ids=str)
def test_the_size_estimate_bounds_triangles_meshes_from_above(scene, values):
    """Scaled by TRIANGLE_DOFS, the estimate is over Triangle's mesh; at most twice it (Triangle
    puts fewer nodes than the relaxed mesh at coarse gradings, which the factor does not follow)."""
    family = get_scene(scene)
    values = {**values, **TRIANGLE}
    params = family.parse(values)
    built = family.build(params, set(values)).mesh.p.size
    estimate, _ = estimate_dofs(scene, params)
    assert built <= estimate <= 2.0 * built, (estimate, built)
