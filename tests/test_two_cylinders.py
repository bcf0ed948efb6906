"""Hertz between two elastic cylinders (hertz-two-cylinders): the pair's reference and the rigid limit."""

import pytest

import signorini
from signorini.errors import InputError
from signorini.references.analytic import hertz_cylinder_load
from signorini.scenes.hertz_two_cylinders import FAMILY, pair_radius

#: coarse meshes, so that each solve takes about a second
COARSE = {"n_contact": 16, "grading": 0.4, "mesher": "relaxed"}  # one body meshed as the two


def test_the_reference_is_hertz_with_the_pair_s_modulus_and_radius():
    params = {"E1": 2.0, "nu1": 0.25, "E2": 3.0, "nu2": 0.2, "R1": 1.0, "R2": 2.0}
    model = FAMILY.build(FAMILY.parse({**COARSE, **params}))
    assert model.reference.R == pytest.approx(1.0 / (1.0 / 1.0 + 1.0 / 2.0), rel=1e-15)
    assert model.reference.E_star == pytest.approx(1.0 / ((1 - 0.25 ** 2) / 2.0 + (1 - 0.2 ** 2) / 3.0),
                                                   rel=1e-15)
    assert pair_radius(FAMILY.parse(params)) == model.reference.R


@pytest.mark.parametrize("discretisation", ["mortar", "nts"])
def test_two_cylinders_of_different_materials_and_radii_meet_two_body_hertz(discretisation):
    params = {**COARSE, "E2": 3.0, "nu2": 0.2, "R2": 2.0, "discretisation": discretisation}
    result = signorini.solve("hertz-two-cylinders", "pdas", params=params)
    assert result.converged
    c = result.comparison  # against a and p0 of the pair's E* and R* at the load carried
    assert abs(c.a / c.a_ref - 1) < 5e-3 and abs(c.p0 / c.p0_ref - 1) < 5e-3
    assert result.applied_load == pytest.approx(result.problem.model.push.P, rel=1e-8)  # load control


@pytest.mark.parametrize("loading", ["traction", "displacement"])
def test_a_stiff_large_lower_cylinder_approaches_the_rigid_flat(loading):
    P = hertz_cylinder_load(0.05, 1.0, 1.0 / (1 - 0.3 ** 2))
    one = signorini.solve("hertz-cylinder", "pdas",
                          params={**COARSE, "loading": loading, "P": P}).comparison
    two = signorini.solve("hertz-two-cylinders", "pdas",
                          params={**COARSE, "loading": loading, "E2": 1e6, "R2": 1e3, "P": P}).comparison
    # (Hertz itself moves by 0.05 % between the two: 1/R* = 1.001 here)
    assert abs(two.a / one.a - 1) < 5e-4 and abs(two.p0 / one.p0 - 1) < 5e-4
    assert two.a_ref / one.a_ref == pytest.approx((1 / 1.001) ** 0.5, rel=1e-5)  # E* by 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("params, limit", [
    ({}, 5e-4),  # two equal cylinders, the scene's defaults
    ({"E1": 2.1e11, "nu1": 0.3, "R1": 0.01, "E2": 7e10, "nu2": 0.33, "R2": 0.02}, 1e-3),  # SI
], ids=["defaults", "steel-on-aluminium-SI"])
def test_the_default_mesh_meets_two_body_hertz(params, limit):
    result = signorini.solve("hertz-two-cylinders", "pdas", params=params)
    assert result.converged and result.problem.n <= 20_000
    c = result.comparison
    assert abs(c.a / c.a_ref - 1) < limit and abs(c.p0 / c.p0_ref - 1) < limit


def test_the_rows_follow_the_normal_asked_for():
    vertical, master = (signorini.build_problem("hertz-two-cylinders",
                                                params={**COARSE, "normal": normal})
                        for normal in ("vertical", "master"))
    for problem, tilted in ((vertical, False), (master, True)):
        x_dofs = problem.model.free_dofs % 2 == 0  # dofs interleaved by node: x even
        assert (abs(problem.N[:, x_dofs]).max() > 1e-3) == tilted


#: a prescribed push: the mesh (graded to a/R*) does not move with the materials
PUSHED = {"n_contact": 12, "grading": 0.5, "E2": 3.0, "nu2": 0.2, "R2": 2.0, "delta": 0.004}


@pytest.mark.parametrize("wrt, h", [("E1", 1e-4), ("E2", 1e-4), ("nu1", 1e-5), ("nu2", 1e-5)])
def test_each_body_s_material_derivative_is_the_finite_difference(wrt, h):
    value = FAMILY.parse(PUSHED)[wrt]
    exact = signorini.derivative("hertz-two-cylinders", "total_force", wrt, params=PUSHED,
                                 method="pdas")
    up, down = (signorini.derivative("hertz-two-cylinders", "total_force", wrt, method="pdas",
                                     params={**PUSHED, wrt: value + step}).value
                for step in (h, -h))
    assert exact.derivative == pytest.approx((up - down) / (2 * h), rel=1e-6)
    assert abs(exact.derivative) > 1e-5  # each body's material moves the force


def test_the_load_derivative_of_the_pair_follows_hertz():
    result = signorini.solve("hertz-two-cylinders", "pdas", params=COARSE)
    force = signorini.derivative(result, "total_force", "P")
    assert force.derivative == pytest.approx(1.0, rel=1e-8)  # the contact carries the load
    peak = signorini.derivative(result, "p0", "P")
    # Hertz: p0 = 2P/(πa) with a ∝ √P, so dp0/dP = p0 / (2P) (the mesh's own error aside)
    assert peak.derivative == pytest.approx(peak.value / (2 * result.problem.model.push.P), rel=0.05)


@pytest.mark.parametrize("scene, wrt, words", [("hertz-two-cylinders", "E", "E1 or E2"),
                                               ("hertz-cylinder", "nu2", "respect to nu")])
def test_a_material_of_the_wrong_body_count_is_refused_in_one_line(scene, wrt, words):
    with pytest.raises(InputError, match=words):
        signorini.derivative(scene, "total_force", wrt, params=COARSE, method="pdas")


@pytest.mark.parametrize("method", ["pdas", "auto"])
def test_two_bodies_cost_at_most_a_third_more_than_one_body_of_as_many_dofs(method):
    """Counted in factorisations and back-solves, the certificate's included: the method's
    saddle-point system serves the certificate (no factorisation of K, no Delassus operator)."""
    from signorini.numerics.factor import counting

    cost = {}
    one_body = {"refine": 1, "mesher": "relaxed", "n_contact": 40, "grading": 0.15}  # as the two's
    for scene, params in (("hertz-cylinder", one_body), ("hertz-two-cylinders", {})):
        with counting() as work:
            result = signorini.solve(scene, method, params=params)
        assert result.converged
        cost[scene] = (result.problem.n, work.factorisations + work.back_solves)
    (n1, one), (n2, two) = cost.values()
    assert abs(n2 / n1 - 1) < 0.1  # about the same dofs
    assert two <= 1.3 * one, cost
