"""Studies: lists of runs through one runner (:mod:`~signorini.studies.runner`).

The validation suite (:mod:`~signorini.studies.suite`), the benchmark
(:mod:`~signorini.studies.bench`), the stability atlas (:mod:`~signorini.studies.atlas`),
refinement studies (:mod:`~signorini.studies.convergence`) and load sweeps
(:mod:`~signorini.studies.sweep`).
"""

from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

__all__ = ["Task", "run_tasks"]
