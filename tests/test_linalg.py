"""Factorisation backends against SuperLU, and the active-set systems of PDAS."""

import numpy as np
import pytest

from signorini.errors import InputError
from signorini.numerics.active_set import ActiveSetSolver, selection_dofs
from signorini.numerics.factor import available_backends, factorize, resolve_backend
from signorini.scenes import build_problem
from synthetic import random_problem

MODULES = {"cholmod": "sksparse.cholmod", "pardiso": "pypardiso", "superlu": "scipy"}


@pytest.fixture(scope="module")
def hertz():
    return build_problem("hertz-cylinder", params={"n_contact": 16, "grading": 0.4})


@pytest.mark.parametrize("backend", sorted(MODULES))
def test_backend_matches_superlu(hertz, backend):
    pytest.importorskip(MODULES[backend], reason=f"the {backend} backend is not installed")
    rhs = np.column_stack([hertz.f, hertz.N.T @ np.ones(hertz.m)])
    reference = factorize(hertz.K, "superlu").solve(rhs)
    result = factorize(hertz.K, backend).solve(rhs)
    assert np.max(np.abs(result - reference)) <= 1e-10 * np.max(np.abs(reference))
    single = factorize(hertz.K, backend).solve(hertz.f)
    assert single.shape == (hertz.n,)
    np.testing.assert_allclose(single, reference[:, 0], rtol=0, atol=1e-10 * np.abs(reference).max())


def test_auto_is_the_first_installed_and_names_are_checked(monkeypatch):
    monkeypatch.delenv("SIGNORINI_FACTOR", raising=False)
    assert resolve_backend() == available_backends()[0]
    monkeypatch.setenv("SIGNORINI_FACTOR", "superlu")
    assert resolve_backend() == "superlu"
    with pytest.raises(InputError, match="choose auto"):
        resolve_backend("mumps")


def test_selection_structure_is_recognised(hertz):
    dofs = selection_dofs(hertz.N)  # a flat obstacle: each row bounds one y dof
    assert dofs is not None and dofs.size == hertz.m
    coupled = random_problem(8, 3, seed=1)  # rows couple two dofs
    assert selection_dofs(coupled.N) is None


@pytest.mark.parametrize("backend", sorted(MODULES))
def test_active_set_solver_paths_agree(hertz, backend):
    """Pinning dofs (with or without CHOLMOD's reused analysis) equals the saddle-point solve."""
    pytest.importorskip(MODULES[backend], reason=f"the {backend} backend is not installed")
    active = hertz.d <= np.quantile(hertz.d, 0.4)
    pinned = ActiveSetSolver(hertz.K, hertz.N, backend)
    u, lam = pinned.solve(active, hertz.f, hertz.d)
    # the same system through the saddle point: add a zero coupling so rows are not selections
    saddle = ActiveSetSolver(hertz.K, hertz.N, backend)
    saddle._dofs = None
    u_ref, lam_ref = saddle.solve(active, hertz.f, hertz.d)
    assert np.max(np.abs(u - u_ref)) <= 1e-9 * np.max(np.abs(u_ref))
    assert np.max(np.abs(lam - lam_ref)) <= 1e-9 * np.max(np.abs(lam_ref))
    assert np.allclose(hertz.N[active] @ u, hertz.d[active], atol=1e-12)
    assert np.all(lam[~active] == 0)
    residual = hertz.K @ u - hertz.f + hertz.N.T @ lam
    assert np.max(np.abs(residual)) <= 1e-10 * np.max(np.abs(hertz.f))
    # several right-hand sides at once give the columns one by one
    U, L = pinned.solve(active, np.column_stack([hertz.f, 2 * hertz.f]),
                        np.column_stack([hertz.d, 2 * hertz.d]))
    np.testing.assert_allclose(U[:, 1], 2 * u, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(L[:, 0], lam, rtol=1e-9, atol=1e-14)


def test_auto_counts_nonzeros_so_that_3d_gets_pardiso_early():
    from signorini.numerics.factor import available_backends, resolve_backend

    installed = available_backends()
    if not {"cholmod", "pardiso"} <= set(installed):
        pytest.skip("needs both CHOLMOD and PARDISO installed (pip install 'signorini[fast]')")
    # a 2D K of 40k dofs (~14 nonzeros per row) stays with CHOLMOD, a 3D one (~37) goes to PARDISO
    assert resolve_backend(None, 40_000, 560_000) == "cholmod"
    assert resolve_backend(None, 40_000, 1_480_000) == "pardiso"
    assert resolve_backend(None, 40_000) == "cholmod"  # size alone: the dof threshold
