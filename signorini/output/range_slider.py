"""A slider that is a plain ``<input type="range">`` in the page (an anywidget).

The explorer's sliders: a browser's own range input, keyboard- and test-friendly; its value
reaches Python when the slider is released (``change``), so that one drag is one re-solve.
"""

from __future__ import annotations

import anywidget
import traitlets

__all__ = ["RangeSlider"]

_ESM = """
function render({ model, el }) {
  const label = document.createElement("label");
  const input = document.createElement("input");
  const shown = document.createElement("output");
  input.type = "range";
  input.name = model.get("name");
  input.min = model.get("start");
  input.max = model.get("stop");
  input.step = model.get("step");
  input.value = model.get("value");
  input.style.width = "14em";
  shown.textContent = model.get("value");
  label.textContent = model.get("label") + " ";
  input.addEventListener("input", () => { shown.textContent = input.value; });
  input.addEventListener("change", () => {
    model.set("value", Number(input.value));
    model.save_changes();
  });
  label.append(input, " ", shown);
  el.appendChild(label);
}
export default { render };
"""


class RangeSlider(anywidget.AnyWidget):
    """``start ≤ value ≤ stop`` in steps of ``step``; ``name`` is the input's name in the page."""

    _esm = _ESM
    value = traitlets.Float(0.0).tag(sync=True)
    start = traitlets.Float(0.0).tag(sync=True)
    stop = traitlets.Float(1.0).tag(sync=True)
    step = traitlets.Float(0.01).tag(sync=True)
    name = traitlets.Unicode("").tag(sync=True)
    label = traitlets.Unicode("").tag(sync=True)
