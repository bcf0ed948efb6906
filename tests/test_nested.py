"""The nested method and its zone solver against PDAS: exact whatever the predicted zone."""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import load_control

from signorini.fem.assembly import assemble
from signorini.certification.comparison import compare
from signorini.certification.kkt import certificate
from signorini.references.catalogue import reference_of
from signorini.numerics.active_set import PinnedFactor
from signorini.numerics.factor import factorize
from signorini.numerics.zone import Zone, ZoneSolver, predict_zone
from signorini.scenes import build as scenes
from signorini.scenes import build_problem, coarse_values, get_scene
from signorini.solvers.registry import solve
from signorini.load_control import analytic_zone
from synthetic import random_problem

MODULES = {"cholmod": "sksparse.cholmod", "pardiso": "pypardiso", "superlu": "scipy"}


def selection_problem(seed: int, n: int = 40, m: int = 15):
    """A random problem whose rows of N each bound one dof (what pinning needs)."""
    problem = random_problem(n, m, seed=seed, condition=50.0)
    N = problem.N.tocsr()
    keep = N.data == -1.0
    rows = np.repeat(np.arange(m), np.diff(N.indptr))[keep]
    return problem.with_data(N=sp.csr_matrix((N.data[keep], (rows, N.indices[keep])), shape=N.shape))


def assert_same_answer(problem, first, second, lam_tol=1e-8):
    agreement = compare(problem, first, second)
    assert agreement.lam_rel <= lam_tol, agreement.as_dict()
    assert agreement.misclassified == 0, agreement.as_dict()


def zoned_build(name, **values):
    """build_problem with load targeting on a predicted zone even for a small model."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(load_control, "ZONE_FROM_DOFS", 0)
        return signorini.at_load(build_problem(name, params=values))


@pytest.fixture(scope="module")
def cylinder():
    """Load-targeted with a zone predicted from its coarse model (refine 1 → refine 0)."""
    return zoned_build("hertz-cylinder", refine=1, n_contact=24, grading=0.4)


def test_nested_equals_pdas_on_the_cylinder(cylinder):
    reference = solve(cylinder, "pdas")
    fresh = cylinder.with_data()  # no solver kept from load targeting: predicts from scratch
    nested = solve(fresh, "nested", analytic=False)
    assert nested.status == "converged" and "coarse model" in nested.message
    assert_same_answer(cylinder, reference, nested)
    assert certificate(cylinder, nested).worst()[1] < 1e-10


@pytest.mark.slow
@pytest.mark.parametrize("scene, nu", [("hertz-cylinder", 0.3), ("hertz-sphere", 0.0),
                                       ("hertz-sphere", 0.45)])
def test_the_analytic_zone_predicts_on_one_factorisation(scene, nu):
    """Hertz's a for the target load predicts the zone (the sphere at ν = 0 is 0.5 % off it)."""
    problem = signorini.at_load(build_problem(scene, params={"refine": 1, "nu": nu}))
    reference = solve(problem, "pdas")
    nested = solve(problem, "nested", zone=analytic_zone(problem))
    assert nested.status == "converged" and "the given zone" in nested.message
    assert_same_answer(problem, reference, nested)
    assert "1 factorisation(s)" in nested.message and nested.extras["band"] <= 8


def test_the_analytic_zone_predicts_the_3d_sphere_by_the_distance_from_the_axis():
    """In 3D the zone is a ring around Hertz's radius a (x² + y² against a²), as wide as the
    candidates' spacing there: nested is exact on one factorisation from it."""
    problem = signorini.at_load(build_problem("hertz-sphere-3d"))
    zone = analytic_zone(problem)
    a = reference_of(problem).extent(problem) / problem.scales.length
    rho = np.hypot(problem.contact_points[:, 0], problem.contact_points[:, 1])
    assert rho[zone.core].max() < a < rho[zone.band].max()
    assert rho[zone.rest].min() > a and zone.band.sum() < problem.m / 2
    reference = solve(problem, "pdas")
    nested = signorini.solve(problem, "nested")  # the API passes the scene's analytic zone
    assert nested.status == "converged" and "the given zone" in nested.message
    assert nested.solution.work["method"]["factorisations"] == 1
    assert_same_answer(problem, reference, nested.solution)


@pytest.mark.slow
def test_auto_reuses_the_load_targeting_factorisation_of_a_large_3d_model():
    """At 47k dofs the 3D sphere's load is targeted on the analytic zone (one factorisation of
    K); auto then picks nested, which solves on that factorisation by back-solves only."""
    problem = build_problem("hertz-sphere-3d", params={"refine": 1})
    answer = signorini.solve(problem)
    assert answer.method == "nested" and answer.status == "converged"
    assert answer.solution.work["load_control"]["factorisations"] == 1
    assert "factorisations" not in answer.solution.work["method"]
    assert answer.solution.extras["auto"].startswith("K (")
    assert signorini.solve(problem, c=2.0).method == "pdas"  # an option nested does not take


def test_a_wrong_analytic_zone_is_amended_not_trusted():
    """A zone predicted for a load 10 % lower (a 5 % too small): the answer stays exact."""
    problem = signorini.at_load(build_problem("hertz-cylinder", params={"refine": 1}))
    zone = analytic_zone(problem)
    shifted = analytic_zone(problem.with_data(push=dataclasses.replace(problem.model.push,
                                                                       P=problem.model.push.P * 0.9)))
    assert shifted is not None and shifted.core.sum() < zone.core.sum()
    reference = solve(problem, "pdas")
    nested = solve(problem, "nested", zone=shifted)
    assert nested.status == "converged"
    assert_same_answer(problem, reference, nested)


def test_nested_reuses_the_factorisation_load_control_hands_it():
    problem = build_problem("hertz-cylinder", params={"refine": 1, "n_contact": 24, "grading": 0.4})
    matched = load_control.match(problem, analytic_zone(problem))
    assert matched.how == "zone kernel" and matched.work["factorisations"] == 1
    system = matched.warm_start.zone_solver
    before = system.factorisations
    nested = solve(matched.problem, "nested", warm_start=matched.warm_start)
    assert system.factorisations == before and "0 factorisation" in nested.message
    assert_same_answer(matched.problem, solve(matched.problem, "pdas"), nested)


@pytest.mark.parametrize("scene,params", [
    ("hertz-sphere", {"refine": 1, "n_contact": 24, "grading": 0.4}),
    ("punch", {"refine": 1, "n_contact": 16}),
])
def test_nested_equals_pdas_on_other_scenes(scene, params):
    problem = signorini.at_load(build_problem(scene, params=params)).with_data()
    assert_same_answer(problem, solve(problem, "pdas"), solve(problem, "nested"))


@pytest.mark.parametrize("seed", range(6))
def test_any_zone_gives_the_exact_answer(seed):
    """However wrong the prediction (random core, band and rest), the answer is exact."""
    problem = selection_problem(seed)
    rng = np.random.default_rng(seed)
    label = rng.integers(0, 3, problem.m)
    zone = Zone(core=label == 0, band=label == 1)
    reference = solve(problem, "pdas")
    nested = solve(problem, "nested", zone=zone)
    assert nested.status == "converged"
    assert_same_answer(problem, reference, nested)


def test_a_core_that_pulls_is_released():
    problem = selection_problem(1)
    everything = Zone(core=np.ones(problem.m, bool), band=np.zeros(problem.m, bool))
    system = ZoneSolver(problem.K, problem.N)
    u, lam, final = system.solve(problem.f, problem.d, everything)
    reference = solve(problem, "pdas")
    np.testing.assert_allclose(lam, reference.lam, atol=1e-9 * np.abs(reference.lam).max())
    assert not np.any(final.core & (reference.lam == 0))  # separated nodes left the core
    assert system.factorisations >= 2


def test_the_push_on_a_zone_equals_the_full_active_set_calibration():
    family = get_scene("hertz-cylinder")
    values = {"refine": 1, "n_contact": 24, "grading": 0.4}
    params = family.parse(values)
    model = family.build(params, set(values))
    nominal = assemble(model)
    assert nominal.model.reference_name == "hertz-2d"  # the family's model hands on its reference record
    full = load_control.match(nominal)  # no zone: one factorisation per active-set step
    zoned = load_control.match(nominal, analytic_zone(nominal))
    assert full.how == "full active set" and zoned.how == "zone kernel"
    assert zoned.problem.model.push.scale == pytest.approx(full.problem.model.push.scale, rel=1e-10)
    assert_same_answer(full.problem, solve(full.problem, "pdas"),
                       solve(zoned.problem, "nested", warm_start=zoned.warm_start))


def test_predicted_zone_follows_the_coarse_edge():
    coarse = np.column_stack([np.linspace(0, 1, 11), np.zeros(11)])
    fine = np.column_stack([np.linspace(0, 1, 41), np.zeros(41)])
    zone = predict_zone(fine, coarse, coarse[:, 0] <= 0.5)
    assert zone.core[fine[:, 0] < 0.3].all() and zone.rest[fine[:, 0] > 0.75].all()
    assert zone.band[(fine[:, 0] > 0.45) & (fine[:, 0] < 0.55)].all()


def test_coarse_values_drop_two_refinements_and_keep_the_load():
    values = coarse_values("hertz-cylinder", get_scene("hertz-cylinder").parse(
        {"refine": 3, "P": 0.01}))
    assert values["refine"] == 1 and values["P"] == 0.01 and "delta" not in values
    once = coarse_values("hertz-cylinder", get_scene("hertz-cylinder").parse(
        {"refine": 1, "delta": 0.002, "n_contact": 40}))
    assert once["refine"] == 0 and once["n_contact"] == 20 and once["delta"] == 0.002
    assert coarse_values("hertz-cylinder", get_scene("hertz-cylinder").parse({})) is None
    assert coarse_values("block", get_scene("block").parse({})) is None


def test_without_a_coarse_model_nested_says_it_used_pdas():
    problem = signorini.at_load(build_problem("block", params={"nx": 6, "ny": 6}))
    nested = solve(problem, "nested")
    assert nested.status == "converged" and "pdas" in nested.message
    assert nested.extras["fallback"] == "pdas"


def test_zone_solver_refuses_rows_that_couple_dofs():
    problem = random_problem(10, 4, seed=2)
    with pytest.raises(ValueError, match="bound one dof"):
        ZoneSolver(problem.K, problem.N)


@pytest.mark.parametrize("backend", sorted(MODULES))
def test_pinned_factor_matches_superlu_on_the_free_block(backend):
    pytest.importorskip(MODULES[backend], reason=f"the {backend} backend is not installed")
    problem = signorini.at_load(build_problem("hertz-cylinder", params={"n_contact": 16, "grading": 0.4}))
    fixed = np.arange(0, problem.n, 7)
    rhs = np.column_stack([problem.f, problem.N.T @ np.ones(problem.m)])
    rhs[fixed] = np.linspace(-1, 1, len(fixed))[:, None]
    u = PinnedFactor(problem.K, fixed, backend).solve(rhs)
    free = np.setdiff1d(np.arange(problem.n), fixed)
    K = problem.K.tocsr()
    expected = np.array(rhs)
    expected[free] = factorize(K[free][:, free], "superlu").solve(
        rhs[free] - K[free][:, fixed] @ rhs[fixed])
    assert np.max(np.abs(u - expected)) <= 1e-10 * np.max(np.abs(expected))


def test_a_coarse_model_out_of_range_means_no_prediction(monkeypatch):
    """Coarser parameters a scene refuses give no coarse model (pdas), never an input error."""
    params = {"refine": 1, "n_contact": 24, "grading": 0.4}
    problem = signorini.at_load(build_problem("hertz-cylinder", params=params)).with_data()
    monkeypatch.setattr(scenes, "coarse_values", lambda name, params: {"n_contact": 1})
    nested = solve(problem, "nested", analytic=False)
    assert nested.status == "converged" and nested.extras["fallback"] == "pdas"


def test_the_committed_bench_holds_nested_near_one_factorisation():
    """docs/bench-nested (one run, docs/performance.md's line generated from it): nested within 2× one
    factorisation + solve at 66k dofs and 1.3× at 261k and 1M, every run converged and exact."""
    import csv
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "docs" / "bench-nested" / "bench.csv"
    rows = {int(r["dofs"]): r for r in csv.DictReader(path.open()) if r["method"] == "nested"}
    assert sorted(rows) == [65_770, 261_300, 1_041_640]
    for dofs, limit in ((65_770, 2.0), (261_300, 1.3), (1_041_640, 1.3)):
        row = rows[dofs]
        assert row["status"] == "converged" and float(row["kkt_worst"]) <= 1e-9
        assert int(row["misclassified"]) == 0
        assert float(row["ratio_to_factor"]) <= limit, (dofs, row["ratio_to_factor"])


@pytest.mark.parametrize("scene, params", [
    ("hertz-cylinder", {"n_contact": 16, "grading": 0.4}),
    ("hertz-sphere-3d", {}),  # a target load: load targeting and the solve both on the zone
])
def test_band_columns_beyond_the_memory_budget_keep_only_what_the_lcp_reads(scene, params,
                                                                              monkeypatch):
    """docs: at 1M 3D dofs the band's whole columns took 17 GB and nested was killed; beyond
    COLUMN_BYTES only N z_j and the core's reactions are kept, and u costs one back-solve more:
    the same answer, no whole column held."""
    from signorini.numerics import zone as zone_module
    from signorini.numerics.zone import ZoneSolver

    whole = signorini.solve(scene, method="nested", tol=1e-10, params=params)
    counts = {}
    original = ZoneSolver._displacement

    def counted(self, *args):
        counts["kept"] = [z is not None for _, _, z in self._columns.values()]
        return original(self, *args)

    monkeypatch.setattr(ZoneSolver, "_displacement", counted)
    monkeypatch.setattr(zone_module, "COLUMN_BYTES", 0)
    slim = signorini.solve(scene, method="nested", tol=1e-10, params=params)
    assert whole.converged and slim.converged
    assert counts["kept"] and not any(counts["kept"])  # no column kept whole
    np.testing.assert_allclose(slim.solution.lam, whole.solution.lam, rtol=1e-9,
                               atol=1e-12 * np.abs(whole.solution.lam).max())
    np.testing.assert_allclose(slim.solution.u, whole.solution.u, rtol=1e-9,
                               atol=1e-12 * np.abs(whole.solution.u).max())


def test_named_nested_takes_load_controls_factorisation():
    """Named, nested costs what auto's route does: load control factorises K once around the
    predicted zone and nested solves on that factorisation by back-solves only."""
    problem = build_problem("hertz-cylinder", params={"refine": 1, "n_contact": 60})
    assert problem.model.pending and problem.model.prescribed.size >= load_control.ZONE_FROM_DOFS
    named = signorini.solve(problem, method="nested")
    assert named.method == "nested" and named.status == "converged"
    assert named.solution.work["load_control"]["factorisations"] == 1
    assert "factorisations" not in named.solution.work["method"]
    assert_same_answer(named.problem, solve(named.problem, "pdas"), named.solution)


def test_nested_predicts_the_zone_from_a_warm_answer():
    """A warm start holding an answer alone (no factorisation): the zone is that answer's
    contact, and nested factorises once and agrees with pdas."""
    problem = signorini.at_load(build_problem("hertz-cylinder", params={"refine": 1}))
    earlier = solve(problem, "pdas")
    nested = solve(problem, "nested", warm_start=signorini.WarmStart.of(earlier))
    assert nested.status == "converged" and "the warm start's contact" in nested.message
    assert "1 factorisation(s)" in nested.message
    assert_same_answer(problem, earlier, nested)
