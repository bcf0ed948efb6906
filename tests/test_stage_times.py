"""The record's ``time`` covers the whole solve: its stages sum to the wall time of the solve."""

from __future__ import annotations

import time

import signorini
from signorini.api import solve_summary
from signorini.result import STAGES, stage_key


def test_the_stages_sum_to_the_wall_time_of_a_solve_and_its_record():
    signorini.solve("hertz-cylinder")  # the modules a first solve imports are start-up, not its stages
    start = time.perf_counter()
    record = signorini.solve("hertz-cylinder").to_dict()
    wall = time.perf_counter() - start
    seconds = record["time"]
    assert {stage_key(stage) for stage in STAGES} <= set(seconds)
    ran = ("mesh", "assemble", "load control", "method", "certificate", "estimate", "output")
    assert all(seconds[stage_key(stage)] > 0 for stage in ran)  # a load-controlled cylinder
    assert abs(sum(seconds[stage_key(stage)] for stage in STAGES) - seconds["total_s"]) < 1e-12
    assert abs(seconds["total_s"] / wall - 1) < 0.05
    assert seconds["build_s"] + seconds["solve_s"] <= seconds["method_s"]


def test_the_summary_names_the_largest_stages():
    seconds = {stage_key(stage): 0.0 for stage in STAGES}
    seconds.update(mesh_s=0.5, method_s=0.2, estimate_s=0.1, output_s=0.05, total_s=0.85)
    record = {"scene": "s", "method": "pdas", "status": "converged", "iterations": 1,
              "message": "", "dofs": 10, "contact_candidates": 2, "time": seconds, "kkt": {},
              "extras": {}}
    line = solve_summary(record).splitlines()[1]
    assert "time 0.85 s: mesh 0.50, method 0.20, estimate 0.10" in line
    assert "output" not in line
