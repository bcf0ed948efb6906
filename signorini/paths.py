"""Input and output paths checked before any work.

:func:`check_outputs` checks every output path of a command: that it can be written, that no two
outputs name the same file and that no output is one of the command's input files; it makes them
absolute, so that a method that changes the working folder cannot move them. How each output is
then written: :mod:`signorini.files`.
"""

from __future__ import annotations

import contextlib
import fnmatch
import os
import stat
import tempfile
from pathlib import Path
from typing import Any, Mapping

from signorini.errors import InputError

__all__ = ["STDOUT", "check_input_file", "check_output_file", "check_output_folder",
           "check_outputs", "where"]

STDOUT = "-"
_EXAMPLES = {"--json": "result.json", "--md": "result.md", "--vtk": "result.vtu"}


def where(path: str | os.PathLike) -> tuple[str, Path | int]:
    """``("replace", file)``, ``("through", device)`` or ``("fd", 1 or 2)`` for an output path."""
    target = Path(os.path.abspath(path))
    try:
        found = os.stat(target)  # follows links
    except OSError:  # a new file, the target of a dangling link (or a name too long, said later)
        return "replace", Path(os.path.realpath(target))
    for fd in (1, 2):
        with contextlib.suppress(OSError):
            if os.path.samestat(found, os.fstat(fd)):
                return "fd", fd
    if stat.S_ISDIR(found.st_mode):
        return "folder", target
    if stat.S_ISREG(found.st_mode):
        return "replace", Path(os.path.realpath(target))
    return "through", target


def _refuse(flag: str, path: Any, why: str, fix: str = "choose another path") -> InputError:
    return InputError(f"{flag} {str(path)!r} {why}: {fix}")


def _probe(folder: Path, flag: str, path: Any) -> None:
    """InputError unless a file can be created in ``folder`` (a real attempt, removed again)."""
    try:
        fd, name = tempfile.mkstemp(prefix=".signorini-probe.", dir=folder)
    except OSError as exc:
        raise _refuse(flag, path, f"cannot be written: the folder {str(folder)!r} takes no new "
                      f"files ({exc.strerror})", "choose a writable path") from None
    os.close(fd)
    os.unlink(name)


def check_output_file(path: str | os.PathLike, flag: str, coming: tuple[str, ...] = ()) -> str:
    """The absolute path of a file output (``-`` for standard output), or InputError naming ``flag``.

    The folder must exist and take new files, or be one of ``coming`` (absolute paths of output
    folders the command creates, checked already); the path must not be a folder, the name
    must fit the file system's limit and an existing file must be writable; checked before any
    work.
    """
    if str(path) == "":
        raise _refuse(flag, path, "is empty", f"give a file name, e.g. {flag} {_EXAMPLES.get(flag, 'result')}")
    if str(path) == STDOUT:
        return STDOUT
    kind, target = where(path)
    if kind == "fd":
        return STDOUT if target == 1 else os.path.abspath(path)
    if kind == "folder":
        raise _refuse(flag, path, "is a directory",
                      f"give a file name, e.g. {flag} {Path(path) / _EXAMPLES.get(flag, 'result')}")
    if kind == "through":
        if not os.access(target, os.W_OK):
            raise _refuse(flag, path, "is not writable", "choose a writable path")
        return os.path.abspath(path)
    if not target.parent.is_dir():
        if os.path.abspath(target.parent) in coming:  # the command makes the folder first
            return os.path.abspath(path)
        raise _refuse(flag, path, f"cannot be written: the folder {str(target.parent)!r} does not exist",
                      "create it or choose another path")
    try:
        longest = os.pathconf(target.parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        longest = 255
    if len(os.fsencode(target.name)) > longest:
        raise InputError(f"{flag}: the file name is {len(os.fsencode(target.name))} bytes long, "
                         f"over this file system's {longest}: choose a shorter name")
    _probe(target.parent, flag, path)
    if target.exists():
        try:  # opened for writing, not truncated: refuses a read-only or immutable file
            os.close(os.open(target, os.O_WRONLY))
        except OSError as exc:
            raise _refuse(flag, path, f"cannot be replaced ({exc.strerror})",
                          "choose a writable path") from None
    return os.path.abspath(path)


def check_output_folder(path: str | os.PathLike, flag: str = "--out") -> str:
    """The absolute path of an output folder, or InputError naming ``flag``; nothing is created.

    An existing folder must take new files; a new one must be creatable in the
    nearest folder that exists.
    """
    if str(path) == "":
        raise _refuse(flag, path, "is empty", f"give a folder, e.g. {flag} report")
    folder = Path(os.path.abspath(path))
    existing = next(p for p in (folder, *folder.parents) if p.exists() or p.is_symlink())
    if not existing.is_dir():
        raise _refuse(flag, path, f"cannot be a folder: {str(existing)!r} is a file",
                      "choose a writable folder")
    _probe(existing, flag, path)
    return str(folder)


def check_input_file(path: str, what: str, missing: str = "") -> None:
    """InputError when ``path`` exists but is not a regular file (a FIFO would wait forever), or
    with ``missing`` (the fix) when it does not exist."""
    if missing and not os.path.exists(path):
        raise InputError(f"{what} {path} does not exist: {missing}")
    if os.path.exists(path) and not os.path.isfile(path):
        raise InputError(f"{what} {path!r} is not a regular file (a folder, FIFO or device): "
                         "give a file")


def _same(path: str, other: str) -> bool:
    """Whether two paths name one file (a device or FIFO can take several outputs)."""
    def identity(name: str) -> tuple:
        try:
            found = os.stat(name)
            return found.st_dev, found.st_ino
        except OSError:
            return (os.path.realpath(name),)

    return identity(path) == identity(other) and where(path)[0] != "through"


def check_outputs(files: Mapping[str, str | None] = {}, folders: Mapping[str, str | None] = {},
                  inputs: Mapping[str, str | None] = {},
                  fills: Mapping[str, tuple[str, ...]] = {}) -> dict[str, str | None]:
    """Every output of a command checked before any work: flag → absolute path (None when not given).

    ``files`` and ``folders`` map flags to output paths, ``inputs`` names to
    the command's input files, ``fills`` a folder's flag to the names (glob
    patterns) of the files it will hold. InputError, naming both, when two
    outputs are one file (or a folder's), or an output is an input; a device
    (``/dev/null``) may take several.
    """
    given = {**files, **folders}
    made = {flag: None if path is None else check_output_folder(path, flag)
            for flag, path in folders.items()}
    coming = tuple(path for path in made.values() if path is not None and not os.path.isdir(path))
    out = {flag: None if path is None else check_output_file(path, flag, coming)
           for flag, path in files.items()}
    out.update(made)
    named = [(flag, path) for flag, path in out.items() if path is not None]
    for i, (flag, path) in enumerate(named):
        for other, there in named[:i]:
            if path == there == STDOUT or STDOUT not in (path, there) and _same(path, there):
                raise InputError(f"{other} {given[other]!r} and {flag} {given[flag]!r} are the "
                                 "same file: give them different paths")
        for folder, patterns in fills.items():
            if flag != folder and _fills(out.get(folder), patterns, path):
                raise InputError(f"{flag} {given[flag]!r} is a file that {folder} "
                                 f"{given[folder]!r} writes ({', '.join(patterns)}): give "
                                 f"{flag} another name or folder")
        for name, source in inputs.items():
            if source and path != STDOUT and os.path.exists(source) and _same(path, source):
                raise InputError(f"{flag} {given[flag]!r} is the {name}: writing it would destroy "
                                 f"an input; choose another path for {flag}")
    for folder, patterns in fills.items():
        taken = [name for name, source in inputs.items() if _fills(out.get(folder), patterns, source)]
        if taken:
            raise InputError(f"{folder} {given[folder]!r} would write over the {taken[0]}: "
                             f"choose another folder for {folder}")
    return out


def _fills(folder: str | None, patterns: tuple[str, ...], path: str | None) -> bool:
    """Whether ``path`` is one of the files named by ``patterns`` in ``folder``."""
    inside = bool(folder and path and path != STDOUT) and os.path.dirname(os.path.abspath(path)) == folder
    return inside and any(fnmatch.fnmatch(os.path.basename(path), p) for p in patterns)

