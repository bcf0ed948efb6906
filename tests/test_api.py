"""The public Python API: the README's example runs, results are in the user's units, bad input is refused."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.files import to_json

ROOT = Path(__file__).resolve().parents[1]
SI = {"E": 2.1e11, "R": 0.01, "a_over_R": 0.05, "n_contact": 24, "grading": 0.3}


def readme_python() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Python", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_example_runs_and_prints_what_it_says():
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(readme_python(), "README.md", "exec"), {})
    lines = out.getvalue().splitlines()
    assert lines[0] == "converged converged"
    assert re.fullmatch(r"\d+ N/m on \d+ nodes", lines[1])
    assert lines[-2:] == ["converged λ = 0.500000", "True"]


def test_forces_are_in_the_scene_units_and_equal_the_cli_json(tmp_path):
    result = signorini.solve("hertz-cylinder", params=SI, tol=1e-9)
    assert result.converged
    scales = result.problem.scales
    assert scales.force != 1.0  # the solver worked in its own units ...
    np.testing.assert_allclose(result.force, result.solution.lam * scales.force)
    # ... and the result is in N/m: the load Hertz's a/R = 0.05 asks for, P = π E* a² / (4R)
    e_star = SI["E"] / (1 - 0.3 ** 2)
    a = SI["a_over_R"] * SI["R"]
    assert result.total_force == pytest.approx(np.pi * e_star * a ** 2 / (4 * SI["R"]), rel=1e-9)
    assert result.hertz.p0_ref == pytest.approx(2 * result.total_force / (np.pi * a), rel=1e-9)
    assert result.hertz.p0 == pytest.approx(result.hertz.p0_ref, rel=0.05)  # a coarse mesh
    assert np.all(result.gap >= -1e-12 * SI["R"])
    assert result.displacement.shape == (result.problem.model.prescribed.size,)

    path = tmp_path / "r.json"
    argv = ["solve", "hertz-cylinder", "--tol", "1e-9", "--json", str(path)]
    for key, value in SI.items():
        argv += ["--set", f"{key}={value}"]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(argv) == 0
    cli = json.loads(path.read_text())
    api = json.loads(to_json(result.to_dict()))
    for record in (cli, api):
        record.pop("time")
    assert api["contact"]["force"] == pytest.approx(cli["contact"]["force"], rel=1e-12, abs=0)
    assert api["total_force"] == pytest.approx(cli["total_force"], rel=1e-12)
    assert set(api) == set(cli) and api["hertz"] == pytest.approx(cli["hertz"], rel=1e-9)


def test_the_result_does_not_depend_on_the_solver_units():
    scaled = signorini.solve("hertz-cylinder", params=SI, tol=1e-10)
    raw = signorini.solve(signorini.build_problem("hertz-cylinder", params=SI, nondimensionalise=False),
                          tol=1e-10)
    assert raw.problem.scales.force == 1.0
    np.testing.assert_allclose(raw.force, scaled.force, rtol=1e-6, atol=1e-9 * scaled.force.max())
    assert raw.total_force == pytest.approx(scaled.total_force, rel=1e-9)


def test_a_qp_of_your_own():
    # min ½uᵀKu − fᵀu, u₀ ≤ 0.25: u = (0.25, 1), λ = 1 − 2·0.25 = 0.5
    problem = signorini.ContactProblem.from_qp(np.diag([2.0, 1.0]), [1.0, 1.0], [[1.0, 0.0]], [0.25])
    for method in ("pdas", "uzawa", "qp-clarabel"):
        result = signorini.solve(problem, method, tol=1e-9)
        assert result.converged, (method, result.message)
        np.testing.assert_allclose(result.force, [0.5], rtol=1e-7)
        np.testing.assert_allclose(result.displacement, [0.25, 1.0], rtol=1e-7)
        assert np.isnan(result.pressure).all() and result.hertz is None
    record = json.loads(to_json(result.to_dict()))
    assert record["contact"]["pressure"] == [None] and "hertz" not in record
    assert "problem with qp-clarabel: converged" in result.summary()


def test_a_qp_with_weights_has_pressures_and_survives_save_and_load(tmp_path):
    problem = signorini.ContactProblem.from_qp(np.diag([2.0, 1.0]), [1.0, 1.0], [[1.0, 0.0]], [0.25],
                                               weights=[0.1])
    assert signorini.solve(problem).pressure == pytest.approx([5.0])
    problem.save(tmp_path / "p.npz")
    again = signorini.ContactProblem.load(tmp_path / "p.npz")
    assert again.weights * again.scales.weight == pytest.approx([0.1])  # kept scaled, with its scale
    bare = signorini.ContactProblem.from_qp(np.eye(1), [1.0], [[1.0]], [0.5])
    bare.save(tmp_path / "q.npz")
    assert signorini.ContactProblem.load(tmp_path / "q.npz").weights is None


@pytest.mark.parametrize("build, words", [
    (lambda: signorini.ContactProblem.from_qp(np.ones((2, 3)), [1, 1], [[1, 0]], [0]), "K must be square"),
    (lambda: signorini.ContactProblem.from_qp([[2, 1], [0, 2]], [1, 1], [[1, 0]], [0]), "symmetric"),
    (lambda: signorini.ContactProblem.from_qp(np.eye(2), [1, 1, 1], [[1, 0]], [0]), "f must have shape"),
    (lambda: signorini.ContactProblem.from_qp(np.eye(2), [1, 1], [[1, 0]], [0, 1]), "d must have shape"),
    (lambda: signorini.ContactProblem.from_qp(np.eye(2), [1, 1], [[1, 0]], [0], weights=[-1]), "weight"),
    (lambda: signorini.solve(42), "ContactProblem or a scene name"),
    (lambda: signorini.solve("no-such-scene"), "unknown scene"),
    (lambda: signorini.solve(signorini.build_problem("block"), params={"E": 2.0}), "params="),
    (lambda: signorini.solve("block", params={"nope": 1}), "no parameter 'nope'"),
    (lambda: signorini.solve("block", method="no-such-method"), "no-such-method"),
    (lambda: signorini.solve("block", tol=-1), "tol"),
])
def test_bad_input_is_one_clear_error(build, words):
    with pytest.raises(signorini.InputError, match=re.escape(words)):
        build()


def test_the_listings():
    names = {m.name for m in signorini.methods()}
    assert {"pdas", "uzawa", "nested", "qp-osqp", "qp-clarabel", "cvxpy"} <= names
    assert {"hertz-cylinder", "block", "punch"} <= set(signorini.scene_families())
    assert all(name in dir(signorini) for name in signorini.__all__)


def test_no_public_name_hides_a_subpackage():
    import pkgutil

    modules = {m.name for m in pkgutil.iter_modules(signorini.__path__)}
    assert not modules & set(signorini.__all__)
    import signorini.scenes.hertz_cylinder as cylinder  # was shadowed by a function `scenes`

    assert cylinder.FAMILY.name == "hertz-cylinder"


@pytest.mark.parametrize("tol", [1e-15, 1e-20])
def test_a_tolerance_double_precision_cannot_certify_is_refused(tol, capsys):
    with pytest.raises(signorini.InputError, match="below what double precision can certify"):
        signorini.solve("block", tol=tol)
    assert main(["solve", "block", "--tol", f"{tol:g}"]) == 2
    assert "--tol" in capsys.readouterr().err


def test_one_default_tolerance():
    """crosscheck asks for signorini.DEFAULT_TOL, and an answer nobody named a tolerance for
    (a QP backend at its own settings) is held to it: λ off by 1e-7 is not converged."""
    import dataclasses
    import inspect

    from signorini.solvers.base import judge
    from signorini.solvers.registry import get_method

    assert inspect.signature(signorini.crosscheck).parameters["tol"].default == signorini.DEFAULT_TOL
    assert get_method("uzawa").default_tol == signorini.DEFAULT_TOL
    assert get_method("qp-osqp").default_tol is None  # its backend's own settings
    problem = signorini.at_load(signorini.build_problem("block", params={"nx": 4, "ny": 4}))
    exact = signorini.solve(problem, "pdas", tol=1e-12).solution

    def off_by(relative):
        lam = exact.lam * (1 + relative)
        return judge(problem, dataclasses.replace(exact, lam=lam, status="converged"), None)

    assert off_by(1e-10).status == "converged"
    assert off_by(1e-7).status == "inaccurate"  # within the 1e-6 accepted before DEFAULT_TOL
