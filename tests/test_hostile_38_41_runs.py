"""The runs of one door and of the slider, attacked as a hostile user would.

A method of the user's gets the problem in the user's units and cannot pass a wrong answer (a
saddle point of an indefinite K, an answer beyond double precision, a changed problem), nor
take the command down when it is imported; the record's time accounts for the wall time of
the command, a worker process, adaptive refinement and the VTK export included.
"""

import json
import os
import textwrap
import time
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import ContactProblem
from signorini.cli import main
from signorini.solvers.registry import Method
from test_hostile_38_41 import pdas_answer, steel_qp


@pytest.mark.parametrize("form", ["callable", "Method"])
def test_a_users_method_in_any_form_receives_the_problem_in_the_users_units(form):
    problem, received = steel_qp(), {}

    def mine(given, *, tol, max_iter, **options):
        received.update(K=given.K.toarray(), f=given.f.copy(), d=given.d.copy(), tol=tol,
                        max_iter=max_iter)
        return pdas_answer(given)

    method = mine if form == "callable" else Method(name="mine", function=mine, summary="mine")
    result = signorini.solve(problem, method)
    assert result.status == "converged"
    assert np.array_equal(received["K"], problem.K.toarray())
    assert np.array_equal(received["f"], problem.f) and np.array_equal(received["d"], problem.d)
    assert isinstance(received["tol"], float) and isinstance(received["max_iter"], int)


SLEEPER = textwrap.dedent("""
    import time

    from signorini.solvers.pdas import pdas


    def sleeps(problem, **options):
        time.sleep(1.0)
        answer = pdas(problem)
        return answer.u, answer.lam
""")


@pytest.mark.parametrize("limit", [[], ["--time-limit", "60"]])
def test_the_time_of_a_solve_in_a_worker_adds_up_to_its_wall_time(tmp_path, monkeypatch, limit):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.py").write_text(SLEEPER)
    steel_qp().save(tmp_path / "qp.npz")
    main(["solve", "qp.npz", "--method", "pdas", "--time-limit", "60"])  # the modules it loads
    start = time.perf_counter()
    code = main(["solve", "qp.npz", "--method", "mine.py:sleeps", "--json", "r.json", *limit])
    wall = time.perf_counter() - start
    times = json.loads((tmp_path / "r.json").read_text())["time"]
    assert code == 0
    assert times["method_s"] >= 1.0  # the worker's run, its sleep included
    assert times["total_s"] >= 0.9 * wall


def test_the_time_of_adaptive_refinement_covers_every_step():
    signorini.solve("hertz-cylinder")  # the modules a solve loads, loaded: a library call's time is the solve's
    start = time.perf_counter()
    record = signorini.solve_adaptive("hertz-cylinder", "0.5%").to_dict()
    wall = time.perf_counter() - start
    steps = record["extras"]["adaptive"]
    assert len(steps) > 1  # refined at least once: earlier steps to account for
    assert record["time"]["total_s"] >= sum(step["seconds"] for step in steps)
    assert abs(record["time"]["total_s"] / wall - 1) < 0.05


def saddle_point(K):
    """A QP with ``K`` and a point meeting its KKT conditions: u given, contact force 1 on the
    first dof, f chosen to balance them."""
    K = sp.csr_matrix(K)
    n = K.shape[0]
    u = np.linspace(1.0, 2.0, n)
    N = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, n))
    lam = np.array([1.0])
    problem = ContactProblem.from_qp(K, K @ u + N.T @ lam, N, np.array([u[0]]))
    return problem, u, lam


@pytest.mark.parametrize("K", [
    np.array([[1.0, 2.0], [2.0, 1.0]]),  # a positive diagonal, an eigenvalue −1
    np.diag([1.0, -1.0]),
    sp.diags(np.r_[np.full(799, 2.0), -1e-3]),  # by LOBPCG
], ids=["positive diagonal", "negative diagonal", "800 dofs"])
def test_a_kkt_point_of_an_indefinite_k_is_never_converged(K):
    problem, u, lam = saddle_point(K)
    assert not signorini.certificate(problem, u=u, force=lam).passed(1e-8)
    result = signorini.solve(problem, lambda given, **options: (u, lam))
    assert result.status != "converged" and "positive semidefinite" in result.solution.message


def test_a_semidefinite_k_bounded_by_its_contact_is_still_certified():
    K = np.diag([1.0, 0.0])  # free along the second dof, held there by the contact
    problem = ContactProblem.from_qp(K, np.array([0.0, 1.0]), np.array([[0.0, 1.0]]),
                                     np.array([0.25]))
    result = signorini.solve(problem, lambda given, **options: (np.array([0.0, 0.25]),
                                                                 np.array([1.0])))
    assert result.status == "converged"


def test_the_vtk_export_is_timed_in_the_record_it_precedes(tmp_path, monkeypatch):
    from signorini.output import export

    def slow_export(problem, solution, path):
        time.sleep(0.5)
        (tmp_path / "r.vtu").write_text("stand-in")

    monkeypatch.setattr(export, "export_vtk", slow_export)
    code = main(["solve", "block", "--json", str(tmp_path / "r.json"), "--vtk",
                 str(tmp_path / "r.vtu")])
    times = json.loads((tmp_path / "r.json").read_text())["time"]
    assert code == 0 and times["output_s"] >= 0.5
    assert times["total_s"] == pytest.approx(sum(v for k, v in times.items()
                                                 if k not in ("total_s", "build_s", "solve_s")))


ESCAPER = textwrap.dedent("""
    import os
    import time

    from signorini.solvers.pdas import pdas


    def escapes(problem, **options):
        if os.fork() == 0:  # a child that leaves the worker's process group and session
            os.setsid()
            with open("escaped.pid", "w") as out:
                out.write(str(os.getpid()))
            time.sleep(300)
            os._exit(0)
        while not os.path.exists("escaped.pid"):
            time.sleep(0.01)
        answer = pdas(problem)
        return answer.u, answer.lam
""")


def gone(pid, within=10.0):
    """Whether process ``pid`` ends (or is a zombie) within ``within`` seconds."""
    end = time.monotonic() + within
    while time.monotonic() < end:
        try:
            with open(f"/proc/{pid}/stat", "rb") as stat:
                if stat.read().rsplit(b")", 1)[1].split()[0] == b"Z":
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="descendants are found in /proc (Linux)")
def test_a_process_a_method_moved_out_of_its_group_ends_with_the_worker(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.py").write_text(ESCAPER)
    steel_qp().save(tmp_path / "qp.npz")
    assert main(["solve", "qp.npz", "--method", "mine.py:escapes"]) == 0
    pid = int((tmp_path / "escaped.pid").read_text())
    if not gone(pid):
        os.kill(pid, 9)  # the test's own leftover
        pytest.fail("the method's setsid child outlived the solve")


@pytest.mark.parametrize("spoil, kind", [
    (lambda u: np.ma.masked_array(u, [True, False]), "MaskedArray"),
    (lambda u: np.asmatrix(u).T, "matrix"),
], ids=["masked", "matrix"])
@pytest.mark.filterwarnings("ignore:the matrix subclass:PendingDeprecationWarning")  # NumPy on np.asmatrix
def test_an_ndarray_subclass_that_is_not_a_vector_of_floats_breaks_the_contract(spoil, kind):
    problem = steel_qp()
    u, lam = pdas_answer(problem)
    result = signorini.solve(problem, lambda given, **options: (spoil(u), lam))
    assert result.status == "failed" and f"got a {kind}" in result.solution.message


@pytest.mark.parametrize("field, value", [
    ("iterations", "many"), ("iterations", float("nan")), ("iterations", -1), ("extras", [1]),
    ("message", 3), ("history", 3), ("solve_time", "x"), ("build_time", float("inf")),
])
def test_what_a_method_reports_beside_its_answer_is_held_to_the_contract(field, value):
    problem = steel_qp()
    u, lam = pdas_answer(problem)

    def mine(given, **options):
        answer = signorini.ContactSolution("mine", u.copy(), lam.copy(), "converged", "")
        setattr(answer, field, value)
        return answer

    result = signorini.solve(problem, mine)
    assert result.status == "failed" and f"its {field} must be" in result.solution.message


@pytest.mark.parametrize("u, lam", [
    ([-1.7e308, -1.7e308], [0.0]),  # K u overflows to inf − inf: NaN stationarity
    ([-1e300, -1.7e308], [1.125e8]),
    ([1e200, 1e200], [1e200]),
])
def test_an_answer_beyond_double_precision_is_never_converged(u, lam):
    problem = steel_qp()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nor does judging it warn
        result = signorini.solve(problem, lambda given, **options: (np.array(u), np.array(lam)))
    assert result.status != "converged"
    assert not signorini.certificate(problem, u=np.array(u), force=np.array(lam)).passed(0.5)


@pytest.mark.parametrize("module, code, words", [
    ("import os\nos._exit(0)\n", 1, ["failed", "worker process died"]),
    ("import time\ntime.sleep(60)\n", 1, ["failed", "no answer within 2 s"]),
], ids=["ends the process", "hangs"])
def test_what_a_method_file_does_when_imported_costs_its_run_not_the_command(
        tmp_path, monkeypatch, capsys, module, code, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.py").write_text(module + "def solve(problem, **options):\n    return None\n")
    steel_qp().save(tmp_path / "qp.npz")
    assert main(["solve", "qp.npz", "--method", "mine.py:solve", "--time-limit", "2",
                 "--json", "r.json"]) == code
    record = json.loads((tmp_path / "r.json").read_text())
    assert all(word in f"{record['status']} {record['message']}" for word in words), record["message"]


def test_a_method_file_that_prints_when_imported_leaves_stdout_to_the_json(tmp_path, monkeypatch,
                                                                           capfd):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.py").write_text(SLEEPER.replace("time.sleep(1.0)", "pass")
                                      + "\nprint('imported')\n")
    steel_qp().save(tmp_path / "qp.npz")
    assert main(["solve", "qp.npz", "--method", "mine.py:sleeps", "--json", "-"]) == 0
    assert json.loads(capfd.readouterr().out)["status"] == "converged"


@pytest.mark.parametrize("change, name", [
    (lambda p: setattr(p, "scales", signorini.Scales(displacement=1e3, force=1e3)), "scales"),
    (lambda p: setattr(p, "force_multiplicity", 100.0), "force_multiplicity"),
    (lambda p: p.weights.__setitem__(slice(None), 1e-9), "weights"),
    (lambda p: p.contact_points.__setitem__(slice(None), 7.0), "contact_points"),
], ids=["units", "multiplicity", "weights", "positions"])
def test_a_method_that_changes_how_its_answer_is_reported_fails(change, name):
    problem = ContactProblem.from_qp(steel_qp().K, steel_qp().f, steel_qp().N, steel_qp().d,
                                     weights=[0.5], contact_points=[[0.0, 0.0]])

    def mine(given, **options):
        answer = pdas_answer(given)
        change(given)
        return answer

    result = signorini.solve(problem, mine)
    assert result.status == "failed" and f"changed the problem it was given: {name}" in \
        result.solution.message


def test_condensed_out_of_steps_and_uzawa_far_beyond_its_bound_say_so_quietly():
    """condensed at one LCP step ends max_iter with its last iterate (not a failed run); Uzawa at
    ρ = 1e300 overflows λ and ends diverged without a floating-point warning (pytest turns one
    raised in the package into an error)."""
    short = signorini.solve("hertz-cylinder", "condensed", max_iter=1)
    assert short.status == "max_iter" and "still changing after 1" in short.message
    assert np.all(np.isfinite(short.solution.u)) and np.all(np.isfinite(short.solution.lam))
    far = signorini.solve("hertz-cylinder", "uzawa", rho=1e300)
    assert far.status == "diverged" and "beyond the bound" in far.message


def test_a_constraint_given_twice_is_named_by_the_active_set_methods_and_solved_by_the_others():
    """Two equal rows of N (both active): PDAS's saddle-point system is singular, and the message
    names the two rows and what to do; the dual methods and the condensed LCP solve it, quietly."""
    problem = ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                     N=np.array([[1.0, 0.0], [1.0, 0.0]]), d=np.array([0.25, 0.25]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for method in ("pdas", "nested"):
            said = signorini.solve(problem, method)
            assert said.status == "failed" and "rows 0 and 1 of N are the same constraint" in said.message
        for method in ("condensed", "uzawa"):
            solved = signorini.solve(problem, method)
            assert solved.converged and np.allclose(solved.solution.u, [0.25, 1.0])
            assert np.isclose(solved.solution.lam.sum(), 0.5)


def test_a_sliders_last_answer_as_warm_start_costs_the_default_route_no_factorisation():
    """The slider's natural call, the last answer as the warm start at the next load: load
    control matches the load and its exact answer, not the one from the other load, starts
    the method, so the method factorises nothing (it did five times from the old answer)."""
    base = signorini.build_problem("hertz-cylinder")
    before = signorini.solve(signorini.with_load(base, a_over_R=0.04))
    problem = signorini.with_load(base, a_over_R=0.05)
    warm, cold = signorini.solve(problem, warm_start=before), signorini.solve(problem)
    assert warm.converged and warm.solution.work["method"].get("factorisations", 0) == 0
    assert np.array_equal(warm.solution.u, cold.solution.u)
    named = signorini.solve(problem, "pdas", warm_start=before)  # a method named starts from it
    assert named.converged and named.iterations > cold.iterations


def test_a_deferred_method_file_is_imported_once_per_process(tmp_path):
    """A method given as ``file.py:function`` is imported at its first call, then kept."""
    from signorini.solvers import user

    log = tmp_path / "imports.txt"
    mine = tmp_path / "counted.py"
    mine.write_text(f"open({str(log)!r}, 'a').write('imported\\n')\n"
                    "def solve(problem, **options):\n    return problem\n")
    method = user.deferred(f"{mine}:solve")
    assert not log.exists()  # nothing imported yet
    method.function("a"), method.function("b")
    assert log.read_text().splitlines() == ["imported"]
