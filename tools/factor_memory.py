"""PARDISO's analysis-phase memory estimate against the resident memory its factorisation took.

    .venv/bin/python tools/factor_memory.py    # docs/speed/factor-memory.json (≈ 2 min here)

For each model, a ``fresh`` task of the studies' runner (a worker process of its own): the
model is built (a prescribed push: no load targeting), then one
:class:`signorini.numerics.factor.PardisoFactor` of K, whose analysis (phase 11) gives
the estimate the package refuses a factorisation by (``memory``, from iparm 15–17);
``resident_growth`` is the worker's resident set size after it minus before it (the
runner's ``factor_memory`` measure).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from readme import provenance  # noqa: E402  (tools/readme.py)

from signorini.files import atomic_write_text  # noqa: E402
from signorini.studies.runner import run_tasks  # noqa: E402
from signorini.studies.task import BUILD_ONLY, Task  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "factor-memory.json"
MODELS = (("hertz-cylinder", {"refine": 2, "delta": 0.001}),
          ("hertz-cylinder", {"refine": 3, "delta": 0.001}),
          ("hertz-sphere-3d", {"refine": 1, "delta": 0.0025}),
          ("hertz-sphere-3d", {"refine": 2, "delta": 0.0025}))
#: seconds a model's build and factorisation may take
TIME_LIMIT = 600.0


def tasks(models=MODELS) -> list[Task]:
    """A fresh build-only task per model that measures its factorisation's memory."""
    return [Task(axis="factor-memory", case=scene, value="", method=BUILD_ONLY, fresh=True,
                 problem={"kind": "scene", "scene": scene, "params": params},
                 reference={"kind": "none"}, measure=("factor_memory",))
            for scene, params in models]


def run(models=MODELS) -> list[dict]:
    rows = []
    for (scene, params), row in zip(models, run_tasks(tasks(models), time_limit=TIME_LIMIT)):
        if "factor_memory" not in row:
            raise RuntimeError(f"{scene} {params}: {row['status']}: {row['message']}")
        rows.append({"scene": scene, "params": params, "dofs": row["dofs"], **row["factor_memory"]})
        print(rows[-1], flush=True)
    return rows


def main() -> int:
    rows = run()
    atomic_write_text(OUT, json.dumps({**provenance("factor_memory.py"), "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
