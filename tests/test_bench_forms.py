"""docs/bench-forms.md (and docs/methods.md's summary of it) is what tools/bench_forms.py renders
from the committed run, docs/bench-forms/runs.json: every QP backend per formulation at 66k and
261k dofs as a multiple of one factorisation, next to nested and pdas, in one run."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def tool():
    spec = importlib.util.spec_from_file_location("bench_forms_tool", ROOT / "tools" / "bench_forms.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_doc_and_the_readme_are_the_committed_run():
    bench = tool()
    from readme import current  # tools/readme.py, put on the path by the tool

    data = json.loads(bench.OUT.read_text())
    methods = ROOT / "docs" / "methods.md"
    assert current(methods.read_text(encoding="utf-8"), "bench-forms-summary") is not None
    for document in (bench.DOC, methods):
        text = document.read_text(encoding="utf-8")
        for name, body in bench.blocks(data).items():
            if current(text, name) is not None or document == bench.DOC:
                assert current(text, name) == body, \
                    f"{document.name} block {name!r}: run python tools/bench_forms.py --doc"


def test_the_run_covers_every_backend_and_form_at_both_sizes():
    bench = tool()
    data = json.loads(bench.OUT.read_text())
    assert [s["dofs"] for s in data["sizes"].values()] == [65_770, 261_300]
    for size in data["sizes"].values():
        ran = {(r["method"], r["form"]) for r in size["rows"]}
        assert {("nested", ""), ("pdas", "")} <= ran
        for method in ("qp-osqp", "qp-clarabel", "cvxpy"):
            assert {(method, form) for form in ("primal", "shifted", "dual")} <= ran
        exact = [r for r in size["rows"] if r["method"] in ("nested", "pdas")]
        assert all(r["status"] == "converged" and r["ratio_to_factor"] > 0 for r in exact)


def test_what_the_doc_says_the_run_shows():
    """The claims of docs/bench-forms.md's "What it shows" and of docs/methods.md's line under the
    summary, against the committed run."""
    bench = tool()
    data = json.loads(bench.OUT.read_text())

    def exact(row):
        return row["status"] == "converged" and row.get("exact_ok")

    for size in data["sizes"].values():
        rows = {(r["method"], r["form"]): r for r in size["rows"]}
        assert rows[("nested", "")]["ratio_to_factor"] <= 1.1
        qp_exact = [r for r in size["rows"] if r["form"] and exact(r)]
        assert min(r["ratio_to_factor"] for r in qp_exact) >= 8.0  # no QP route near one factorisation
        for method in ("qp-osqp", "qp-clarabel", "cvxpy"):  # named solvers, default forms: exact
            row = rows[(method, bench._default_form(method))]
            assert exact(row) and 8.0 <= row["ratio_to_factor"] <= 28.0, (method, row)
        osqp = {form: rows[("qp-osqp", form)] for form in ("primal", "shifted", "dual")}
        assert min(osqp.values(), key=lambda r: r["ratio_to_factor"]) is osqp["dual"]
        for method in ("qp-piqp", "qp-ecos", "qp-cvxopt"):  # never exact, in any form
            assert not any(exact(r) for r in size["rows"] if r["method"] == method)
        assert rows[("qp-highs", "primal")]["status"] == "failed"
