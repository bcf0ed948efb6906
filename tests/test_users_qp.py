"""The QP a user gives is the QP the problem holds, and what the user's own method receives.

``ContactProblem.from_qp`` keeps the arrays it was given (as CSR and float arrays, the same
bits); a method of the user's own receives those arrays and numbers for ``tol`` and
``max_iter`` from the one table of defaults; no other default tolerance is written under
``signorini/solvers/``.
"""

from __future__ import annotations

import ast
import io
import json
import textwrap
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini.cli import main
from signorini.solvers import condensed, pdas
from signorini.solvers.options import DEFAULT_TOL, TABLE
from signorini.solvers.registry import get_method

SOLVERS = Path(signorini.__file__).parent / "solvers"

#: a user's QP in mm and N: two candidates under a stiff 3-dof body (not of order one)
K = np.array([[181_730.77, -40_000.0, 0.0], [-40_000.0, 120_000.0, -25_000.0],
              [0.0, -25_000.0, 90_000.0]])
F = np.array([0.0, -350.0, -900.0])
N = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
D = np.array([0.0025, 0.001])


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype == np.float64 and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("kind", ["dense", "sparse"])
def test_the_problem_holds_the_arrays_given(kind):
    given = (K, N) if kind == "dense" else (sp.csr_matrix(K), sp.coo_matrix(N))
    problem = signorini.ContactProblem.from_qp(given[0], F, given[1], D)
    assert problem.scales == signorini.Scales()
    for held in (problem.qp(), (problem.K, problem.f, problem.N, problem.d)):
        assert same_bits(held[0].toarray(), K) and same_bits(held[2].toarray(), N)
        assert same_bits(held[1], F) and same_bits(held[3], D)
        assert sp.isspmatrix_csr(held[0]) and sp.isspmatrix_csr(held[2])
    result = signorini.solve(problem, "pdas")
    assert result.converged  # and in the user's units: their own KKT conditions hold
    # the certificate solved with the method's factorisation of its scaled view, and factorised
    # the user's K itself, unpinned and in the user's units: a K of one's own may have no minimum
    assert result.certificate.back_solves > 0
    assert problem.cached_factor is not None and problem.cached_factor.matrix is problem.K
    assert np.max(np.abs(K @ result.u - F + N.T @ result.force)) <= 1e-9 * np.max(np.abs(F))
    assert np.all(N @ result.u <= D + 1e-12)


GRAB = textwrap.dedent("""
    import numpy as np

    from signorini.solvers.pdas import pdas


    def grab(problem, *, tol, max_iter, **options):
        np.savez({out!r}, K=problem.K.toarray(), f=problem.f, N=problem.N.toarray(), d=problem.d,
                 tol=np.array(repr(tol)), max_iter=np.array(repr(max_iter)),
                 kinds=np.array(repr((type(tol).__name__, type(max_iter).__name__))))
        answer = pdas(problem, tol=tol)
        return answer.u, answer.lam
""")


def received(path: Path) -> dict:
    with np.load(path) as z:
        return {key: z[key] for key in z.files}


def user_method(tmp_path: Path) -> tuple[str, Path]:
    out = tmp_path / "received.npz"
    (tmp_path / "mine.py").write_text(GRAB.format(out=str(out)))
    return f"{tmp_path / 'mine.py'}:grab", out


def assert_got_the_users_qp(got: dict, tol: float, max_iter: int) -> None:
    assert same_bits(got["K"], K) and same_bits(got["f"], F)
    assert same_bits(got["N"], N) and same_bits(got["d"], D)
    assert str(got["kinds"]) == repr(("float", "int"))
    assert float(str(got["tol"])) == tol and int(str(got["max_iter"])) == max_iter


def test_a_user_method_through_the_python_api_gets_the_users_qp_and_numbers(tmp_path):
    spec, out = user_method(tmp_path)
    problem = signorini.ContactProblem.from_qp(K, F, N, D)
    row = TABLE["user"]
    signorini.solve(problem, spec)
    assert_got_the_users_qp(received(out), DEFAULT_TOL, row.max_iter)
    assert row.tol == DEFAULT_TOL and isinstance(row.max_iter, int)
    signorini.solve(problem, spec, tol=1e-9, max_iter=7)
    assert_got_the_users_qp(received(out), 1e-9, 7)
    assert not get_method(spec).scaled and get_method("pdas").scaled


def test_a_user_method_through_the_cli_gets_the_users_qp_and_numbers(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec, out = user_method(tmp_path)
    np.savez(tmp_path / "mine_qp.npz", K=K, f=F, N=N, d=D)
    assert main(["solve", "mine_qp.npz", "--method", spec, "--json", "r.json"]) == 0
    assert_got_the_users_qp(received(out), DEFAULT_TOL, TABLE["user"].max_iter)
    assert main(["solve", "mine_qp.npz", "--method", spec, "--tol", "1e-9", "--json", "r.json"]) == 0
    assert_got_the_users_qp(received(out), 1e-9, TABLE["user"].max_iter)


# --- one tolerance table ------------------------------------------------------------------------


def default_tolerance_literals(path: Path) -> list[str]:
    """Where ``path`` writes a default tolerance or iteration limit as a number: a default
    of a ``tol``/``max_iter`` parameter, a ``…TOL``/``MAX_ITER`` name bound to a number (or a
    dict of numbers), a ``default_tol=`` keyword, ``tol=``/``max_iter=`` given a number in a
    call, or ``tol = <number> if tol is None else tol``."""
    tree = ast.parse(path.read_text())
    found = []

    def numeric(node) -> bool:
        if isinstance(node, ast.IfExp):
            return numeric(node.body) or numeric(node.orelse)
        if isinstance(node, ast.Dict):
            return any(numeric(value) for value in node.values)
        if isinstance(node, ast.UnaryOp):
            return numeric(node.operand)
        return isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) \
            and not isinstance(node.value, bool)

    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            args = node.args
            pairs = list(zip(args.args[len(args.args) - len(args.defaults):], args.defaults))
            pairs += [(a, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None]
            found += [f"{node.name}({a.arg}=…)" for a, d in pairs
                      if a.arg in ("tol", "max_iter") and numeric(d)]
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                name = target.id if isinstance(target, ast.Name) else ""
                if (name.endswith("_TOL") or name in ("TOL", "MAX_ITER", "tol", "max_iter")) \
                        and numeric(node.value):
                    found.append(f"{name} = … (line {node.lineno})")
        elif isinstance(node, ast.keyword) and (node.arg == "default_tol" or (
                node.arg in ("tol", "max_iter") and numeric(node.value))):
            found.append(f"{node.arg}=… in a call")
    return found


def test_no_default_tolerance_outside_the_table():
    where = {p.name: default_tolerance_literals(p) for p in sorted(SOLVERS.glob("*.py"))
             if p.name != "options.py"}
    assert {name: hits for name, hits in where.items() if hits} == {}
    assert default_tolerance_literals(SOLVERS / "options.py")  # the scan finds the table's


def test_the_scan_finds_a_default_tolerance(tmp_path):
    planted = tmp_path / "planted.py"
    planted.write_text("DEFAULT_TOL = 1e-9\nMAX_ITER = {'a': 20}\n\n"
                       "def solve(problem, *, tol=1e-9, max_iter=None):\n"
                       "    tol = 1e-9 if tol is None else tol\n"
                       "    return run(problem, max_iter=200 if max_iter is None else max_iter)\n")
    assert len(default_tolerance_literals(planted)) == 5


def test_every_registered_method_has_a_row():
    for method in signorini.methods():
        row = method.defaults
        assert row.reason and (row.tol is None or 0 < row.tol < 1)
        assert row.max_iter is None or (isinstance(row.max_iter, int) and row.max_iter > 0)
    assert get_method("pdas").default_tol < get_method("uzawa").default_tol  # exact is held tighter


@pytest.mark.parametrize("solve", [pdas.pdas, condensed.condensed], ids=["pdas", "condensed"])
def test_an_exact_method_uses_tol(solve):
    """Stopped as soon as its answer on the active set meets the bounds to tol: at a loose tol
    one step sooner, at a tight one only when the active set repeats."""
    from synthetic import random_problem

    problem = random_problem(n=30, m=12, seed=0, push=2.0)
    tight, loose = solve(problem, tol=1e-12), solve(problem, tol=0.3)
    assert loose.iterations < tight.iterations
    loose_cert = signorini.certificate(problem, loose)
    assert loose_cert.primal <= 0.3 and loose_cert.dual_sign <= 0.3
    assert signorini.certificate(problem, tight).worst()[1] <= 1e-9


# --- refusals -----------------------------------------------------------------------------------


def test_from_qp_refuses_k_none():
    with pytest.raises(signorini.InputError, match="K is None"):
        signorini.ContactProblem.from_qp(None, F, N, D)


def test_from_qp_refuses_nan_contact_points():
    points = np.array([[0.0, 0.0], [np.nan, 0.0]])
    with pytest.raises(signorini.InputError, match="contact_points row 1"):
        signorini.ContactProblem.from_qp(K[:2, :2], F[:2], N[:, :2], D, contact_points=points)


def test_a_problem_file_with_nan_contact_points_exits_2(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    np.savez("nan_points.npz", K=K, f=F, N=N, d=D, contact_points=[[0.0, 0.0], [np.nan, 1.0]])
    assert main(["solve", "nan_points.npz"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "contact_points row 1" in err


def rewritten(tmp_path: Path, change) -> Path:
    """A file ``ContactProblem.save`` wrote, with one array changed by ``change(arrays)``."""
    path = tmp_path / "saved.npz"
    signorini.ContactProblem.from_qp(K, F, N, D).save(path)
    with np.load(path) as z:
        arrays = {key: z[key] for key in z.files}
    change(arrays)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    path.write_bytes(buffer.getvalue())
    return path


def meta_of(text: str) -> np.ndarray:
    return np.frombuffer(text.encode(), dtype=np.uint8)


def unsymmetric(arrays) -> None:
    arrays["K_data"] = arrays["K_data"].copy()
    arrays["K_data"][1] *= 2.0  # K[0, 1] only


@pytest.mark.parametrize("change, words", [
    (lambda a: a.update(meta=meta_of("[1, 2]")), ["meta", "list", "save the problem again"]),
    (lambda a: a.update(meta=meta_of('"text"')), ["meta", "str"]),
    (unsymmetric, ["K must be symmetric"]),
], ids=["meta-list", "meta-string", "unsymmetric-K"])
def test_a_bad_saved_file_is_an_input_error(tmp_path, monkeypatch, capsys, change, words):
    path = rewritten(tmp_path, change)
    with pytest.raises(signorini.InputError):
        signorini.ContactProblem.load(path)
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert all(word in err for word in [str(path), *words]), err


def test_a_file_saved_scaled_by_an_older_version_loads_in_the_users_units(tmp_path):
    """An older version stored a QP given as arrays scaled, with the scales that undo it."""
    scales = {"length": 1.0, "displacement": 0.0025, "force": 454.3, "weight": 2.0}

    def scaled(arrays) -> None:
        arrays["K_data"] = arrays["K_data"] * (scales["displacement"] / scales["force"])
        arrays["f"] = arrays["f"] / scales["force"]
        arrays["d"] = arrays["d"] / scales["displacement"]
        meta = json.loads(bytes(arrays["meta"]).decode())
        arrays["meta"] = meta_of(json.dumps({**meta, "scales": scales}))

    problem = signorini.ContactProblem.load(rewritten(tmp_path, scaled))
    assert problem.scales == signorini.Scales()
    np.testing.assert_allclose(problem.K.toarray(), K, rtol=1e-15)
    np.testing.assert_allclose(problem.f, F, rtol=1e-15)
    np.testing.assert_allclose(problem.d, D, rtol=1e-15)
    fresh = signorini.solve(signorini.ContactProblem.from_qp(K, F, N, D), "pdas")
    np.testing.assert_allclose(signorini.solve(problem, "pdas").force, fresh.force, rtol=1e-12)


def test_the_docs_show_the_table():
    text = (Path(__file__).resolve().parents[1] / "docs" / "methods.md").read_text()
    for key, row in TABLE.items():
        tol = "its backend" if row.tol is None else f"{row.tol:g}"
        assert f"| `{key}` | {tol} |" in text, key


@pytest.mark.parametrize("method, option", [("uzawa", "rho"), ("pdas", "c")])
def test_options_in_the_users_units_run_on_the_users_arrays(method, option):
    """A step, a start or a callback is in the problem's units: the method then works on the
    arrays as given (no scaled view), so the callback reads the user's λ and the step is the
    user's: Uzawa's first step from λ = 0 is ρ (N K⁻¹ f − d)⁺ in the user's numbers."""
    problem = signorini.ContactProblem.from_qp(K, F, N, D)
    seen = []
    record = (lambda it, lam, displacement: seen.append(np.array(lam))) if method == "uzawa" \
        else (lambda it, u, lam: seen.append(np.array(lam)))
    rho = 0.5 / np.linalg.eigvalsh(N @ np.linalg.solve(K, N.T))[-1]
    value = rho if option == "rho" else 1e5
    result = signorini.solve(problem, method, tol=1e-10, callback=record, **{option: value})
    assert result.converged, result.message
    assert np.allclose(seen[-1], result.force, rtol=1e-6)  # the callback's λ is the user's λ
    if method == "uzawa":
        first = rho * np.maximum(N @ np.linalg.solve(K, F) - D, 0.0)
        assert not np.any(seen[0]) and np.allclose(seen[1], first, rtol=1e-9)  # from λ = 0
