"""What the package shows: reports of the validation suite, plots, VTK export."""
