"""What a small solve and a slider's step cost in process, stage by stage (docs/performance.md).

    .venv/bin/python tools/slider_timing.py

The default cylinder meshed afresh (the graded disc's cache cleared) ``REPEAT`` times, then a load
slider (:func:`signorini.with_load` on one built problem) and a material slider (``E`` through
``params``, the mesh kept); the medians of each stage of the record's ``time``, and the first as
docs/performance.md's table.
"""

from __future__ import annotations

import os
import statistics
import time

import signorini
from signorini.scenes.meshing import graded_unit_disc

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


def medians(runs: list[tuple[float, dict[str, float]]]) -> str:
    walls = [wall for wall, _ in runs]
    stages = {key: statistics.median(t[key] for _, t in runs) for key in runs[0][1]}
    return (f"wall median {statistics.median(walls):.3f} s ({min(walls):.3f}–{max(walls):.3f}); "
            + ", ".join(f"{key} {value:.3f}" for key, value in stages.items()))


#: the record's stages as docs/performance.md names them
STAGES = {"mesh_s": "mesh (`mesh_s`)", "assemble_s": "assemble", "load_control_s": "load control",
          "method_s": "method", "certificate_s": "certificate", "estimate_s": "estimate",
          "output_s": "output (the record)"}


def table(runs: list[tuple[float, dict[str, float]]]) -> str:
    """The medians of each stage as docs/performance.md's table, the wall time's median last."""
    lines = ["| stage | seconds |", "|---|---:|"]
    lines += [f"| {name} | {statistics.median(t[key] for _, t in runs):.3f} |"
              for key, name in STAGES.items()]
    total = statistics.median(t["total_s"] for _, t in runs)
    wall = statistics.median(wall for wall, _ in runs)
    cpu = statistics.median(t["cpu_s"] for _, t in runs)
    return "\n".join(lines + [f"| **total** (wall, median: {wall:.3f}) | **{total:.3f}** |",
                              f"| the process's CPU time (median) | {cpu:.3f} |"])


def main() -> None:
    signorini.solve("hertz-cylinder")  # imports and first calls out of the way
    fresh = []
    for _ in range(REPEAT):
        graded_unit_disc.cache_clear()
        fresh.append(timed(lambda: signorini.solve("hertz-cylinder")))
    problem = signorini.build_problem("hertz-cylinder")
    load = [timed(lambda: signorini.solve(signorini.with_load(problem, a_over_R=a))) for a in LOADS]
    material = [timed(lambda: signorini.solve("hertz-cylinder", params={"E": E})) for E in MODULI]
    print(f"the default cylinder, meshed afresh: {medians(fresh)}")
    print(table(fresh))
    print(f"a load slider's step (with_load): {medians(load)}")
    print(f"a material slider's step (E, the mesh kept): {medians(material)}")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
