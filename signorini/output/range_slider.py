"""A slider that is a plain ``<input type="range">`` in the page (an anywidget).

The explorer's sliders: a browser's own range input, keyboard- and test-friendly; its value
reaches Python when the slider is released (``change``), so that one drag is one re-solve.
"""

from __future__ import annotations

from pathlib import Path

import anywidget
import traitlets

__all__ = ["RangeSlider"]

#: the widget's JavaScript module, beside this file
ESM = Path(__file__).with_name("range_slider.js")


class RangeSlider(anywidget.AnyWidget):
    """``start ≤ value ≤ stop`` in steps of ``step``; ``name`` is the input's name in the page."""

    _esm = ESM
    value = traitlets.Float(0.0).tag(sync=True)
    start = traitlets.Float(0.0).tag(sync=True)
    stop = traitlets.Float(1.0).tag(sync=True)
    step = traitlets.Float(0.01).tag(sync=True)
    name = traitlets.Unicode("").tag(sync=True)
    label = traitlets.Unicode("").tag(sync=True)
