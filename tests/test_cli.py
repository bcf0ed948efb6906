"""The command line: results, the JSON contract and one-line errors with exit code 2."""

import json
import subprocess
import sys
import types

import numpy as np
import pytest

from signorini.cli import app, main

SMALL_HERTZ = ["--set", "n_contact=16", "--set", "grading=0.4"]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_scenes_and_methods_are_listed(capsys):
    code, out, _ = run(capsys, "scenes")
    assert code == 0 and "hertz-cylinder" in out and "block" in out and "a_over_R" in out
    code, out, _ = run(capsys, "methods")
    assert code == 0
    for name in ("pdas", "uzawa", "qp-osqp", "qp-clarabel", "cvxpy"):
        assert name in out


def test_solve_json_contract(capsys, tmp_path):
    path = tmp_path / "result.json"
    code, out, _ = run(capsys, "solve", "hertz-cylinder", *SMALL_HERTZ, "--method", "pdas",
                       "--json", str(path))
    assert code == 0 and "converged" in out and "Hertz" in out
    record = json.loads(path.read_text())
    for key in ("scene", "params", "method", "status", "message", "iterations", "dofs",
                "contact_candidates", "time", "kkt", "total_force", "contact", "hertz"):
        assert key in record
    assert record["status"] == "converged"
    for key in ("R", "E", "nu", "P", "a_over_R", "n_contact"):
        assert key in record["params"]
    assert set(record["time"]) >= {"assemble_s", "solve_s"}
    assert set(record["kkt"]) >= {"primal", "stationarity", "dual_sign", "complementarity"}
    contact = record["contact"]
    m = record["contact_candidates"]
    assert all(len(contact[k]) == m for k in ("x", "gap", "force", "pressure", "active"))
    assert contact["x"][0] == pytest.approx(0.0, abs=1e-12)
    # force is λ, pressure λ/w; the total force is that of the full (mirrored) cylinder
    assert record["total_force"] == pytest.approx(2 * sum(contact["force"]), rel=1e-12)
    assert record["total_force"] == pytest.approx(record["params"]["P"], rel=1e-8)
    assert set(record["hertz"]) >= {"a", "a_ref", "p0", "p0_ref", "pressure_l2_rel"}


def test_solve_json_to_stdout_is_pure_json(capsys):
    code, out, _ = run(capsys, "solve", "block", "--method", "uzawa", "--tol", "1e-10",
                       "--json", "-")
    assert code == 0
    record = json.loads(out)
    assert record["method"] == "uzawa" and record["status"] == "converged"
    assert "hertz" not in record


def test_method_options_reach_the_method(capsys):
    code, out, _ = run(capsys, "solve", "block", "--method", "uzawa", "--opt", "step_fraction=1.25",
                       "--opt", "max_iter=2000", "--json", "-")
    record = json.loads(out)
    assert code == 1  # not converged: the step is beyond the bound 2/λ_max
    assert record["status"] in ("diverged", "max_iter")
    assert record["extras"]["rho_over_bound"] == pytest.approx(1.25)


@pytest.mark.parametrize("argv, words", [
    (["solve", "nowhere"], ["unknown scene", "hertz-cylinder"]),
    (["solve", "block", "--method", "simplex"], ["unknown method", "pdas", "uzawa"]),
    (["solve", "hertz-cylinder", "--set", "E=0"], ["E", "> 0"]),
    (["solve", "hertz-cylinder", "--set", "E=-2e11"], ["E"]),
    (["solve", "hertz-cylinder", "--set", "nu=0.5"], ["nu", "(-1, 0.5)"]),
    (["solve", "hertz-cylinder", "--set", "nu=-1"], ["nu"]),
    (["solve", "hertz-cylinder", "--set", "E=nan"], ["E", "finite"]),
    (["solve", "hertz-cylinder", "--set", "R=abc"], ["R", "float"]),
    (["solve", "hertz-cylinder", "--set", "n_contact=2.5"], ["n_contact", "int"]),
    (["solve", "hertz-cylinder", "--set", "radius=1"], ["radius", "a_over_R"]),
    (["solve", "hertz-cylinder", "--set", "P=1", "--set", "a_over_R=0.1"], ["P", "a_over_R"]),
    (["solve", "hertz-cylinder", "--set", "E"], ["--set", "key=value"]),
    (["solve", "block", "--tol", "abc"], ["--tol"]),
    (["solve", "block", "--tol", "0"], ["--tol", "(0, 1)"]),
    (["solve", "block", "--method", "uzawa", "--opt", "speed=3"], ["speed", "step_fraction"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "speed=3"], ["speed"]),
    (["frobnicate"], ["invalid choice"]),
])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, words):
    code, out, err = run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("signorini: error:")
    for word in words:
        assert word in lines[0]
    assert "Traceback" not in err


def test_bad_input_leaves_an_existing_result_file_alone(capsys, tmp_path):
    path = tmp_path / "result.json"
    assert run(capsys, "solve", "block", "--json", str(path))[0] == 0
    before = path.read_bytes()
    assert run(capsys, "solve", "block", "--set", "nu=0.7", "--json", str(path))[0] == 2
    assert path.read_bytes() == before


def test_unwritable_outputs_are_input_errors(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    code, _, err = run(capsys, "solve", "block", "--json", str(blocker / "x.json"))
    assert code == 2 and "writable" in err
    code, _, err = run(capsys, "validate", "--out", str(blocker / "report"))
    assert code == 2 and "--out" in err


@pytest.mark.slow
def test_validate_writes_a_passing_report(capsys, tmp_path, saved_figures):
    out_dir = tmp_path / "report"
    code, out, err = run(capsys, "validate", "--method", "pdas", "--method", "uzawa",
                         "--out", str(out_dir))
    assert code == 0, out
    assert "checks passed" in out
    report = json.loads((out_dir / "report.json").read_text())
    assert report["passed"] is True
    assert {r["method"] for r in report["runs"]} == {"pdas", "uzawa"}
    assert (out_dir / "report.md").read_text().startswith("# signorini validation report")
    assert (out_dir / "hertz-cylinder-pressure.png").stat().st_size > 10_000
    # the pressure figure plots both methods asked for against Hertz's curve, in Hertz's units
    (ax,) = [ax for f in saved_figures for ax in f.axes
             if ax.get_title().startswith("hertz-cylinder: contact pressure")]
    assert ax.get_xlabel() == "x / a (Hertz)" and ax.get_ylabel() == "p / p₀ (Hertz)"
    lines = {line.get_label(): line for line in ax.get_lines()}
    (uzawa,) = [label for label in lines if label.startswith("uzawa")]
    exact = np.asarray(lines["pdas"].get_ydata())
    assert exact.max() == pytest.approx(1.0, abs=0.02)  # the peak is Hertz's p0
    np.testing.assert_allclose(lines[uzawa].get_ydata(), exact, atol=1e-5)
    assert "hertz-cylinder" in err  # progress goes to stderr


def test_installed_entry_point_exits_2_without_traceback():
    proc = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "hertz-cylinder",
                           "--set", "nu=0.5"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "nu" in proc.stderr


@pytest.mark.parametrize("json_to", ["-", "file"])
def test_the_process_ends_with_every_output_written(tmp_path, json_to):
    # `python -m signorini.cli` ends by os._exit, past the interpreter's teardown: what it printed
    # into a block-buffered file and the JSON it wrote must be whole, and the code its own
    record = tmp_path / "r.json"
    with open(tmp_path / "out.txt", "w") as out:
        proc = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "block", "--set",
                               "nx=4", "--set", "ny=4", "--json",
                               "-" if json_to == "-" else str(record)],
                              stdout=out, stderr=subprocess.PIPE, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    printed = (tmp_path / "out.txt").read_text()
    if json_to == "-":
        assert json.loads(printed)["status"] == "converged"
    else:
        written = json.loads(record.read_text())
        assert written["status"] == "converged"
        assert printed.rstrip().splitlines()[-1].lstrip().startswith("units:"), printed
        # the process's start-up is a stage of its record (in process, below, it is not)
        assert 0 < written["time"]["startup_s"] < written["time"]["total_s"]
        assert main(["solve", "block", "--set", "nx=4", "--set", "ny=4", "--json",
                     str(record)]) == 0
        assert json.loads(record.read_text())["time"]["startup_s"] == 0


def test_run_skips_the_teardown_only_as_the_one_process(monkeypatch):
    ended, handlers = [], []
    monkeypatch.setattr(app, "keep_freed_memory", lambda: None)  # this process's allocator stays
    monkeypatch.setattr(app.os, "_exit", ended.append)
    monkeypatch.setattr(app.atexit, "_run_exitfuncs", lambda: handlers.append(True))
    monkeypatch.delitem(sys.modules, "mpi4py", raising=False)  # no MPI loaded in this process
    app.run(["methods"])
    assert ended == [0] and handlers == [True]  # the exit handlers ran, then the process ended
    # with MPI loaded by a process alone, PETSc and then MPI are finalised here, and the
    # teardown skipped as before
    finalised = []
    petsc, mpi = types.ModuleType("petsc4py.PETSc"), types.ModuleType("mpi4py.MPI")
    petsc.Sys = types.SimpleNamespace(isFinalized=lambda: bool(finalised))
    petsc._finalize = lambda: finalised.append("PETSc")
    mpi.Is_initialized, mpi.Is_finalized = lambda: True, lambda: "MPI" in finalised
    mpi.Finalize = lambda: finalised.append("MPI")
    for name, module in (("mpi4py", types.ModuleType("mpi4py")), ("mpi4py.MPI", mpi),
                         ("petsc4py.PETSc", petsc)):
        monkeypatch.setitem(sys.modules, name, module)
    monkeypatch.setattr(app, "main", lambda argv, process: 0)
    app.run(["methods"])
    assert finalised == ["PETSc", "MPI"] and ended == [0, 0]
    # under mpirun (one rank or more) MPI is finalised by the usual exit, which mpirun waits for
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "2")
    with pytest.raises(SystemExit) as stopped:
        app.run(["methods"])
    assert stopped.value.code == 0 and ended == [0, 0] and finalised == ["PETSc", "MPI"]


def test_the_process_keeps_the_memory_it_frees():
    # what run() sets for the command's process, in a fresh one: NumPy's huge-page requests off,
    # and arrays larger than glibc's mmap threshold still allocate, free and come back
    code = ("import numpy as np\n"
            "from numpy._core.multiarray import _get_madvise_hugepage\n"
            "from signorini.cli.app import keep_freed_memory\n"
            "keep_freed_memory()\n"
            "for _ in range(3):\n"
            "    a = np.ones(2 ** 23)\n"
            "    assert a.sum() == 2 ** 23\n"
            "    del a\n"
            "print(_get_madvise_hugepage())")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "False"
