"""The executable validation documents, imported and pinned to their claims."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

VALIDATION = Path(__file__).resolve().parents[1] / "validation"


def load(name):
    spec = importlib.util.spec_from_file_location(name, VALIDATION / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def hertz():
    return load("hertz_cylinder")


def test_hertz_cylinder_in_si_units_within_one_percent(hertz):
    assert hertz.problem.n <= 20_000
    assert hertz.exact.status == "converged"
    assert hertz.hertz.p0_rel < 0.01
    assert hertz.hertz.a_rel < 0.01
    assert hertz.hertz.pressure_l2_rel < 0.03
    assert hertz.hertz.force_balance < 1e-8


def test_the_papers_uzawa_reaches_the_exact_answer(hertz):
    assert hertz.paper.status == "converged"
    assert hertz.agreement.lam_rel < 1e-6
    assert hertz.agreement.misclassified == 0
    # the default step is 0.9 of the bound 2/λ_max(W)
    assert hertz.paper.extras["rho_over_bound"] == pytest.approx(0.9)


def test_hertz_figure_shows_both_methods_against_hertz(hertz, tmp_path, saved_figures):
    path = hertz.visualize(tmp_path / "p.png")
    assert path.stat().st_size > 10_000
    (figure,) = saved_figures
    (ax,) = figure.axes
    assert ax.get_xlabel() == "x / a (Hertz)" and ax.get_ylabel() == "p / p₀ (Hertz)"
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert {"Hertz", "pdas (exact)", "uzawa (the paper)"} <= set(lines)
    assert {t.get_text() for t in ax.get_legend().get_texts()} >= {"Hertz", "pdas (exact)"}
    exact, paper = lines["pdas (exact)"].get_ydata(), lines["uzawa (the paper)"].get_ydata()
    assert len(exact) == hertz.problem.m and np.allclose(exact, paper, atol=1e-4)
    assert np.max(exact) == pytest.approx(1.0, abs=0.01)  # the peak at Hertz's p₀, within 1 %
    assert np.max(lines["Hertz"].get_ydata()) == pytest.approx(1.0)


def test_block_patch_test_is_exact():
    block = load("block")
    assert block.uniform.pressure_max_rel < 1e-10
    assert np.all(block.profile.active)
    expected_total = 2 * block.PARAMS["W"] * block.pressure_expected
    assert block.profile.total_force == pytest.approx(expected_total, rel=1e-10)


def test_two_unlike_cylinders_meet_two_body_hertz_and_uzawa_reaches_the_exact_answer():
    pair = load("two_cylinders")
    assert pair.problem.n <= 20_000 and pair.exact.status == "converged"
    assert pair.hertz.p0_rel < 1e-3 and pair.hertz.a_rel < 1e-3  # two-body Hertz
    assert pair.hertz.force_balance < 1e-8
    assert pair.paper.status == "converged"
    assert pair.agreement.lam_rel < 1e-6 and pair.agreement.misclassified == 0
    assert "'pdas-amg'" in pair.refusal and "share dofs" in pair.refusal
