"""What the package shows: reports of the validation suite, plots, VTK export."""

from signorini.output.export import export_vtk
from signorini.output.plots import pressure_profile
from signorini.output.report import provenance, write_suite_report

__all__ = ["export_vtk", "pressure_profile", "provenance", "write_suite_report"]
