"""The problem a method is judged on is the problem it was given: ``K``, ``f``, ``N``, ``d`` held.

The certificate judges ``(u, λ)`` against ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d``. A method
that changes the data it was handed (``problem.f *= 0.5``, ``problem.d[:] += 1``) or
returns an answer to another problem (``solution.problem``) would have its answer
judged against its own question, and a half-load answer would pass. So the data are
fingerprinted before the method runs and checked after it:

- ``f`` and ``d``: a hash of their bytes (exact);
- ``K`` and ``N``: their product with a fixed random vector, equal up to summation
  order (sorting a matrix's indices in place reorders its sums but not the matrix),
  and their shapes.

A ``solution.problem`` other than the problem given is accepted only from a method
that matches a pending target load itself (``targets_load``), and only when it is the
given problem pushed by the package (:meth:`~signorini.problem.ContactProblem.pushed`:
the same K and N, ``f`` and ``d`` those of its push).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from signorini.problem import ContactProblem, ContactSolution

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


def _pushed_from(given: ContactProblem, other: ContactProblem) -> bool:
    """``other`` is ``given`` pushed by the package: same K and N, f and d from the same push."""
    pu, po = given.push, other.push
    if pu is None or po is None or other.K.shape != given.K.shape or other.N.shape != given.N.shape:
        return False
    x = _probe(given.K.shape[1])
    if not (np.allclose(other.K @ x, given.K @ x, rtol=SAME_PRODUCT_RTOL, atol=0.0)
            and np.allclose(other.N @ x, given.N @ x, rtol=SAME_PRODUCT_RTOL, atol=0.0)):
        return False
    if not (po.f1 is pu.f1 and po.d0 is pu.d0 and po.d1 is pu.d1 and po.f_load is pu.f_load):
        return False
    return (np.array_equal(other.f, po.f(po.scale, po.load))
            and np.array_equal(other.d, po.d0 + po.scale * po.d1))


def held_to_problem(problem: ContactProblem, before: Fingerprint, solution: ContactSolution,
                    method: str, may_push: bool = False) -> ContactSolution:
    """``solution``, or a ``failed`` one when the method changed ``problem`` or answered another.

    ``before`` is :func:`fingerprint` of ``problem`` taken before the method ran;
    ``may_push``: the method matches a pending target load itself and may answer
    the given problem pushed (see the module).
    """
    touched = changed(problem, before)
    if touched:
        names = ", ".join(f"{name} ({MEANING[name]})" for name in touched)
        return ContactSolution.failure(
            method, problem, "failed",
            f"the method changed the problem it was given: {names}; a method must not change "
            "K, f, N or d (copy them first), so its answer cannot be judged")
    other = solution.problem
    if other is not None and other is not problem and not (may_push and _pushed_from(problem, other)):
        return ContactSolution.failure(
            method, problem, "failed",
            "the method returned an answer to another problem (solution.problem is not the "
            "problem it was given): it is judged on the problem asked about, and has no answer "
            "to it")
    return solution
