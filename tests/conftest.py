"""Shared fixtures."""

from __future__ import annotations

import pytest


@pytest.fixture
def saved_figures(monkeypatch):
    """Every matplotlib figure saved while the test runs, in order: a figure test can then check
    what it shows (axes, legend, the plotted data), not only that a file was written."""
    from matplotlib.figure import Figure

    saved = []
    original = Figure.savefig

    def record(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return saved
