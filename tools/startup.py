"""What a whole process costs before any contact is computed: interpreters, imports, the default solve.

    .venv/bin/python tools/startup.py         # ~20 s here; writes docs/speed/startup.json

Each step is its own fresh process, timed from start to exit, the fastest of ``REPEAT`` runs
(interleaved); the byte-code cache is warm, as on a user's machine. The package's steps run
in this virtual environment, GetFEM's in the system Python that has it
(``signorini.studies.peer.system_python``). docs/peer.md quotes the table that ``table``
renders (tools/readme.py writes it there; tests/test_readme_numbers.py holds it).
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "startup.json"
REPEAT = 7
GETFEM_SCRIPT = ROOT / "benchmarks" / "peers" / "getfem_hertz.py"

#: (label, interpreter: "venv" or "system", argv after the interpreter)
STEPS = (
    ("Python, nothing imported", "venv", ["-c", "pass"]),
    ("import numpy", "venv", ["-c", "import numpy"]),
    ("import numpy, scipy.sparse, scipy.sparse.linalg", "venv",
     ["-c", "import numpy, scipy.sparse, scipy.sparse.linalg"]),
    ("… and scikit-fem", "venv", ["-c", "import numpy, scipy.sparse, scipy.sparse.linalg, skfem"]),
    ("… and scipy.spatial (Delaunay, k-d trees)", "venv",
     ["-c", "import numpy, scipy.sparse, scipy.sparse.linalg, skfem, scipy.spatial"]),
    ("import the package's command line", "venv", ["-c", "import signorini.cli.app"]),
    ("… and mesh the default cylinder (relaxed, 4,803 dofs)", "venv",
     ["-c", "import signorini.cli.app\nfrom signorini.scenes.meshing import graded_quarter_disc\n"
      "graded_quarter_disc(1.0, 0.05, 40, 0.15)"]),
    ("… and mesh it by bisection alone (`mesher=bisection`)", "venv",
     ["-c", "import signorini.cli.app\nfrom signorini.scenes.meshing import graded_quarter_disc\n"
      "graded_quarter_disc(1.0, 0.05, 40, 0.15, mesher='bisection')"]),
    ("`signorini solve hertz-cylinder` (4,803 dofs)", "venv",
     ["-m", "signorini.cli", "solve", "hertz-cylinder"]),
    ("`signorini solve hertz-cylinder --set n_contact=10` (1,957 dofs)", "venv",
     ["-m", "signorini.cli", "solve", "hertz-cylinder", "--set", "n_contact=10"]),
    ("GetFEM's Python, nothing imported", "system", ["-c", "pass"]),
    ("GetFEM's Python: import numpy, getfem, gmsh", "system", ["-c", "import numpy, getfem, gmsh"]),
    ("GetFEM: the cylinder at h = a/16 (2,298 dofs), our script", "system",
     [str(GETFEM_SCRIPT), '{"scene": "cylinder", "h_contact": 0.0625}']),
)


def interpreter(kind: str) -> str:
    if kind == "venv":
        return sys.executable
    from signorini.studies.peer import system_python
    return system_python()


def wall(argv: list[str]) -> float:
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, cwd=ROOT)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed: {done.stderr.decode().strip()[-300:]}")
    return elapsed


def run() -> dict:
    times: dict[str, list[float]] = {label: [] for label, _, _ in STEPS}
    load_before = os.getloadavg()
    for _ in range(REPEAT):  # interleaved: other load on the machine hits every step alike
        for label, kind, argv in STEPS:
            times[label].append(wall([interpreter(kind), *argv]))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=ROOT).stdout.strip()
    return {"command": "python tools/startup.py", "commit": commit,
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
            "load_before": load_before, "load_after": os.getloadavg(), "repeat": REPEAT,
            "rows": [{"step": label, "python": kind, "argv": argv, "runs_s": times[label],
                      "fastest_s": min(times[label])} for label, kind, argv in STEPS]}


def table(data: dict) -> str:
    """The Markdown table of the committed run: each step's fastest whole-process time."""
    lines = [f"`.venv/bin/python tools/startup.py` (commit {data['commit']}, {data['date'][:10]}, "
             f"fastest of {data['repeat']} fresh processes each, load average "
             f"{data['load_before'][0]:.1f} → {data['load_after'][0]:.1f}):", "",
             "| step | whole process [s] |", "|---|---:|"]
    lines += [f"| {r['step']} | {r['fastest_s']:.2f} |" for r in data["rows"]]
    return "\n".join(lines)


def reading(data: dict) -> str:
    """The sentence docs/peer.md draws from the committed run."""
    fastest = {r["step"]: r["fastest_s"] for r in data["rows"]}
    floor = fastest["… and scipy.spatial (Delaunay, k-d trees)"]
    getfem = fastest["GetFEM: the cylinder at h = a/16 (2,298 dofs), our script"]
    package = fastest["import the package's command line"]
    relaxed = fastest["… and mesh the default cylinder (relaxed, 4,803 dofs)"] - package
    bisected = fastest["… and mesh it by bisection alone (`mesher=bisection`)"] - package
    default = fastest["`signorini solve hertz-cylinder` (4,803 dofs)"]
    return (f"NumPy, SciPy's sparse modules, scikit-fem and scipy.spatial take {floor:.2f} s to "
            f"import, {floor / getfem:.1f}× GetFEM's whole process on its coarsest cylinder "
            f"({getfem:.2f} s, which already meets 0.1 %); within 2× of it leaves "
            f"{2 * getfem - floor:.2f} s for the package's own imports, meshing, assembly, "
            f"the solve, the certificate and the estimate. The default cylinder spends "
            f"{default:.2f} s: {package:.2f} s to import the command line, {relaxed:.2f} s to mesh "
            f"({bisected:.2f} s of it refining by bisection, the rest relaxing the triangles), "
            f"{default - package - relaxed:.2f} s for all the rest.")


def load() -> dict:
    return json.loads(OUT.read_text())


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    from signorini.files import atomic_write_text, to_json

    data = run()
    atomic_write_text(OUT, to_json(data))
    print(table(data))
    print(f"written: {OUT}", file=sys.stderr)
