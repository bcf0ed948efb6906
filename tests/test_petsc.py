"""The petsc methods: the bound form, serial solves, and solves under ``mpirun -n 1`` and ``-n 2``.

The bound-form tests need no PETSc. The solver tests need petsc4py and
mpi4py (``make`` installs them on Debian with tools/install_petsc.sh): they
are skipped, with that reason in the summary, where they are missing, and
the ``mpirun`` tests also when no ``mpirun`` is on the PATH. Never more
ranks than cores: an oversubscribed run is 20–40× slower.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.certification.kkt import active_set
from signorini.scenes import build_problem
from signorini.solvers.bounds import InfeasibleBounds, NoBoundForm, bound_form
from signorini.solvers.cluster import mpirun_command
from signorini.solvers.registry import solve
from synthetic import random_problem

#: PETSc, MUMPS and mpirun: 25–100 s together here; `pytest -m "not slow"` leaves them out
pytestmark = pytest.mark.slow

SCENES = ("hertz-cylinder", "hertz-sphere-3d")


@pytest.fixture(scope="module")
def references():
    """Each scene at its defaults and its exact answer from the serial active-set method."""
    out = {}
    for name in SCENES + ("reverse-hertz",):
        problem = signorini.at_load(build_problem(name))
        out[name] = (problem, solve(problem, "pdas"))
    return out


def full_vector(problem, u):
    out = np.zeros(problem.model.prescribed.size)
    out[problem.model.free_dofs] = u
    return out


@pytest.mark.parametrize("name", SCENES + ("reverse-hertz",))
def test_bound_form_is_the_same_problem(references, name):
    """Rotated back, the exact answer is feasible for the bounds and its reactions are its λ."""
    problem, exact = references[name]
    form = bound_form(problem)
    assert abs(form.K - form.K.T).max() <= 1e-12 * abs(form.K).max()
    identity = (form.T.T @ form.T - sp.identity(form.n)).tocsr()
    assert abs(identity).max() <= 1e-12  # the rotation is orthogonal
    v = form.T.T @ full_vector(problem, exact.u)
    assert np.allclose(form.displacement(v), exact.u, rtol=0, atol=1e-12 * abs(exact.u).max())
    assert np.all(v <= form.upper + 1e-12) and np.all(v >= form.lower - 1e-12)
    lam_error = abs(form.multipliers(v) - exact.lam).max() / exact.lam.max()
    assert lam_error <= 1e-10
    assert np.array_equal(form.bound_coef > 0, np.isfinite(form.upper[form.bound_index]))


def test_curved_obstacle_rows_are_rotated(references):
    """Reverse Hertz: a curved obstacle's rows mix both dofs of a node; one bound each after."""
    problem, _ = references["reverse-hertz"]
    assert np.any(np.diff(problem.N.tocsr().indptr) > 1)
    form = bound_form(problem)
    assert form.bound_index.size == problem.m and np.unique(form.bound_index).size == problem.m


def test_rows_sharing_a_dof_have_no_bound_form():
    problem = random_problem(12, 4, seed=3)
    N = problem.N.tolil()
    N[1, :] = N[0, :]  # two rows on the same dofs
    shared = problem.with_data(N=sp.csr_matrix(N))
    with pytest.raises(NoBoundForm, match="share a dof"):
        bound_form(shared)


def test_petsc_vi_refuses_rows_that_share_a_dof_in_one_line():
    pytest.importorskip("petsc4py", reason="petsc-vi needs petsc4py (make installs it)")
    problem = random_problem(12, 4, seed=3)
    N = problem.N.tolil()
    N[1, :] = N[0, :]  # two rows on the same dofs
    with pytest.raises(InputError, match="method 'petsc-vi' .* share dofs.*use pdas"):
        solve(problem.with_data(N=sp.csr_matrix(N)), "petsc-vi")


def test_a_row_without_free_dofs_bounds_nothing_or_is_infeasible():
    problem = random_problem(12, 4, seed=5)
    N = problem.N.tocsr()
    keep = N.data == -1.0  # one dof per row, so the rows are bounds
    rows = np.repeat(np.arange(4), np.diff(N.indptr))[keep]
    N = sp.csr_matrix((N.data[keep], (rows, N.indices[keep])), shape=N.shape).tolil()
    N[3, :] = 0.0  # a candidate whose dofs are all prescribed
    loose = problem.with_data(N=sp.csr_matrix(N), d=np.r_[problem.d[:3], 1.0])
    form = bound_form(loose)
    assert form.bound_index[3] == -1 and form.multipliers(np.zeros(form.n))[3] == 0.0
    with pytest.raises(InfeasibleBounds, match="infeasible"):
        bound_form(loose.with_data(d=np.r_[problem.d[:3], -1.0]))


def test_rigid_modes_are_a_near_null_space(references):
    problem, _ = references["hertz-sphere-3d"]
    form = bound_form(problem)
    modes = form.rigid_modes()
    assert modes.shape == (form.n, 6)
    assert np.allclose(modes.T @ modes, np.eye(6), atol=1e-10)
    # the stiffness of the unconstrained body, rotated like the unknowns, annihilates them
    from skfem import Basis, ElementVector, asm
    from skfem.models.elasticity import linear_elasticity

    mesh = problem.model.mesh
    body = asm(linear_elasticity(1.0, 1.0), Basis(mesh, ElementVector(mesh.elem())))
    rotated = form.T.T @ body @ form.T
    assert np.abs(rotated @ modes).max() <= 1e-10 * abs(rotated).max()


def require_petsc():
    pytest.importorskip("petsc4py", reason="the petsc methods need petsc4py: make installs it "
                                           "(tools/install_petsc.sh) on Debian as root")
    pytest.importorskip("mpi4py", reason="the petsc methods need mpi4py")


@pytest.mark.parametrize("ksp", ["mumps", "gamg"])
@pytest.mark.parametrize("method", ["petsc-vi", "petsc-tron", "petsc-gpcg"])
@pytest.mark.parametrize("name", SCENES)
def test_petsc_matches_the_exact_answer(references, name, method, ksp):
    require_petsc()
    problem, exact = references[name]
    answer = solve(problem, method, ksp=ksp)
    assert answer.status == "converged", answer.message
    agreement = compare(problem, answer, exact)
    assert agreement.lam_rel <= 1e-6, agreement.as_dict()
    assert agreement.misclassified == 0, agreement.as_dict()
    assert answer.extras["ranks"] == 1 and answer.extras["ksp"] == ksp


def test_auto_picks_multigrid_for_big_3d_problems_only(references, monkeypatch):
    require_petsc()
    from signorini.solvers import petsc_

    monkeypatch.setattr(petsc_, "GAMG_FROM_DOFS", 1000)
    for name, expected in (("hertz-sphere-3d", "gamg"), ("hertz-cylinder", "mumps")):
        problem, exact = references[name]
        answer = solve(problem, "petsc-vi")
        assert answer.extras["ksp"] == expected and answer.status == "converged"
        assert compare(problem, answer, exact).lam_rel <= 1e-6


def test_petsc_on_a_curved_obstacle(references):
    require_petsc()
    problem, exact = references["reverse-hertz"]
    answer = solve(problem, "petsc-vi")
    assert answer.status == "converged", answer.message
    assert compare(problem, answer, exact).lam_rel <= 1e-6


def test_petsc_options_reach_petsc_and_bad_options_are_named(references):
    require_petsc()
    problem, _ = references["hertz-cylinder"]
    capped = solve(problem, "petsc-vi", petsc_options="-snes_max_it 1")
    assert capped.status != "converged"
    with pytest.raises(InputError, match="ksp"):
        solve(problem, "petsc-vi", ksp="lu")
    with pytest.raises(InputError, match="petsc_options"):
        solve(problem, "petsc-tron", petsc_options=3)


def mpirun_solve(tmp_path: Path, ranks: int, scene: str, method: str, *extra: str):
    """``mpirun -n ranks signorini solve …`` in a subprocess; returns (process, JSON record)."""
    require_petsc()
    try:  # the package's own launcher: no mpirun or too many ranks for the cores → skip, saying so
        command, env = mpirun_command(ranks, [])
    except InputError as exc:
        pytest.skip(str(exc))
    out = tmp_path / f"{scene}-{method}-{ranks}.json"
    command += [sys.executable, "-m", "signorini.cli", "solve", scene, "--method", method,
                "--json", str(out), *extra]
    proc = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600)
    record = json.loads(out.read_text()) if out.exists() else None
    return proc, record


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("method", ["petsc-vi", "petsc-tron"])
@pytest.mark.parametrize("name", SCENES)
def test_mpirun_agrees_with_the_serial_exact_method(references, tmp_path, name, method, ranks):
    problem, exact = references[name]
    proc, record = mpirun_solve(tmp_path, ranks, name, method)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert record["status"] == "converged" and record["extras"]["ranks"] == ranks
    per_rank = record["extras"]["per_rank"]
    assert [r["rank"] for r in per_rank] == list(range(ranks))
    assert sum(r["local_rows"] for r in per_rank) == bound_form(problem).n
    force = np.array(record["contact"]["force"])  # λ in physical units
    expected = exact.lam * problem.scales.force
    assert abs(force - expected).max() <= 1e-6 * abs(expected).max()
    active = np.array(record["contact"]["active"], dtype=bool)
    assert np.array_equal(active, active_set(problem, exact))


def test_mpirun_refuses_serial_methods_in_one_line(tmp_path):
    proc, record = mpirun_solve(tmp_path, 2, "hertz-cylinder", "pdas")
    assert proc.returncode != 0 and record is None
    assert "only the petsc methods run distributed" in proc.stderr
    assert "Traceback" not in proc.stderr
