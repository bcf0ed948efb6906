"""A factorisation is refused from PARDISO's analysis, before its numeric phase, when it would not
fit (issue 13 §2, issue 14 item 3); the estimate is held to the committed measurement."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from signorini.cli import main
from signorini.numerics.factor import FACTOR_MEMORY_VARIABLE, FactorTooLarge, counting

ROOT = Path(__file__).resolve().parents[1]


def test_a_factorisation_over_the_limit_is_refused_before_its_numeric_phase(monkeypatch):
    pytest.importorskip("pypardiso", reason="the estimate is PARDISO's analysis (extra 'pardiso')")
    import signorini
    from signorini.numerics.factor import PardisoFactor

    problem = signorini.build_problem("hertz-cylinder", params={"refine": 2, "delta": 0.001})
    factor = PardisoFactor(problem.K)
    assert factor.memory > 8 * problem.K.nnz  # at least K's own values
    monkeypatch.setenv(FACTOR_MEMORY_VARIABLE, f"{0.5 * factor.memory / 1e9}")
    with counting() as work, pytest.raises(FactorTooLarge, match=r"PARDISO's analysis.*pdas-amg"):
        PardisoFactor(problem.K)
    assert work.factorisations == 0


def test_the_cli_refuses_in_one_line_and_writes_nothing(monkeypatch, capsys, tmp_path):
    pytest.importorskip("pypardiso", reason="the estimate is PARDISO's analysis (extra 'pardiso')")
    monkeypatch.setenv(FACTOR_MEMORY_VARIABLE, "0.001")
    out = tmp_path / "result.json"
    code = main(["solve", "hertz-cylinder", "--set", "refine=2", "--method", "pdas",
                 "--json", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "needs about" in err and FACTOR_MEMORY_VARIABLE in err


def test_a_limit_that_is_not_a_number_is_an_input_error(monkeypatch, capsys):
    pytest.importorskip("pypardiso", reason="the estimate is PARDISO's analysis (extra 'pardiso')")
    monkeypatch.setenv(FACTOR_MEMORY_VARIABLE, "lots")
    assert main(["solve", "hertz-cylinder", "--set", "refine=2", "--method", "pdas"]) == 2
    assert FACTOR_MEMORY_VARIABLE in capsys.readouterr().err


def test_the_committed_measurement_puts_the_estimate_near_the_memory_taken():
    """docs/speed/factor-memory.json (tools/factor_memory.py): the analysis's estimate against the
    resident memory the factorisation took, 2D and 3D, within the factor docs/speed.md states."""
    rows = json.loads((ROOT / "docs" / "speed" / "factor-memory.json").read_text())["rows"]
    assert {r["scene"] for r in rows} == {"hertz-cylinder", "hertz-sphere-3d"}
    assert max(r["dofs"] for r in rows) > 300_000
    for row in rows:
        assert 0.5 <= row["ratio"] <= 2.0, row
