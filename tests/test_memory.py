"""Factorisations give their memory back when they go (issue 16: PARDISO leaked 260 MB per factorisation)."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import signorini
from signorini.numerics.factor import available_backends, factorize


def resident_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024
    pytest.skip("no /proc/self/status: resident memory cannot be read here")


@pytest.mark.slow
@pytest.mark.parametrize("backend", available_backends())
def test_repeated_factorisations_do_not_grow_resident_memory(backend):
    K = signorini.build_problem("hertz-cylinder", params={"refine": 1}).K  # ~19k dofs
    b = np.ones(K.shape[0])
    for _ in range(2):  # the first ones load the library and size its pools
        factorize(K, backend).solve(b)
    gc.collect()
    start = resident_mb()
    for _ in range(6):
        factor = factorize(K, backend)
        factor.solve(b)
        del factor
        gc.collect()
    grown = resident_mb() - start
    # before the fix PARDISO grew by 16 MB per factorisation here (≈ 100 MB over six)
    assert grown < 20, f"{backend}: resident memory grew by {grown:.0f} MB over 6 factorisations"


@pytest.mark.slow
def test_a_freed_factorisation_leaves_the_others_intact():
    K = signorini.build_problem("hertz-cylinder", params={"refine": 1}).K
    b = np.ones(K.shape[0])
    for backend in available_backends():
        first, second = factorize(K, backend), factorize(K, backend)
        x = first.solve(b)
        del first
        gc.collect()
        np.testing.assert_allclose(second.solve(b), x, rtol=1e-10, atol=1e-12 * np.abs(x).max())


def test_the_delassus_operator_bounds_the_right_hand_sides_in_flight():
    """W = N K⁻¹ Nᵀ in blocks of at most BLOCK_BYTES of dense right-hand sides (8 to 128 columns):
    at 66k dofs blocks of 128 made the condensed dual's peak 5× one factorisation's memory."""
    import scipy.sparse as sp

    from signorini.numerics.lcp import BLOCK_BYTES, delassus

    class Recording:
        widest = 0

        def solve(self, b):
            Recording.widest = max(Recording.widest, b.shape[1])
            return b

    for n, expected in ((1_000_000, 8), (65_770, int(BLOCK_BYTES // (8 * 65_770))), (2_000, 128)):
        Recording.widest = 0
        N = sp.csr_matrix((np.ones(300), (np.arange(300), np.arange(300))), shape=(300, n))
        W = delassus(N, Recording())
        assert Recording.widest == min(expected, 300) and np.allclose(W, np.eye(300))
