"""The problem a method is judged on is the problem it was given: ``K``, ``f``, ``N``, ``d`` held.

The certificate judges ``(u, λ)`` against ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d``. A method
that changes the data it was handed (``problem.f *= 0.5``, ``problem.d[:] += 1``) would
have its answer judged against its own question, and a half-load answer would pass. So
the data are fingerprinted before the method runs and checked after it:

- ``f`` and ``d``: a hash of their bytes (exact);
- ``K`` and ``N``: their product with a fixed random vector, equal up to summation
  order (sorting a matrix's indices in place reorders its sums but not the matrix),
  and their shapes.

A method answers the problem it was given: the package itself pushes a pending
problem to the push a load-matching method reports (``solution.extras["push"]``), so
no method can hand in another problem to be judged on.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from signorini.problem.contact import ContactProblem, ContactSolution

#: ``K x`` before and after a method agree to this (relative): summation order only
SAME_PRODUCT_RTOL = 1e-12
#: what each array is, for the message
MEANING = {"K": "the stiffness", "f": "the load", "N": "the contact normals", "d": "the gaps"}


def _digest(array: np.ndarray) -> str:
    return hashlib.blake2b(np.ascontiguousarray(array).view(np.uint8), digest_size=16).hexdigest()


def _probe(n: int) -> np.ndarray:
    return np.random.default_rng(1).uniform(0.5, 1.5, n)


@dataclass(frozen=True)
class Fingerprint:
    """What :func:`fingerprint` keeps of a problem's data (a few vectors, no copy of K)."""

    shapes: tuple
    f: str
    d: str
    K: np.ndarray
    N: np.ndarray


def fingerprint(problem: ContactProblem) -> Fingerprint:
    """Hashes of f and d, ``K x`` and ``N x`` for a fixed random x, and the shapes."""
    x = _probe(problem.K.shape[1])
    return Fingerprint((problem.K.shape, problem.N.shape, problem.f.shape, problem.d.shape),
                       _digest(problem.f), _digest(problem.d), problem.K @ x, problem.N @ x)


def changed(problem: ContactProblem, before: Fingerprint) -> list[str]:
    """The names of the arrays of ``problem`` that differ from ``before`` (none: unchanged)."""
    now = (problem.K.shape, problem.N.shape, np.shape(problem.f), np.shape(problem.d))
    if now != before.shapes:
        return [name for name, a, b in zip("KNfd", now, before.shapes) if a != b]
    x = _probe(problem.K.shape[1])
    out = []
    for name, product, kept in (("K", problem.K @ x, before.K), ("N", problem.N @ x, before.N)):
        if not np.allclose(product, kept, rtol=SAME_PRODUCT_RTOL, atol=0.0):
            out.append(name)
    out += [name for name, value, kept in (("f", problem.f, before.f), ("d", problem.d, before.d))
            if _digest(np.asarray(value, dtype=float)) != kept]
    return sorted(out, key="KfNd".index)


def held_to_problem(problem: ContactProblem, before: Fingerprint, solution: ContactSolution,
                    method: str) -> ContactSolution:
    """``solution``, or a ``failed`` one when the method changed ``problem``.

    ``before`` is :func:`fingerprint` of ``problem`` taken before the method ran.
    """
    touched = changed(problem, before)
    if touched:
        names = ", ".join(f"{name} ({MEANING[name]})" for name in touched)
        return ContactSolution.failure(
            method, problem, "failed",
            f"the method changed the problem it was given: {names}; a method must not change "
            "K, f, N or d (copy them first), so its answer cannot be judged")
    return solution
