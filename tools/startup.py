"""What a whole process costs before any contact is computed: interpreters, imports, the default solve.

    .venv/bin/python tools/startup.py         # ~2 min here; writes docs/speed/startup.json

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

def meshing(imports: str, disc: str) -> str:
    """Code that imports ``imports`` and meshes the Hertz disc (n_contact, grading, mesher)."""
    return (f"import {imports}\nfrom signorini.scenes.meshing import graded_quarter_disc\n"
            f"graded_quarter_disc(1.0, 0.05, {disc})")


#: (label, interpreter: "venv" or "system", argv after the interpreter)
FLOOR = "import numpy, scipy.sparse"
COMMAND_LINE = "import the package's command line"
DEFAULT_MESH = "… and mesh the default cylinder (Triangle, 5,207 dofs)"
SOLVERS = "… and import the solvers, load control and the certificate (`signorini.api`)"
DEFAULT_SOLVE = "`signorini solve hertz-cylinder` (5,207 dofs)"
STEEL = ("the held-out steel cylinder: `signorini solve hertz-cylinder --set E=2.1e11 --set nu=0.3 "
         "--set R=0.02 --set a_over_R=0.05`")
FEM_IMPORTS = "… and scipy.sparse.linalg, scikit-fem"
GETFEM = "GetFEM: the cylinder at h = a/16 (2,298 dofs), our script"
STEPS = (
    ("Python, nothing imported", "venv", ["-c", "pass"]),
    ("import numpy", "venv", ["-c", "import numpy"]),
    (FLOOR, "venv", ["-c", "import numpy, scipy.sparse"]),
    (FEM_IMPORTS, "venv",
     ["-c", "import numpy, scipy.sparse, scipy.sparse.linalg, skfem"]),
    (COMMAND_LINE, "venv", ["-c", "import signorini.cli.app"]),
    (DEFAULT_MESH, "venv", ["-c", meshing("signorini.cli.app", "24, 0.11, mesher='triangle'")]),
    (SOLVERS, "venv",
     ["-c", meshing("signorini.cli.app, signorini.api", "24, 0.11, mesher='triangle'")]),
    ("… and mesh it by the relaxed mesher instead (n_contact=40, grading=0.15)", "venv",
     ["-c", meshing("signorini.cli.app", "40, 0.15, mesher='relaxed'")]),
    (DEFAULT_SOLVE, "venv", ["-m", "signorini.cli", "solve", "hertz-cylinder"]),
    (STEEL, "venv", ["-m", "signorini.cli", "solve", "hertz-cylinder", "--set", "E=2.1e11", "--set",
                     "nu=0.3", "--set", "R=0.02", "--set", "a_over_R=0.05"]),
    ("GetFEM's Python, nothing imported", "system", ["-c", "pass"]),
    ("GetFEM's Python: import numpy, getfem, gmsh", "system", ["-c", "import numpy, getfem, gmsh"]),
    (GETFEM, "system", [str(GETFEM_SCRIPT), '{"scene": "cylinder", "h_contact": 0.0625}']),
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
    """The sentence docs/peer.md draws from the committed run: the whole process against the
    import of NumPy and scipy.sparse alone, and against GetFEM's, measured in the same run."""
    fastest = {r["step"]: r["fastest_s"] for r in data["rows"]}
    floor, getfem, steel = fastest[FLOOR], fastest[GETFEM], fastest[STEEL]
    solve, meshed, imports = fastest[DEFAULT_SOLVE], fastest[DEFAULT_MESH], fastest[FEM_IMPORTS]
    solvers = fastest[SOLVERS]
    return (f"The held-out steel cylinder's whole process takes {steel:.2f} s: "
            f"{steel - floor:.2f} s above importing NumPy and scipy.sparse alone ({floor:.2f} s; "
            f"the aim is at most 0.15 s above it) and {steel / getfem:.2f}× GetFEM's whole process "
            f"on its coarsest cylinder ({getfem:.2f} s; the aim is at most 1.25×). Of the default "
            f"cylinder's {solve:.2f} s, {meshed:.2f} s pass before its mesh exists (the imports of "
            f"NumPy, SciPy's sparse modules and scikit-fem alone take {imports:.2f} s of them; the "
            f"command line itself, imported lazily, {fastest[COMMAND_LINE]:.2f} s), "
            f"{solvers - meshed:.2f} s import the solvers, load control and the certificate, and "
            f"{solve - solvers:.2f} s are assembly, load control, the solve, the certificate, the "
            f"estimate and the output.")


def load() -> dict:
    return json.loads(OUT.read_text())


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    from signorini.files import atomic_write_text, to_json

    data = run()
    atomic_write_text(OUT, to_json(data))
    print(table(data))
    print(f"written: {OUT}", file=sys.stderr)
