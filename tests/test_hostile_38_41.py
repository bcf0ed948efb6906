"""The surfaces of one door and of the slider, attacked as a hostile user would.

A method of the user's, in whatever form it is given, receives the problem in the user's units;
the record's time accounts for the wall time of the command, a worker process included.
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


def steel_qp():
    """Two dofs in SI units (K ~ 1e11 N/m, gaps ~ 0.1 mm): far from order one."""
    K = np.array([[2e11, -1e11], [-1e11, 2e11]])
    return ContactProblem.from_qp(K, np.array([1e8, 1e8]), np.array([[1.0, 0.0]]),
                                  np.array([2.5e-4]))


def pdas_answer(problem):
    answer = signorini.solve(problem, "pdas").solution
    return answer.u, answer.lam


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


@pytest.fixture(scope="module")
def cylinder():
    return signorini.build_problem("hertz-cylinder", params={"n_contact": 12, "grading": 0.4})


@pytest.mark.parametrize("call, words", [
    (lambda p: signorini.at_load("hertz-cylinder"), ["at_load", "ContactProblem", "build_problem"]),
    (lambda p: signorini.at_load(None), ["at_load", "ContactProblem"]),
    (lambda p: signorini.with_load(p, P=None), ["P=None", "number"]),
    (lambda p: p.model.at_push(float("nan")), ["scale=nan", "finite"]),
    (lambda p: p.model.at_push(float("inf")), ["scale=inf", "finite"]),
    (lambda p: p.model.at_push("1"), ["scale='1'", "finite"]),
    (lambda p: p.model.at_push(1.0, load=float("nan")), ["load=nan", "finite"]),
    (lambda p: p.pushed(float("nan")), ["scale=nan"]),
    (lambda p: steel_qp().model.at_push(1.0), ["push", "as it is"]),
    (lambda p: p.with_target(float("nan")), ["P=nan", "finite number > 0"]),
    (lambda p: p.with_target(-1.0), ["P=-1.0", "finite number > 0"]),
])
def test_the_sliders_doors_refuse_bad_input_naming_it(cylinder, call, words):
    with pytest.raises(signorini.InputError) as refused:
        call(cylinder)
    assert all(word in str(refused.value) for word in words), str(refused.value)


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


BROKEN_CSR = (np.array([2.0, 2.0]), np.array([0, 1]), np.array([0, 5, 2]))  # indptr decreases


@pytest.mark.parametrize("matrix", [sp.csr_matrix, sp.csc_matrix, sp.csr_array])
def test_a_compressed_matrix_with_broken_indices_is_refused_not_read_out_of_bounds(matrix):
    K = matrix(BROKEN_CSR, shape=(2, 2))  # SciPy builds it unchecked; its C code would crash
    with pytest.raises(signorini.InputError, match="K is not a valid .* matrix .indptr"):
        ContactProblem.from_qp(K, [1.0, 1.0], [[1.0, 0.0]], [0.25])


@pytest.mark.parametrize("arrays, words", [
    ({"K_data": BROKEN_CSR[0], "K_indices": BROKEN_CSR[1], "K_indptr": BROKEN_CSR[2]},
     ["K is not a valid CSR matrix"]),
    ({"K_row": np.array([0, 1.5]), "K_col": np.array([0, 1]), "K_data": np.array([2.0, 2.0])},
     ["K_row", "whole numbers"]),
    ({"K": np.eye(2), "force_multiplicity": np.array("two")}, ["force_multiplicity", "one number"]),
], ids=["decreasing indptr", "a fractional index", "a word for a number"])
def test_a_hostile_problem_file_is_one_line_exit_2(tmp_path, capsys, arrays, words):
    shape = {} if "K" in arrays else {"K_shape": np.array([2, 2])}
    np.savez(tmp_path / "qp.npz", f=np.ones(2), N=np.array([[1.0, 0.0]]), d=np.array([0.25]),
             **arrays, **shape)
    assert main(["solve", str(tmp_path / "qp.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err


def test_whole_numbers_stored_as_floats_still_index_a_file(tmp_path):
    np.savez(tmp_path / "qp.npz", K_row=np.array([0.0, 0, 1, 1]), K_col=np.array([0.0, 1, 0, 1]),
             K_data=np.array([2.0, -1, -1, 2]), K_shape=np.array([2.0, 2]), f=np.ones(2),
             N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    assert main(["solve", str(tmp_path / "qp.npz")]) == 0


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


def test_a_first_mesh_beyond_max_dofs_is_refused_before_it_is_solved(capsys):
    assert main(["solve", "hertz-cylinder", "--target-error", "1%", "--max-dofs", "100"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "max dofs 100" in err and "--max-dofs" in err


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


@pytest.fixture(scope="module")
def block_answer():
    return signorini.solve("block", "pdas")


@pytest.mark.parametrize("method", ["pdas", "nested", "auto"])
@pytest.mark.parametrize("field, spoil", [("lam", lambda v: v * np.nan), ("u", lambda v: v + np.inf)])
def test_a_non_finite_warm_start_is_refused_naming_it(block_answer, method, field, spoil):
    solution = block_answer.solution
    given = {"lam": solution.lam, "u": solution.u}
    given[field] = spoil(given[field])
    with pytest.raises(signorini.InputError, match=f"warm_start: its {field} is not finite"):
        signorini.solve(block_answer.problem, method, warm_start=signorini.WarmStart(**given))


def test_a_warm_start_given_as_lists_is_taken_as_arrays(block_answer):
    start = signorini.WarmStart(lam=list(block_answer.solution.lam))
    assert signorini.solve(block_answer.problem, "nested", warm_start=start).status == "converged"


def compressed_bomb(path, key, count, others):
    """An .npz whose compressed member ``key`` unpacks to ``count`` zeros (a few hundred kB on
    disk, a consistent header and zip entry), beside the small arrays ``others``."""
    import io
    import zipfile

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (count,)})
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        with archive.open(f"{key}.npy", "w", force_zip64=True) as member:
            member.write(header.getvalue())
            for _ in range(count // 1_000_000):
                member.write(bytes(8_000_000))
        for name, value in others.items():
            buffer = io.BytesIO()
            np.save(buffer, value)
            archive.writestr(f"{name}.npy", buffer.getvalue())


@pytest.mark.parametrize("key, others, words", [
    ("f", {"K": np.eye(2), "N": np.array([[1.0, 0.0]]), "d": np.array([0.25])},
     ["f must have shape (2,), got (30000000,)"]),
    ("f", {"K_row": np.array([0, 1]), "K_col": np.array([0, 1]), "K_data": np.ones(2),
           "K_shape": np.array([2, 2]), "N_row": np.array([0]), "N_col": np.array([0]),
           "N_data": np.ones(1), "N_shape": np.array([1, 2]), "d": np.array([0.25])},
     ["K_shape declares 2 × 2", "f has length 30000000"]),
    ("K_data", {"K_row": np.array([0, 1]), "K_col": np.array([0, 1]), "K_shape": np.array([2, 2]),
                "f": np.ones(2), "N": np.array([[1.0, 0.0]]), "d": np.array([0.25])},
     ["K_data declares 30,000,000 entries", "2 unknowns"]),
], ids=["dense K", "sparse K", "sparse part"])
def test_a_compressed_member_is_held_to_the_others_before_it_is_read(tmp_path, capsys,
                                                                    monkeypatch, key, others, words):
    path = tmp_path / "bomb.npz"
    compressed_bomb(path, key, 30_000_000, others)
    read = []
    original = np.lib.npyio.NpzFile.__getitem__
    monkeypatch.setattr(np.lib.npyio.NpzFile, "__getitem__",
                        lambda self, name: read.append(name) or original(self, name))
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err
    assert key not in read


@pytest.mark.parametrize("argv, words", [
    (["--set", "nx=4", "--set", "nx=6"], ["--set nx is given twice (4 and 6)"]),
    (["--method", "pdas", "--opt", "c=1", "--opt", "c=2"], ["--opt c is given twice (1 and 2)"]),
], ids=["set", "opt"])
def test_a_setting_given_twice_with_two_values_is_refused(capsys, argv, words):
    assert main(["solve", "block", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err


@pytest.mark.parametrize("call, words", [
    (lambda: signorini.solve(steel_qp(), "pdas", keep_factor="yes"), ["keep_factor='yes'"]),
    (lambda: signorini.solve_adaptive("block", 0.5, max_dofs=True), ["max dofs True", "whole"]),
    (lambda: signorini.solve_adaptive("block", 0.5, max_dofs=1e5), ["max dofs 100000.0", "whole"]),
    (lambda: signorini.with_load("hertz-cylinder", P=1.0), ["with_load", "ContactProblem"]),
    (lambda: ContactProblem.load("no-such-problem.npz"), ["no-such-problem.npz", "does not exist"]),
], ids=["keep_factor", "max_dofs bool", "max_dofs float", "with_load of a name", "load missing"])
def test_more_api_doors_refuse_bad_input_naming_it(call, words):
    with pytest.raises(signorini.InputError) as refused:
        call()
    assert all(word in str(refused.value) for word in words), str(refused.value)


def test_a_file_that_is_not_an_archive_is_refused_by_load(tmp_path):
    (tmp_path / "p.npz").write_bytes(b"not a zip")
    with pytest.raises(signorini.InputError, match="not an archive"):
        ContactProblem.load(tmp_path / "p.npz")


@pytest.mark.parametrize("spoil, kind", [
    (lambda u: np.ma.masked_array(u, [True, False]), "MaskedArray"),
    (lambda u: np.asmatrix(u).T, "matrix"),
], ids=["masked", "matrix"])
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
