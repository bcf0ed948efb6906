"""PARDISO's analysis-phase memory estimate against the resident memory its factorisation took.

    .venv/bin/python tools/factor_memory.py    # docs/speed/factor-memory.json (≈ 2 min here)

For each model: build it (a prescribed push: no load targeting), then one
:class:`signorini.numerics.factor.PardisoFactor` of K, whose analysis (phase 11) gives
the estimate the package refuses a factorisation by (``memory``, from iparm 15–17);
``resident_growth`` is the process's resident set size after it minus before it.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
from pathlib import Path

import signorini
from signorini.files import atomic_write_text
from signorini.numerics.factor import PardisoFactor

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "factor-memory.json"
MODELS = (("hertz-cylinder", {"refine": 2, "delta": 0.001}),
          ("hertz-cylinder", {"refine": 3, "delta": 0.001}),
          ("hertz-sphere-3d", {"refine": 1, "delta": 0.0025}),
          ("hertz-sphere-3d", {"refine": 2, "delta": 0.0025}))


def resident() -> float:
    """This process's resident set size in bytes."""
    with open("/proc/self/statm", encoding="ascii") as statm:
        return float(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def main() -> int:
    rows = []
    for scene, params in MODELS:
        problem = signorini.build_problem(scene, params=params)
        before = resident()
        factor = PardisoFactor(problem.K)
        growth = resident() - before
        rows.append({"scene": scene, "params": params, "dofs": problem.n,
                     "estimate_bytes": factor.memory, "resident_growth_bytes": growth,
                     "ratio": factor.memory / growth})
        print(rows[-1], flush=True)
        del factor
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    atomic_write_text(OUT, json.dumps({
        "command": "python tools/factor_memory.py", "commit": commit,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
