"""tools/snapshot.py's compare: round-off passes, a real difference is flagged, in both formats."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("snapshot_tool", ROOT / "tools" / "snapshot.py")
snapshot = importlib.util.module_from_spec(spec)
spec.loader.exec_module(snapshot)


def write_record(path, rows):
    """A synthetic record of ``rows`` (scene, method, status, active, u, force), as record writes."""
    meta, arrays = {"rows": []}, {}
    for scene, method, status, active, u, force in rows:
        row = {"scene": scene, "method": method, "status": status, "iterations": 3, "active": active}
        for name, values in (("u", u), ("force", force)):
            arrays[f"{name}|{scene}|{method}"] = values
            row[f"{name}_norm"] = float(np.max(np.abs(values)))
            row[f"{name}_hash"] = snapshot.rounded_hash(values)
        meta["rows"].append(row)
    snapshot.save(path, meta, arrays)
    return path


@pytest.fixture
def answer():
    rng = np.random.default_rng(0)
    return rng.standard_normal(50), np.abs(rng.standard_normal(8))


@pytest.mark.parametrize("suffix", [".npz", ".json"])
def test_round_off_agrees_and_a_difference_is_flagged(tmp_path, answer, suffix):
    u, force = answer
    a = write_record(tmp_path / f"a{suffix}", [("block", "pdas", "converged", [0, 1], u, force),
                                               ("block", "uzawa", "converged", [0, 1], u, force)])
    b = write_record(tmp_path / f"b{suffix}", [
        ("block", "pdas", "converged", [0, 1], u * (1 + 1e-14), force),  # round-off
        ("block", "uzawa", "converged", [0, 1], u, force * (1 + 1e-6))])  # beyond it
    by_pair = {d["method"]: d for d in snapshot.differences(a, b)[0]}
    assert not by_pair["pdas"]["differs"] and by_pair["pdas"]["u"] < snapshot.ROUND_OFF
    assert by_pair["uzawa"]["differs"] and by_pair["uzawa"]["force"] > snapshot.ROUND_OFF
    table = snapshot.compare_table(a, b)
    assert "1 differ beyond it" in table and "| block | uzawa |" in table
    assert "| block | pdas |" not in table


def test_status_active_set_mesh_and_missing_pairs_are_differences(tmp_path, answer):
    u, force = answer
    a = write_record(tmp_path / "a.npz", [("punch", "pdas", "converged", [0, 1], u, force),
                                          ("punch", "nested", "converged", [0, 1], u, force),
                                          ("punch", "cvxpy", "converged", [0], u, force),
                                          ("punch", "qp-osqp", "converged", [0], u, force)])
    b = write_record(tmp_path / "b.npz", [("punch", "pdas", "max_iter", [0, 1], u, force),
                                          ("punch", "nested", "converged", [0, 2], u, force),
                                          ("punch", "cvxpy", "converged", [0], u[:-1], force),
                                          ("block", "pdas", "converged", [0], u, force)])
    both, only_a, only_b = snapshot.differences(a, b)
    by_method = {d["method"]: d for d in both}
    assert by_method["pdas"]["differs"] and by_method["pdas"]["status"] == ("converged", "max_iter")
    assert by_method["nested"]["differs"] and by_method["nested"]["active"] == 2
    assert by_method["cvxpy"]["differs"] and by_method["cvxpy"]["u"] == "50 → 49 values"
    assert only_a == ["punch qp-osqp"] and only_b == ["block (every method)"]
    assert "converged → max_iter" in snapshot.compare_table(a, b)


def test_the_users_qp_touches_in_part():
    K, f, N, d = snapshot.users_qp()
    u = np.linalg.solve(K.toarray(), f)  # without the obstacle, the middle goes through it
    violated = N @ u > d
    assert violated.any() and not violated.all()


def test_a_solve_that_hangs_or_is_refused_is_a_row_not_the_end(monkeypatch):
    import time

    from signorini.errors import InputError

    monkeypatch.setattr(snapshot, "solve_one", lambda *args: time.sleep(30))  # the forked child sees it
    assert snapshot.run_forked("block", "pdas", {}, timeout=0.5)["status"] == "timeout"

    def refuse(*args):
        raise InputError("method 'x' takes no such problem")

    monkeypatch.setattr(snapshot, "solve_one", refuse)
    row = snapshot.run_forked("block", "pdas", {}, timeout=30)
    assert row["status"] == "refused" and "no such problem" in row["message"]


def test_a_recorded_solve_keeps_the_answer_in_the_problems_units():
    row = snapshot.run_forked(snapshot.USERS_QP, "pdas", {}, timeout=60)
    K, f, N, d = snapshot.users_qp()
    assert row["status"] == "converged" and row["active"]
    assert np.all(N @ row["u"] <= d + 1e-12 * np.max(np.abs(d)))
    residual = K @ row["u"] - f + N.T @ row["force"]  # stationarity in the user's units
    assert np.max(np.abs(residual)) < 1e-6 * np.max(np.abs(f))
