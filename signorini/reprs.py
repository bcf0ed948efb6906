"""Short reprs: a record of arrays prints as a line or a few, not as its arrays.

``__repr__ = short_repr`` in a dataclass's body gives ``Name(field=value, …)`` with
numbers to four digits, arrays as their shape and kind, long text cut, mappings as their
keys and any other object as its type: a :class:`~signorini.api.Result` whose arrays hold
10⁵ numbers still reads in one glance.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

#: text longer than this is cut (with …)
TEXT = 80


def brief(value: Any) -> str:
    """One value in a few characters (see the module's note)."""
    if isinstance(value, (bool, np.bool_, int, np.integer)) or value is None:
        return repr(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.4g}"
    if isinstance(value, str):
        return repr(value if len(value) <= TEXT else value[:TEXT] + "…")
    if isinstance(value, np.ndarray):
        return f"<{value.dtype} array {'×'.join(map(str, value.shape)) or 'scalar'}>"
    if isinstance(value, dict):
        keys = ", ".join(map(str, list(value)[:6])) + (", …" if len(value) > 6 else "")
        return f"{{{keys}}}"
    if isinstance(value, (list, tuple)):
        return f"[{', '.join(map(brief, value))}]" if len(value) <= 4 else f"<{len(value)} items>"
    return f"<{type(value).__name__}>"


def short_repr(record: Any) -> str:
    """``Name(field=value, …)`` over a dataclass's fields shown in its repr, each :func:`brief`."""
    shown = [f"{f.name}={brief(getattr(record, f.name))}"
             for f in dataclasses.fields(record) if f.repr]
    return f"{type(record).__name__}({', '.join(shown)})"


__all__ = ["brief", "short_repr"]
