"""The block on a flat: a patch test. Every contact node carries the pressure E*δ/H.

Run it to print the nodal pressures' largest deviation; the tests import it.
"""

from __future__ import annotations

import numpy as np

import signorini
from signorini.references.analytic import contact_modulus
from signorini.references.pressure import compare_uniform, contact_profile
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

PARAMS = {"W": 0.5, "H": 0.2, "E": 70e9, "nu": 0.33, "delta": 1e-4, "nx": 10, "ny": 4}

problem = signorini.at_load(build_problem("block", params=PARAMS))
solution = solve(problem, "pdas", tol=1e-9)
uniform = compare_uniform(problem, solution)
profile = contact_profile(problem, solution)
pressure_expected = contact_modulus(PARAMS["E"], PARAMS["nu"]) * PARAMS["delta"] / PARAMS["H"]

if __name__ == "__main__":
    print(f"expected pressure E*δ/H = {pressure_expected:.6e} Pa")
    print(f"nodal pressures from {profile.pressure.min():.6e} to {profile.pressure.max():.6e} Pa "
          f"(largest relative deviation {uniform.pressure_max_rel:.1e})")
    print(f"total force {profile.total_force:.6e} N/m = 2 W p = {2 * PARAMS['W'] * pressure_expected:.6e}"
          f"; all {int(np.sum(profile.active))} of {problem.m} nodes in contact")
