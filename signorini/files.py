"""Result files written whole or not at all, and every output checked before any work.

Where an output goes decides how it is written:

- a new path or a regular file: a temporary file in the same folder, renamed
  onto it (readers see the old file or the new one, never half of one);
- a symbolic link: followed, its target replaced that way, the link kept;
- a device, a FIFO or a socket (``/dev/null``, a named pipe): opened and
  written through, never replaced;
- this process's own standard output (``/dev/stdout``, ``/proc/self/fd/1``):
  the same as ``-``.

Within :func:`all_or_none` the outputs are produced under temporary names and
take their places only when the whole block succeeded; otherwise none does.
:func:`check_outputs` checks every output path of a command before any work:
that it can be written, that no two outputs name the same file and that no
output is one of the command's input files; it makes them absolute, so that
a method that changes the working folder cannot move them.
"""

from __future__ import annotations

import contextlib
import fnmatch
import json
import math
import os
import stat
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping

import numpy as np

from signorini.errors import InputError, OutputError

STDOUT = "-"
_EXAMPLES = {"--json": "result.json", "--md": "result.md", "--vtk": "result.vtu"}
#: outputs produced inside :func:`all_or_none`, waiting to take their places
_staged: list[tuple[str | None, Path | int, bytes | None]] | None = None
#: folders :func:`writable_directory` created (removed again while still empty)
_created: list[Path] = []
#: the mark of a file being written under a temporary name (:func:`atomic_write`), and the
#: folders written into, by this process or by its workers below them (:func:`remove_partial_files`)
PARTIAL, _written = ".signorini-partial.", set[Path]()


def _where(path: str | os.PathLike) -> tuple[str, Path | int]:
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


def check_output_file(path: str | os.PathLike, flag: str) -> str:
    """The absolute path of a file output (``-`` for standard output), or InputError naming ``flag``.

    The folder must exist and take new files, the path must not be a folder,
    the name must fit the file system's limit and an existing file must be
    writable; checked before any work.
    """
    if str(path) == "":
        raise _refuse(flag, path, "is empty", f"give a file name, e.g. {flag} {_EXAMPLES.get(flag, 'result')}")
    if str(path) == STDOUT:
        return STDOUT
    kind, target = _where(path)
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

    return identity(path) == identity(other) and _where(path)[0] != "through"


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
    out = {flag: None if path is None else check_output_file(path, flag)
           for flag, path in files.items()}
    out.update({flag: None if path is None else check_output_folder(path, flag)
                for flag, path in folders.items()})
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


def writable_directory(path: str | os.PathLike) -> Path:
    """Create ``path`` if needed; InputError when it cannot be a writable directory.

    Folders created here are removed again by :func:`remove_empty_folders`
    while nothing was written into them.
    """
    directory = Path(path)
    if str(path) == "":
        raise _refuse("--out", path, "is empty", "give a folder, e.g. --out report")
    missing = [p for p in (directory, *directory.parents) if not p.exists()]
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {str(directory)!r} cannot be created ({exc.strerror}): "
                         "choose a writable directory") from None
    _created.extend(reversed(missing))
    _written.add(directory.absolute())
    if not os.access(directory, os.W_OK):
        raise InputError(f"--out {str(directory)!r} is not writable: choose a writable directory")
    return directory


def remove_partial_files() -> None:
    """Remove the temporary files of writes that never finished (a worker killed while writing,
    a signal between two steps) from the folders written into and their subfolders."""
    for leftover in [p for f in _written for p in (*f.glob(f"*{PARTIAL}*"), *f.glob(f"*/*{PARTIAL}*"))]:
        leftover.unlink(missing_ok=True)


def remove_empty_folders() -> None:
    """Remove the folders :func:`writable_directory` created that are still empty, deepest first."""
    while _created:
        with contextlib.suppress(OSError):
            _created.pop().rmdir()


@contextlib.contextmanager
def all_or_none() -> Iterator[None]:
    """Outputs written inside the block take their places only when it ends without an error."""
    global _staged
    outer, _staged = _staged, []
    staged = _staged
    try:
        yield
    except BaseException:
        _discard(staged)
        raise
    finally:
        _staged = outer
    if outer is not None:
        outer.extend(staged)
    else:
        _place(staged)


def _discard(staged: list) -> None:
    for tmp, _, _ in staged:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)


def _place(staged: list) -> None:
    """Write through first (the writes that can fail), then rename every file into place;
    OutputError, nothing written, when two of them would land on one file."""
    try:
        targets = [str(target) for tmp, target, _ in staged if tmp is not None]
        for twice in {t for t in targets if targets.count(t) > 1}:
            raise OutputError(f"two outputs of the command are the same file {twice!r}: "
                              "nothing was written; give them different paths")
        for tmp, target, data in staged:
            if tmp is None:
                _write_through(target, data)
        for tmp, target, _ in staged:
            if tmp is not None:
                os.replace(tmp, target)
    except BaseException:
        _discard(staged)
        raise


def _write_through(target: Path | int, data: bytes) -> None:
    try:
        if isinstance(target, int):  # through sys.stdout: what is buffered there stays in order
            stream = sys.stdout if target == 1 else sys.stderr
            binary = getattr(stream, "buffer", None)
            stream.flush()
            if binary is not None:
                binary.write(data)
            else:
                stream.write(data.decode("utf-8"))
            stream.flush()
        else:
            with open(target, "wb") as handle:
                handle.write(data)
    except BrokenPipeError:  # the command says so (signorini.cli.app)
        raise
    except OSError as exc:
        where = {1: "standard output", 2: "standard error"}.get(target, repr(str(target)))
        raise OutputError(f"cannot write {where} ({exc.strerror}): free some space or "
                          "choose another path") from None


def atomic_write(path: str | os.PathLike, produce: Callable[[str], None], suffix: str = "") -> None:
    """``produce(name)`` writes a file; it then takes the place of ``path`` whole, or nothing does.

    OutputError (nothing left behind) when the file cannot be produced, e.g.
    on a full disk.
    """
    kind, target = _where(path)
    if kind == "folder":
        raise InputError(f"cannot write {str(path)!r}: it is a directory; give a file name")
    folder = target.parent if kind == "replace" else None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{Path(path).name}{PARTIAL}", suffix=suffix, dir=folder)
        _written.add(Path(tmp).parent)
    except OSError as exc:  # no such folder, or one that takes no files: the path is at fault
        raise InputError(f"cannot write {str(path)!r} ({exc.strerror}): choose a writable path") \
            from None
    os.close(fd)
    try:
        produce(tmp)
        if kind != "replace":  # a device, a FIFO or stdout: written through, never replaced
            data = Path(tmp).read_bytes()
            Path(tmp).unlink()
            tmp = None
        else:
            data = None
            mode = target.stat().st_mode & 0o7777 if target.exists() else 0o666 & ~_umask()
            os.chmod(tmp, mode)  # mkstemp's 0600 would hide results from other users
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise OutputError(f"cannot write {str(path)!r} ({exc.strerror}): nothing was left "
                          "behind; free some space or choose another path") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _place_or_stage([(tmp, target, data)])


def _place_or_stage(items: list) -> None:
    if _staged is not None:
        _staged.extend(items)
    else:
        _place(items)


def write_stdout(text: str) -> None:
    """``text`` on standard output (inside :func:`all_or_none`: once every output was produced)."""
    _place_or_stage([(None, 1, text.encode("utf-8"))])


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` so that readers see the old file or the new one, never half."""
    atomic_write(path, lambda name: Path(name).write_bytes(data))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def plain(value: Any) -> Any:
    """JSON-safe copy: arrays to lists, non-finite floats to null."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def to_json(data: Any) -> str:
    return json.dumps(plain(data), indent=2, allow_nan=False)


def save_figure(figure, path: str | os.PathLike, dpi: int = 130) -> None:
    """Save a matplotlib figure atomically as PNG."""
    import io as _io

    buffer = _io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    atomic_write_bytes(path, buffer.getvalue())
