"""The library side of the tutorials (docs/tutorials/): the dual function, a two-contact-point
model, synthetic problems and the tutorials' figures."""

from signorini.teaching.dual import dense_dual, lagrangian, objectives, solve_recorded, uzawa_path
from signorini.teaching.synthetic import bogie, random_problem

__all__ = ["bogie", "dense_dual", "lagrangian", "objectives", "random_problem", "solve_recorded",
           "uzawa_path"]
