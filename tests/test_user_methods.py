"""User methods held to the contract (issue 13 §2).

A ``file.py:function`` that does not import is an input error naming the
file; a function that returns something other than a ContactSolution with
``u`` of n floats, ``lam`` of m floats (finite when it claims convergence)
and a known status ends ``failed`` with the reason; ``sys.exit`` inside it
cannot fake success; ``solve --time-limit`` runs it in a worker process so
that a method that hangs or kills its process costs its limit.
"""

import json
import textwrap

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError

METHODS = textwrap.dedent("""
    import os
    import sys
    import time

    import numpy as np

    from signorini.problem.contact import ContactSolution
    from signorini.solvers.pdas import pdas


    def answer(problem, u=None, lam=None, status="converged"):
        return ContactSolution("mine", np.zeros(problem.n) if u is None else u,
                               np.zeros(problem.m) if lam is None else lam, status, "")


    def returns_none(problem, **options):
        return None

    def returns_tuple(problem, **options):
        return pdas(problem).u, pdas(problem).lam

    def returns_zero_pair(problem, **options):
        return pdas(problem).u, np.zeros(problem.m)

    def returns_triple(problem, **options):
        return pdas(problem).u, pdas(problem).lam, "converged"

    def returns_short_pair(problem, **options):
        return np.zeros(3), np.zeros(problem.m)

    def short_u(problem, **options):
        return answer(problem, u=np.zeros(3))

    def long_lam(problem, **options):
        return answer(problem, lam=np.zeros(problem.m + 1))

    def matrix_u(problem, **options):
        return answer(problem, u=np.zeros((problem.n, 1)))

    def complex_u(problem, **options):
        return answer(problem, u=np.zeros(problem.n, dtype=complex))

    def text_lam(problem, **options):
        return answer(problem, lam=np.array(["0"] * problem.m))

    def list_u(problem, **options):
        return answer(problem, u=[0.0] * problem.n)

    def nan_lam(problem, **options):
        return answer(problem, lam=np.full(problem.m, np.nan))

    def inf_u(problem, **options):
        return answer(problem, u=np.full(problem.n, np.inf))

    def made_up_status(problem, **options):
        solution = pdas(problem)
        solution.status = "great"
        return solution

    def exits_zero(problem, **options):
        sys.exit(0)

    def exits_in_the_middle(problem, **options):
        pdas(problem)
        raise SystemExit("done")

    def hangs(problem, **options):
        time.sleep(600)

    def kills_its_process(problem, **options):
        os._exit(0)

    def integer_answer(problem, **options):
        solution = pdas(problem)
        return answer(problem, u=solution.u, lam=np.rint(solution.lam * 0).astype(int))

    def honest(problem, tol=None, max_iter=None, **options):
        return pdas(problem)
""")


@pytest.fixture
def user_file(tmp_path, monkeypatch):
    path = tmp_path / "mine.py"
    path.write_text(METHODS)
    monkeypatch.chdir(tmp_path)
    return path


BROKEN = [
    ("returns_none", "returned NoneType, not a ContactSolution"),
    ("returns_triple", "returned a tuple of 3 items, not (u, lam) or a ContactSolution"),
    ("returns_short_pair", "u must be an array of 544 floats, got a float64 array of shape (3,)"),
    ("short_u", "u must be an array of 544 floats, got a float64 array of shape (3,)"),
    ("long_lam", "lam must be an array of 17 floats, got a float64 array of shape (18,)"),
    ("matrix_u", "u must be an array of 544 floats, got a float64 array of shape (544, 1)"),
    ("complex_u", "u must be an array of 544 floats, got a complex128 array"),
    ("text_lam", "lam must be an array of 17 floats, got a <U1 array"),
    ("list_u", "u must be an array of 544 floats, got a list"),
    ("nan_lam", "status 'converged' with non-finite entries"),
    ("inf_u", "status 'converged' with non-finite entries"),
    ("made_up_status", "status 'great' is not one of converged"),
    ("exits_zero", "the method called sys.exit(0)"),
    ("exits_in_the_middle", "the method called sys.exit('done')"),
]


@pytest.mark.parametrize("function, reason", BROKEN, ids=[b[0] for b in BROKEN])
def test_a_broken_answer_is_failed_with_the_reason(user_file, function, reason):
    result = signorini.solve("block", f"{user_file}:{function}")
    assert result.status == "failed" and not result.converged
    assert reason in result.message, result.message


def test_an_honest_user_method_converges_and_integer_forces_are_floats(user_file):
    assert signorini.solve("block", "mine.py:honest").status == "converged"
    result = signorini.solve("block", "mine:integer_answer")  # a module on the current directory
    assert result.solution.lam.dtype == float
    assert result.status != "failed", result.message  # zero forces: wrong, but judged as an answer
    assert result.status != "converged"


def test_a_method_returning_u_and_lam_is_judged_as_a_claim_of_convergence(user_file):
    right = signorini.solve("block", "mine.py:returns_tuple")  # pdas's (u, λ): the exact answer
    assert right.status == "converged", right.message
    assert "returned (u, lam)" in right.message
    wrong = signorini.solve("block", "mine.py:returns_zero_pair")  # no contact force: not an answer
    assert wrong.claimed_status == "converged" and wrong.status != "converged"


@pytest.mark.parametrize("source, words", [
    ("def solve(problem, **options)\n    return None\n", ["bad.py", "line 1", "syntax error"]),
    ("import no_such_module_here\n", ["bad.py", "no_such_module_here"]),
    ("x = undefined_name\n", ["bad.py", "NameError", "undefined_name"]),
    ("import sys\nsys.exit(3)\n", ["bad.py", "sys.exit(3)"]),
    ("raise RuntimeError('not today')\n", ["bad.py", "RuntimeError: not today"]),
    ("solve = 3\n", ["bad.py", "no function 'solve'"]),
])
def test_a_file_that_does_not_import_is_an_input_error_naming_it(capsys, tmp_path, monkeypatch,
                                                                  source, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.py").write_text(source)
    with pytest.raises(InputError) as info:
        signorini.solve("block", "bad.py:solve")
    for word in words:
        assert word in str(info.value), (word, str(info.value))
    code = main(["solve", "block", "--method", "bad.py:solve", "--json", str(tmp_path / "r.json")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert not (tmp_path / "r.json").exists()


@pytest.mark.slow
@pytest.mark.parametrize("function, words", [
    ("hangs", ["failed", "no answer within 3 s: the run was stopped"]),
    ("kills_its_process", ["failed", "the worker process died"]),
    ("exits_zero", ["failed", "sys.exit(0)"]),
])
def test_solve_time_limit_runs_the_method_in_a_worker_that_cannot_take_the_run_down(
        capsys, user_file, function, words):
    code = main(["solve", "block", "--method", f"mine.py:{function}", "--time-limit", "3",
                 "--json", "r.json"])
    out = capsys.readouterr().out
    assert code == 1
    for word in words:
        assert word in out, (word, out)
    record = json.loads((user_file.parent / "r.json").read_text())
    assert record["status"] == "failed" and record["contact"] is None


def test_solve_time_limit_gives_the_same_answer_as_in_process(capsys, user_file):
    assert main(["solve", "block", "--method", "pdas", "--time-limit", "60", "--json", "a.json"]) == 0
    assert main(["solve", "block", "--method", "pdas", "--json", "b.json"]) == 0
    capsys.readouterr()
    read = json.loads
    a, b = (read((user_file.parent / name).read_text()) for name in ("a.json", "b.json"))
    assert a["status"] == b["status"] == "converged"
    np.testing.assert_allclose(a["contact"]["force"], b["contact"]["force"], rtol=1e-12)


def test_solve_time_limit_matches_a_target_load_once_in_the_worker(capsys, user_file):
    """The worker builds the scene and solves it as signorini.solve does, load control included,
    and says the push it matched: the command does not match the load again before it."""
    assert main(["solve", "hertz-cylinder", "--method", "pdas", "--time-limit", "60",
                 "--json", "a.json"]) == 0
    assert main(["solve", "hertz-cylinder", "--method", "pdas", "--json", "b.json"]) == 0
    capsys.readouterr()
    a, b = (json.loads((user_file.parent / name).read_text()) for name in ("a.json", "b.json"))
    assert "load matched by" in a["message"] and a["time"]["load_control_s"] == 0
    assert a["status"] == b["status"] == "converged"
    np.testing.assert_allclose(a["contact"]["force"], b["contact"]["force"], rtol=1e-12)


@pytest.mark.parametrize("argv", [
    ["solve", "block", "--time-limit", "0"],
    ["solve", "block", "--time-limit", "-3"],
    ["solve", "block", "--time-limit", "soon"],
    ["solve", "block", "--time-limit", "inf"],
    ["solve", "hertz-cylinder", "--time-limit", "5", "--target-error", "0.01"],
    ["validate", "--time-limit", "nan"],
    ["validate", "--time-limit", "-1"],
])
def test_a_bad_time_limit_is_one_line_exit_2(capsys, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--time-limit" in err, err
    assert list(tmp_path.iterdir()) == []


# -- your own method, debuggable ------------------------------------------------------------

SIBLING = "def compare(a, b):\n    return a < b\n"
DEBUGGED = textwrap.dedent("""
    import os
    import subprocess
    import sys

    from helper import compare
    from signorini.solvers.pdas import pdas


    def crashes(problem, **options):
        print("mine: starting on", problem.n, "dofs")
        print("mine: a word on stderr", file=sys.stderr)
        return compare(None, 1)


    def forks(problem, **options):
        child = subprocess.Popen(["sleep", "60"])
        with open(os.environ["CHILD_PID_FILE"], "w") as file:
            file.write(str(child.pid))
        return pdas(problem)
""")


@pytest.fixture
def method_folder(tmp_path):
    """A method file beside the module it imports, and a working folder elsewhere."""
    folder = tmp_path / "methods"
    folder.mkdir()
    (folder / "helper.py").write_text(SIBLING)
    (folder / "debugged.py").write_text(DEBUGGED)
    (tmp_path / "work").mkdir()
    return folder


def _command(tmp_path, *argv, **env):
    import os
    import subprocess
    import sys

    environment = {**os.environ, **env}
    environment.pop("PYTHONSAFEPATH", None)
    return subprocess.run([sys.executable, "-m", "signorini.cli", *argv], cwd=tmp_path / "work",
                          capture_output=True, text=True, env=environment, timeout=300)


def test_a_raising_method_is_shown_with_its_line_and_with_v_its_traceback(tmp_path, method_folder):
    method = f"{method_folder / 'debugged.py'}:crashes"
    quiet = _command(tmp_path, "solve", "block", "--method", method)
    helper = f"{method_folder / 'helper.py'}:2"
    assert quiet.returncode == 1, quiet.stderr
    assert "TypeError: '<' not supported" in quiet.stdout and helper in quiet.stdout, quiet.stdout
    assert "Traceback" not in quiet.stderr
    # what it wrote on stdout and stderr is shown when it failed
    assert "mine: starting on 544 dofs" in quiet.stderr and "a word on stderr" in quiet.stderr
    loud = _command(tmp_path, "-v", "solve", "block", "--method", method)
    assert "Traceback" in loud.stderr, loud.stderr
    assert f'File "{method_folder / "debugged.py"}", line 13, in crashes' in loud.stderr
    assert f'File "{method_folder / "helper.py"}", line 2, in compare' in loud.stderr


def test_a_method_that_raises_in_a_crosscheck_is_shown_with_its_line(tmp_path, method_folder):
    found = _command(tmp_path, "crosscheck", "block", "--method",
                     f"{method_folder / 'debugged.py'}:crashes", "--method", "pdas")
    assert found.returncode == 1
    assert "TypeError: '<' not supported" in found.stdout, found.stdout
    assert f"{method_folder / 'helper.py'}:2" in found.stdout


@pytest.mark.parametrize("limit", [[], ["--time-limit", "60"]], ids=["no limit", "time limit"])
def test_what_a_method_forks_ends_with_the_command(tmp_path, method_folder, limit):
    psutil = pytest.importorskip("psutil", reason="psutil tells a live process from a zombie")
    pid_file = tmp_path / "child.pid"
    done = _command(tmp_path, "solve", "block", "--method",
                    f"{method_folder / 'debugged.py'}:forks", *limit, CHILD_PID_FILE=str(pid_file))
    assert done.returncode == 0, done.stdout + done.stderr
    pid = int(pid_file.read_text())
    try:
        alive = psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        alive = False
    if alive:
        psutil.Process(pid).kill()
    assert not alive, f"the method's child {pid} outlived the command"


@pytest.mark.parametrize("spec, words", [(":", ["names no module or file", "module:function"]),
                                         ("mine.py:", ["names no function", "file.py:function"]),
                                         (":solve", ["names no module or file"])])
def test_a_method_spec_without_a_part_names_method_and_its_forms(spec, words):
    with pytest.raises(InputError) as info:
        signorini.solve("block", spec)
    for word in ["--method", *words]:
        assert word in str(info.value), str(info.value)


def test_the_python_api_takes_a_function_wherever_it_takes_a_name(user_file):
    from signorini.solvers.registry import get_method

    honest, returns_none = (get_method(f"mine.py:{name}").function
                            for name in ("honest", "returns_none"))
    result = signorini.solve("block", method=honest)
    assert result.status == "converged" and result.solution.method == "honest"
    check = signorini.crosscheck("block", [honest, "pdas", returns_none])
    assert [run.method for run in check.runs] == ["honest", "pdas", "returns_none"]
    assert check.runs[0].status == "converged" and check.runs[2].status == "failed"
    assert "returns_none failed" in "; ".join(check.failures)


def test_what_a_method_wrote_is_shown_when_it_fails_in_a_study(tmp_path, method_folder):
    found = _command(tmp_path, "validate", "--case", "block", "--method",
                     f"{method_folder / 'debugged.py'}:crashes", "--out", str(tmp_path / "out"))
    assert "mine: starting on" in found.stderr and "a word on stderr" in found.stderr, found.stderr


def test_solve_time_limit_takes_the_workers_certificate(capsys, user_file):
    """The worker certified its answer on the same arrays; the command reads that certificate
    (infinite residuals included) instead of factorising K again."""
    from signorini.numerics.factor import counting

    with counting() as work:
        assert main(["solve", "block", "--method", "pdas", "--time-limit", "60", "--json",
                     "a.json"]) == 0
    assert work.factorisations == 0  # every factorisation was the worker's
    assert main(["solve", "block", "--method", "pdas", "--json", "b.json"]) == 0
    capsys.readouterr()
    a, b = (json.loads((user_file.parent / name).read_text()) for name in ("a.json", "b.json"))
    assert a["kkt"].keys() == b["kkt"].keys() and "certificate" not in a["extras"]
    for name, value in b["kkt"].items():
        assert value == a["kkt"][name] or abs(value - a["kkt"][name]) < 1e-12
