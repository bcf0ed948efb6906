"""What a small solve and a slider's step cost in process, stage by stage (docs/performance.md).

    .venv/bin/python tools/slider_timing.py     # writes docs/speed/slider.json

The default cylinder meshed afresh (the graded disc's cache cleared) ``REPEAT`` times, then a load
slider (:func:`signorini.with_load` on one built problem) and a material slider (``E`` through
``params``, the mesh kept). Every run's wall time and record ``time`` are stored; tools/readme.py
renders docs/performance.md's table (:func:`table`) and the sliders' lines (:func:`steps`) from the
committed file.
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "slider.json"

REPEAT = 7
LOADS = (0.03, 0.035, 0.04, 0.045, 0.055, 0.06, 0.065, 0.07)
MODULI = (1.0, 1.5, 2.0, 2.5, 3.0, 3.5)


def timed(solve) -> tuple[float, dict[str, float]]:
    """The wall time of ``solve()`` and its record, and the record's ``time`` with the process's
    CPU time over the same span (``cpu_s``: what the solve costs when other work shares the
    cores, which stretches its wall time)."""
    start, cpu = time.perf_counter(), time.process_time()
    record = solve().to_dict()
    return time.perf_counter() - start, {**record["time"], "cpu_s": time.process_time() - cpu}


def median(runs: list, key: str) -> float:
    return statistics.median(t[key] for _, t in runs)


#: the record's stages as docs/performance.md names them
STAGES = {"mesh_s": "mesh (`mesh_s`)", "assemble_s": "assemble", "load_control_s": "load control",
          "method_s": "method", "certificate_s": "certificate", "estimate_s": "estimate",
          "output_s": "output (the record)"}


def table(data: dict) -> str:
    """The medians of each stage of the fresh solves, the wall time's median last."""
    runs = data["fresh"]
    lines = [f"`.venv/bin/python tools/slider_timing.py` ({data['date'][:16].replace('T', ' ')} UTC, "
             f"the median of {len(runs)} solves each meshed afresh, one-minute load average "
             f"{data['load_before']:.1f} → {data['load_after']:.1f}):", "",
             "| stage | seconds |", "|---|---:|"]
    lines += [f"| {name} | {median(runs, key):.3f} |" for key, name in STAGES.items()]
    wall = statistics.median(wall for wall, _ in runs)
    return "\n".join(lines + [f"| **total** (wall, median: {wall:.3f}) | **{median(runs, 'total_s'):.3f}** |",
                              f"| the process's CPU time (median) | {median(runs, 'cpu_s'):.3f} |"])


def steps(data: dict) -> str:
    """The two sliders' steps, medians of the same run."""
    load, material = data["load"], data["material"]
    walls = [wall for wall, _ in load]
    return (f"A load slider's step, `signorini.solve(signorini.with_load(problem, a_over_R=a))"
            f".to_dict()`, took **{statistics.median(walls):.3f} s** of wall time and "
            f"{median(load, 'cpu_s'):.3f} s of CPU (medians of {len(load)} steps over a/R = "
            f"{min(LOADS)}…{max(LOADS)}; {min(walls):.3f}–{max(walls):.3f} s): load control "
            f"{median(load, 'load_control_s'):.3f}, the method {median(load, 'method_s'):.3f}, "
            f"certificate {median(load, 'certificate_s'):.3f}, estimate "
            f"{median(load, 'estimate_s'):.3f}. A material slider's step "
            f"(`signorini.solve(\"hertz-cylinder\", params={{\"E\": E}})`, the mesh kept) took "
            f"**{statistics.median(w for w, _ in material):.3f} s** of wall time and "
            f"{median(material, 'cpu_s'):.3f} s of CPU (medians of {len(material)}), of which "
            f"placing the kept mesh {median(material, 'mesh_s'):.3f} and assembly "
            f"{median(material, 'assemble_s'):.3f}.")


def run() -> dict:
    import signorini
    from signorini.scenes.meshing import graded_unit_disc

    load_before = os.getloadavg()[0]
    signorini.solve("hertz-cylinder")  # imports and first calls out of the way
    fresh = []
    for _ in range(REPEAT):
        graded_unit_disc.cache_clear()
        fresh.append(timed(lambda: signorini.solve("hertz-cylinder")))
    problem = signorini.build_problem("hertz-cylinder")
    load = [timed(lambda: signorini.solve(signorini.with_load(problem, a_over_R=a))) for a in LOADS]
    material = [timed(lambda: signorini.solve("hertz-cylinder", params={"E": E})) for E in MODULI]
    return {"command": "python tools/slider_timing.py",
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "load_before": load_before, "load_after": os.getloadavg()[0],
            "fresh": fresh, "load": load, "material": material}


def load() -> dict:
    return json.loads(OUT.read_text())


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    from signorini.files import atomic_write_text, to_json

    data = run()
    atomic_write_text(OUT, to_json(data))
    print(table(data))
    print(steps(data))
    print(f"written: {OUT}", file=sys.stderr)
