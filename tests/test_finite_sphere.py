"""The axisymmetric sphere's difference from Hertz is the finite sphere's, first order in a/R
(docs/accuracy.md §3, the committed run of tools/finite_sphere.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import signorini

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import finite_sphere  # noqa: E402  (tools/finite_sphere.py)


@pytest.fixture(scope="module")
def limits():
    return finite_sphere.limits(finite_sphere.load())


def test_the_rate_fit_recovers_a_power_of_a_over_r():
    rows = [{"a_over_R": x, "p0_err": -0.2 * x ** 1.5} for x in (0.05, 0.01, 0.002)]
    k, c = finite_sphere.rate(rows, "p0_err")
    assert k == pytest.approx(1.5) and c == pytest.approx(0.2)


def test_the_load_error_reads_the_measured_force_from_hertz_radius():
    row = {"a_over_R": 0.05, "R": 2.0, "a_ref": 0.1 * 1.01 ** (1 / 3)}
    assert finite_sphere.load_error(row) == pytest.approx(0.01)


def test_at_nu_0_the_difference_is_first_order_in_a_over_r(limits):
    at_zero = [r for r in limits if r["nu"] == 0.0]
    for key in ("a_err", "p0_err"):
        k, _ = finite_sphere.rate(at_zero, key)
        assert 0.8 < k < 1.2, (key, k)
    # and refinement does not remove it: the last refinement moves it by a tenth of itself or less
    largest = max(at_zero, key=lambda r: r["a_over_R"])
    assert abs(largest["p0_err_change"]) < 0.1 * abs(largest["p0_err"])


def test_at_nu_0_3_the_model_is_held_to_0_01_percent_only_at_a_light_load(limits):
    at_03 = {r["a_over_R"]: r for r in limits if r["nu"] == 0.3}
    assert abs(at_03[0.05]["p0_err"]) > 1e-3  # the finite sphere at the scene's default load
    assert max(abs(at_03[0.0025]["a_err"]), abs(at_03[0.0025]["p0_err"])) < 1e-4


def test_every_run_carries_its_target_load():
    rows = finite_sphere.load()
    assert all(abs(finite_sphere.load_error(r)) < 1e-9 and r["force_balance"] < 1e-9 for r in rows)


def test_a_quarter_of_a_over_r_is_a_quarter_of_the_difference_at_nu_0():
    """Live: at a fixed number of elements across a, a discretisation or reading error would not
    shrink with a/R; the finite sphere's difference does."""
    errors = {}
    for ratio in (0.05, 0.0125):
        hertz = signorini.solve("hertz-sphere", params={"nu": 0.0, "a_over_R": ratio}).hertz
        errors[ratio] = hertz.p0 / hertz.p0_ref - 1
    assert errors[0.05] < -0.005  # the finite sphere at ν = 0: p₀ well below Hertz's
    assert 3.0 < errors[0.05] / errors[0.0125] < 6.0


def test_the_light_load_mesh_is_within_0_05_percent_of_hertz_in_steel_units():
    params = {"a_over_R": 0.0025, "n_contact": 40, "grading": 0.12, "E": 2.1e11, "R": 0.01}
    for nu in (0.3, 0.45):
        result = signorini.solve("hertz-sphere", params={**params, "nu": nu})
        assert result.problem.n <= 10_000
        assert result.hertz.a_rel < 5e-4 and result.hertz.p0_rel < 5e-4, (nu, result.hertz)
