"""Hertz between two elastic spheres (hertz-two-spheres, axisymmetric): two-body Hertz, the rigid
limit and the r-weighted dual mortar basis."""

import numpy as np
import pytest

import signorini
from signorini.references.analytic import hertz_sphere_load
from signorini.fem.mortar import GAUSS_POINTS, GAUSS_WEIGHTS, _dual

#: coarse meshes, so that each solve takes about a second
COARSE = {"n_contact": 16, "grading": 0.4}


@pytest.mark.parametrize("radial", [False, True])
def test_the_dual_basis_is_biorthogonal_in_the_segment_s_weight(radial):
    r0, r1 = (0.0, 0.3) if radial else (1.0, 1.0)  # a segment starting on the axis
    phi = np.stack([1.0 - GAUSS_POINTS, GAUSS_POINTS])
    weight = GAUSS_WEIGHTS * ((1.0 - GAUSS_POINTS) * r0 + GAUSS_POINTS * r1)
    psi = _dual(r0, r1, radial) @ phi
    products = np.einsum("iq,jq,q->ij", psi, phi, weight)
    assert np.allclose(products, np.diag(np.einsum("iq,q->i", phi, weight)), atol=1e-15)
    if not radial:
        assert np.allclose(_dual(r0, r1, radial), [[2.0, -1.0], [-1.0, 2.0]], atol=1e-14)


@pytest.mark.parametrize("discretisation", ["mortar", "nts"])
def test_two_spheres_of_different_materials_and_radii_meet_two_body_hertz(discretisation):
    params = {**COARSE, "E2": 3.0, "nu2": 0.2, "R2": 2.0, "discretisation": discretisation}
    result = signorini.solve("hertz-two-spheres", "pdas", params=params)
    assert result.converged and result.problem.model.axisymmetric
    c = result.comparison  # against a and p0 of the pair's E* and R* at the load carried
    reference = result.problem.model.reference  # the pair's R* and E*
    assert reference.R == pytest.approx(2 / 3, rel=1e-15)
    assert reference.E_star == pytest.approx(1 / ((1 - 0.3 ** 2) / 1.0 + (1 - 0.2 ** 2) / 3.0),
                                             rel=1e-15)
    assert abs(c.a / c.a_ref - 1) < 5e-3 and abs(c.p0 / c.p0_ref - 1) < 5e-3
    assert result.applied_load == pytest.approx(result.problem.model.push.P, rel=1e-8)  # load control


def test_a_stiff_large_lower_sphere_approaches_the_rigid_flat():
    P = hertz_sphere_load(0.05, 1.0, 1.0 / (1 - 0.3 ** 2))
    one = signorini.solve("hertz-sphere", "pdas", params={"P": P}).comparison  # default meshes:
    two = signorini.solve("hertz-two-spheres", "pdas",  # coarse ones differ by their own errors
                          params={"E2": 1e6, "R2": 1e3, "P": P}).comparison
    # (Hertz itself moves by 0.03 % between the two: 1/R* = 1.001 here)
    assert abs(two.a / one.a - 1) < 1e-3 and abs(two.p0 / one.p0 - 1) < 1e-3
    assert two.a_ref / one.a_ref == pytest.approx((1 / 1.001) ** (1 / 3), rel=1e-5)


def test_the_default_mesh_meets_two_body_hertz_within_a_thousandth():
    result = signorini.solve("hertz-two-spheres")
    assert result.converged
    c = result.comparison
    assert abs(c.a / c.a_ref - 1) < 1e-3 and abs(c.p0 / c.p0_ref - 1) < 1e-3
