"""The registry of scene families by name: register one, look one up, read one field of all.

A family is one module with a ``FAMILY = SceneFamily(...)``
(:class:`~signorini.scenes.base.SceneFamily`) and one call
``register(FAMILY)``; the built-in ones are registered by
:mod:`signorini.scenes.families`. Everything that needs to know a family
(the size guard, adaptive refinement, coarse models, the validation suite,
convergence studies) reads it from here.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from signorini.errors import InputError, docs_page
from signorini.problem.files import is_problem_file
from signorini.scenes.base import Case, SceneFamily

SCENES: dict[str, SceneFamily] = {}


def register(family: SceneFamily, *, replace: bool = False) -> SceneFamily:
    """Add ``family`` to :data:`SCENES` under its name and return it.

    A family needs a size model (the size guard refuses a scene too big for
    the machine before it is meshed); a name already taken is refused unless
    ``replace``.
    """
    if not isinstance(family, SceneFamily):
        raise InputError(f"register takes a SceneFamily, got {type(family).__name__}")
    if family.size_model is None:
        raise InputError(f"scene family {family.name!r} has no size model: give it "
                         "size_model= (signorini.scenes.size.SizeModel, or CountedSize for a "
                         "mesh counted from its parameters) before registering it")
    if family.name in SCENES and not replace and SCENES[family.name] is not family:
        raise InputError(f"scene family {family.name!r} is already registered: choose another "
                         "name or pass replace=True")
    SCENES[family.name] = family
    return family


def unregister(name: str) -> SceneFamily | None:
    """Remove the family ``name`` from :data:`SCENES`; it is returned (None when there was none)."""
    return SCENES.pop(name, None)


def get_scene(name: str) -> SceneFamily:
    """Look a scene family up by name; unknown names list the known ones."""
    if name not in SCENES and is_problem_file(name):
        raise InputError(f"{name!r} is a problem file, and this needs a scene (see 'signorini "
                         "scenes'): a problem file goes to solve, crosscheck, validate --problem "
                         "and bench --problem")
    if name not in SCENES:
        raise InputError(f"unknown scene {name!r}: choose one of {', '.join(sorted(SCENES))} "
                         "(or give the path of a .toml scene file, or of a problem file: .npz or "
                         f"Matrix Market, see {docs_page('problem-files')})")
    return SCENES[name]


def scene_reference(name: str) -> str:
    """The analytic reference of scene ``name`` ("" for scenes read from mesh files)."""
    return SCENES[name].reference if name in SCENES else ""


class FamilyField(Mapping):
    """One field of every registered family that has it, by family name: a live, read-only view
    (e.g. ``FamilyField("size_model")``), so a family registered later is in it."""

    def __init__(self, field: str):
        self.field = field

    def _items(self) -> dict[str, Any]:
        return {name: getattr(f, self.field) for name, f in SCENES.items() if getattr(f, self.field)}

    def __getitem__(self, name: str) -> Any:
        return self._items()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._items())

    def __len__(self) -> int:
        return len(self._items())

    def __repr__(self) -> str:
        return f"FamilyField({self.field!r}: {', '.join(self._items())})"


class ValidationCases(Sequence):
    """Every registered family's validation cases, in the order of registration: a live,
    read-only sequence (a family registered later adds its cases)."""

    def _cases(self) -> tuple[Case, ...]:
        return tuple(case for family in SCENES.values() for case in family.validation)

    def __getitem__(self, index):
        return self._cases()[index]

    def __len__(self) -> int:
        return len(self._cases())

    def __repr__(self) -> str:
        return f"ValidationCases({', '.join(case.name for case in self._cases())})"


__all__ = ["register", "unregister", "get_scene", "scene_reference", "FamilyField",
           "ValidationCases", "SCENES"]
