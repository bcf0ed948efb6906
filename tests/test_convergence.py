"""Convergence studies on tiny meshes: rates, agreement of the exact methods, files, the CLI."""

import json

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.scenes import build_problem
from signorini.solvers.registry import solve
from signorini.output.plots import plot_punch_edge, plot_punch_pressure
from signorini.studies.convergence import LABELS, dofs_for_error, fitted_rate, grading_comparison, run_study
from signorini.studies.convergence_report import plot_convergence, plot_grading, write_study

# a/R = 0.05: at 0.2 Hertz's half-space theory itself is ~1 % off the exact cylinder (docs/accuracy.md)
TINY = {"a_over_R": 0.05, "n_contact": 6, "grading": 0.8}


def test_fitted_rate_recovers_a_power_law():
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    assert fitted_rate(h, 3.0 * h ** 1.5) == pytest.approx(1.5)
    assert np.isnan(fitted_rate(h[:1], h[:1]))


def test_dofs_for_error_interpolates_and_extrapolates():
    dofs = np.array([100.0, 400.0, 1600.0])
    error = 10.0 / np.sqrt(dofs)  # 1.0, 0.5, 0.25
    assert dofs_for_error(dofs, error, 0.5) == (pytest.approx(400.0), "interpolated")
    value, how = dofs_for_error(dofs, error, 0.1)
    assert how == "extrapolated" and value == pytest.approx(10_000.0)
    assert dofs_for_error(dofs, error[::-1], 0.01)[1] == "not reached"


@pytest.fixture(scope="module")
def hertz_study():
    return run_study("hertz-cylinder", 2, TINY)


@pytest.mark.slow
def test_exact_methods_coincide_and_errors_fall(hertz_study):
    study = hertz_study
    assert set(study.methods) >= {"pdas"}
    assert study.max_disagreement() < 1e-9
    for method in study.methods:
        _, dofs, p0 = study.series(method, "p0_rel")
        assert len(p0) == 3 and np.all(np.diff(dofs) > 0)
        h, _, l2 = study.series(method, "pressure_l2_rel")
        # first order (docs/convergence.md pins 1.00 on the committed study): every halving of h at
        # least halves p0's error here, where the tiny meshes are still pre-asymptotic (faster)
        assert np.all(p0[:-1] / p0[1:] >= 2.0)
        assert study.rates[method]["p0_rel"] == pytest.approx(fitted_rate(h, p0))
        assert study.rates[method]["pressure_l2_rel"] == pytest.approx(fitted_rate(h, l2))
        assert study.rates[method]["pressure_l2_rel"] >= 0.95
    rates = [study.rates[m]["p0_rel"] for m in study.methods]
    assert max(rates) - min(rates) < 1e-6


def test_punch_study_shows_the_edge_singularity():
    study = run_study("punch", 2, {"n_contact": 4, "grading": 0.8, "size": 6}, methods=["pdas"])
    assert study.rates["pdas"]["edge_over_centre"] == pytest.approx(-0.5, abs=0.1)
    # the peak pressure's error falls at first order (1.15 on the committed 4-level study)
    assert study.rates["pdas"]["pressure_max_rel"] == pytest.approx(1.1, abs=0.2)


@pytest.mark.slow
def test_grading_comparison_at_equal_dofs():
    graded = run_study("hertz-cylinder", 2, TINY, methods=["pdas"])
    comparison = grading_comparison("hertz-cylinder", graded, 1, {"a_over_R": 0.05}, target=0.05)
    assert comparison.uniform_dofs > comparison.graded_dofs > 0
    assert comparison.saving > 1
    for ax in (plot_grading(comparison), plot_convergence(graded)):
        assert ax.get_xscale() == "log"


def test_write_study_writes_markdown_json_and_figures(hertz_study, tmp_path, saved_figures):
    paths = write_study(hertz_study, tmp_path, "signorini converge hertz-cylinder --levels 2")
    payload = json.loads(paths["json"].read_text())
    assert payload["study"]["scene"] == "hertz-cylinder"
    assert "rates" in payload["study"] and paths["figure"].stat().st_size > 10_000
    # the figure shows each method's errors against h, its fitted rate in the legend
    (ax,) = saved_figures[0].axes
    assert ax.get_xscale() == ax.get_yscale() == "log" and ax.get_xlabel().startswith("h ")
    lines = {line.get_label(): line for line in ax.get_lines()}
    legend = {t.get_text() for t in ax.get_legend().get_texts()}
    for method in hertz_study.methods:
        h, _, p0 = hertz_study.series(method, "p0_rel")
        rate = hertz_study.rates[method]["p0_rel"]
        label = f"{LABELS['p0_rel']} ({method}): rate {rate:.2f}"
        assert label in legend
        np.testing.assert_allclose(lines[label].get_xdata(), h)
        np.testing.assert_allclose(lines[label].get_ydata(), np.abs(p0))
    assert "Fitted rates" in paths["markdown"].read_text()


def test_punch_figures_take_and_return_axes():
    from matplotlib.figure import Figure

    problem = signorini.at_load(build_problem("punch", params={"n_contact": 8, "grading": 0.8, "size": 6}))
    solution = solve(problem, "pdas", tol=1e-10)
    ax = Figure().add_subplot()
    assert plot_punch_pressure(problem, solution, ax=ax) is ax
    assert plot_punch_edge(problem, solution).get_yscale() == "log"


def test_bad_studies_are_input_errors():
    with pytest.raises(InputError, match="no 'refine' parameter"):
        run_study("block", 1)
    with pytest.raises(InputError, match="--levels"):
        run_study("hertz-cylinder", 9)
    with pytest.raises(InputError, match="refine"):
        run_study("hertz-cylinder", 1, {"refine": 2})


@pytest.mark.slow
def test_cli_converge(tmp_path, capsys):
    out = tmp_path / "conv"
    code = main(["converge", "punch", "--levels", "1", "--set", "n_contact=4", "--set", "grading=0.8",
                 "--set", "size=6", "--out", str(out)])
    assert code == 0
    assert (out / "convergence-punch.md").exists() and (out / "convergence-punch.png").exists()
    assert "Fitted rates" in capsys.readouterr().out
    assert main(["converge", "block", "--levels", "1", "--out", str(out)]) == 2
    assert "refine" in capsys.readouterr().err


def test_the_rates_docs_convergence_states_are_the_committed_studies():
    """docs/convergence.md's readings of the committed studies (docs/convergence/*.json; the
    tables themselves are generated and held by test_readme_numbers): both exact methods agree,
    the estimates converge at P1's rates where the solution is smooth, the punch's edge at −½."""
    import json
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    text = " ".join((root / "docs" / "convergence.md").read_text(encoding="utf-8").split())

    def study(scene, folder=""):
        path = root / "docs" / "convergence" / folder / f"convergence-{scene}.json"
        return json.loads(path.read_text())

    differences = []
    for scene in ("hertz-cylinder", "hertz-sphere", "punch", "reverse-hertz"):
        found = study(scene)["study"]
        assert set(found["rates"]) >= {"pdas", "condensed"}
        for metric, value in found["rates"]["pdas"].items():
            assert found["rates"]["condensed"][metric] == pytest.approx(value, abs=1e-6)
        differences.append(f"{found['max_lam_rel_between_methods']:.0e}".replace("e-0", "e-"))
        if scene != "punch":  # smooth solutions: η first order in h, the pressure estimate near it
            assert 0.9 <= found["rates"]["pdas"]["estimate"] <= 1.1
            assert 0.75 <= found["rates"]["pdas"]["pressure_estimate"] <= 1.1
    assert f"{', '.join(differences[:3])} and {differences[3]} on the four scenes" in text
    punch = study("punch")["study"]["rates"]["pdas"]
    assert -0.6 < punch["edge_over_centre"] < -0.4
    assert f"(rate {punch['edge_over_centre']:.2f})".replace("-", "−") in text
    assert f"η converges at {punch['estimate']:.2f}" in text
    assert f"(rate {punch['pressure_estimate']:.2f})" in text
    grading = study("hertz-cylinder", "grading")
    graded = {r["level"]: r["errors"] for r in grading["study"]["rows"]}
    uniform = {r["level"]: r["errors"] for r in grading["uniform"]["rows"]}
    ratio = uniform[0]["pressure_l2_rel"] / graded[3]["pressure_l2_rel"]
    assert (f"{100 * graded[3]['pressure_l2_rel']:.2f} % against "
            f"{100 * uniform[0]['pressure_l2_rel']:.1f} %, about {ratio:.0f}×") in text


def test_the_readings_docs_convergence_gives_are_the_committed_studies():
    """The numbers docs/convergence.md reads off the committed studies, held to their JSONs."""
    import json
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    text = " ".join((root / "docs" / "convergence.md").read_text(encoding="utf-8").split())

    def levels(scene, key="study", folder=""):
        path = root / "docs" / "convergence" / folder / f"convergence-{scene}.json"
        rows = json.loads(path.read_text())[key]["rows"]
        return [r["errors"] for r in rows if r["method"] == "pdas"]

    def pct(value, digits=2):
        return f"{100 * value:.{digits}f}".rstrip("0").rstrip(".") + " %"

    cylinder = levels("hertz-cylinder")
    assert (f"fall to {pct(cylinder[2]['p0_rel'])} and {pct(cylinder[2]['a_rel'], 3)} at level 2"
            in text)
    assert "settle at 0.05–0.06 % and 0.02–0.03 %" in text
    assert all(0.05 <= round(100 * c["p0_rel"], 2) <= 0.06 and 0.02 <= round(100 * c["a_rel"], 2) <= 0.03
               for c in cylinder[3:])
    assert (f"({pct(cylinder[3]['pressure_l2_rel'])} → {pct(cylinder[4]['pressure_l2_rel'])})"
            in text)
    sphere = levels("hertz-sphere")
    assert f"dips to {pct(sphere[1]['p0_rel'])} at level 1" in text
    graded, uniform = levels("hertz-cylinder", folder="grading"), levels(
        "hertz-cylinder", "uniform", "grading")
    assert f"{pct(graded[3]['estimate'], 1)} against {pct(uniform[0]['estimate'], 1)}" in text
    assert (f"({pct(uniform[1]['p0_rel'])} → {pct(uniform[2]['p0_rel'], 3)} in one refinement) "
            f"while its a error is still {pct(uniform[2]['a_rel'])}") in text
    reverse = levels("reverse-hertz")
    assert f"settle at {pct(reverse[3]['p0_rel'])} and {pct(reverse[3]['a_rel'])}" in text
