"""Factorisation + one solve of the Hertz cylinder's K with every installed backend.

    .venv/bin/python examples/factorisations.py [LEVELS]   # default 0,1,2,3

The scene is the benchmark's (n_contact=110, grading=0.1) at the given refinement
levels (about 17k, 66k, 261k and 1.04M dofs), pushed by a fixed delta so that no load
targeting runs. Each time is the best of three in this process, after one small
factorisation has loaded the backend's library; SuperLU is skipped above 300k dofs
(it needs minutes there). docs/speed.md quotes this script's output.
"""

import sys
import time

import numpy as np
import scipy.sparse as sp

from signorini.numerics.factor import available_backends, factorize
from signorini.scenes import build_problem

levels = [int(x) for x in (sys.argv[1] if len(sys.argv) > 1 else "0,1,2,3").split(",")]
backends = available_backends()
for backend in backends:
    factorize(sp.identity(2, format="csc"), backend).solve(np.ones(2))
print("| dofs | " + " | ".join(backends) + " |")
print("|---:|" + "---:|" * len(backends))
for level in levels:
    problem = build_problem("hertz-cylinder", params={"refine": level, "n_contact": 110, "grading": 0.1,
                                                      "delta": 0.0025})
    cells = []
    for backend in backends:
        if backend == "superlu" and problem.n > 300_000:
            cells.append("—")
            continue
        times = []
        for _ in range(3):
            start = time.perf_counter()
            factorize(problem.K, backend).solve(problem.f)
            times.append(time.perf_counter() - start)
        cells.append(f"{min(times):.3g} s")
    print(f"| {problem.n:,} | " + " | ".join(cells) + " |", flush=True)
