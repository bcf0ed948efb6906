"""Your own method: loaded from ``module:function`` or ``file.py:function``, or given as a callable.

A user method has the registry's signature,
``function(problem, *, tol, max_iter, **options) -> ContactSolution | (u, lam)``.
A method file's own folder is put first on ``sys.path`` (as Python does for a script), so a
method file imports the modules beside it without ``PYTHONPATH``. When the method raises,
:func:`raised` says where: the exception and the ``file:line`` of the innermost frame in the
user's own code (a sibling module's line when the error is there), and the traceback from the
method's call down.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
import sysconfig
import traceback
from pathlib import Path
from types import TracebackType
from typing import Any, Callable, Mapping

from signorini.errors import InputError
from signorini.solvers.base import Method

#: the forms a user method is named in, for every message about one
FORMS = "--method module:function or --method path/to/file.py:function"
#: the package's folder, and where the Python installation lives: frames there are not the user's
_PACKAGE = str(Path(__file__).resolve().parents[1])
_INSTALLED = tuple(str(Path(sysconfig.get_paths()[k]).resolve())
                   for k in ("stdlib", "platstdlib", "purelib", "platlib"))


def load(spec: str) -> Method:
    """The method named ``module:function`` or ``path/to/file.py:function``.

    A module is looked up on ``sys.path`` and then in the current directory;
    a file's folder is put first on ``sys.path`` before it is imported.
    InputError names ``--method`` and the fix for every way this can fail.
    """
    module_name, attr = _parts(spec)
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise ImportError(f"no file {module_name}")
            folder = str(path.resolve().parent)  # its sibling modules import, as for a script
            if folder not in sys.path:
                sys.path.insert(0, folder)
            loader_spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(loader_spec)
            loader_spec.loader.exec_module(module)
        else:
            if os.getcwd() not in sys.path:
                sys.path.append(os.getcwd())
            module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"--method {spec!r}: cannot import {module_name!r} ({exc}); give "
                         f"{FORMS}") from exc
    except SyntaxError as exc:
        raise InputError(f"--method {spec!r}: {exc.filename or module_name}, line {exc.lineno}: "
                         f"syntax error ({exc.msg}): fix the file") from None
    except (Exception, SystemExit) as exc:  # the user's module failed while it was imported
        what = f"sys.exit({exc.code!r})" if isinstance(exc, SystemExit) else \
            f"{type(exc).__name__}: {exc}{where(exc.__traceback__)}"
        raise InputError(f"--method {spec!r}: importing {module_name!r} failed ({what}): "
                         "fix the module so that it imports") from None
    func = getattr(module, attr, None)
    if not callable(func):
        raise InputError(f"--method {spec!r}: module {module_name!r} has no function {attr!r}")
    return _method(spec, func)


def _parts(spec: str) -> tuple[str, str]:
    """``(module or file, function)`` of ``spec``; InputError when either is missing."""
    module_name, _, attr = spec.rpartition(":")
    if not module_name.strip() or not attr.strip():
        missing = "module or file" if not module_name.strip() else "function"
        raise InputError(f"--method {spec!r} names no {missing}: give {FORMS}")
    return module_name, attr


def deferred(spec: str) -> Method:
    """The method named ``spec`` (as :func:`load` takes it), imported when first called and not
    now: a command that runs it in a worker process imports it there alone, so that what its
    module does on import (exits, prints, hangs, fails) costs that run and not the command."""
    module_name, _ = _parts(spec)
    if module_name.endswith(".py") and not Path(module_name).is_file():
        raise InputError(f"--method {spec!r}: cannot import {module_name!r} (no file "
                         f"{module_name}); give {FORMS}")

    loaded: list[Method] = []  # imported once, at the first call, in the process that runs it

    def imported(problem: Any, **options: Any) -> Any:
        if not loaded:
            loaded.append(load(spec))
        return loaded[0].function(problem, **options)

    return _method(spec, imported)


def of_callable(function: Callable[..., Any], taken: Mapping[str, Method]) -> Method:
    """A callable as a method, named by its ``__name__`` (``module:qualname`` when a different
    method already has that name in ``taken``, the registry)."""
    name = getattr(function, "__name__", type(function).__name__)
    if name in taken and taken[name].function is not function:
        name = f"{getattr(function, '__module__', '')}:{getattr(function, '__qualname__', name)}"
    return _method(name, function)


def _method(name: str, function: Callable[..., Any]) -> Method:
    return Method(name=name, function=function, family="user",
                  summary=(getattr(function, "__doc__", None) or "").strip().split("\n")[0])


def _under(filename: str, roots: tuple[str, ...]) -> bool:
    path = str(Path(filename).resolve())
    return any(path == root or path.startswith(root + os.sep) for root in roots)


def where(tb: TracebackType | None) -> str:
    """`` at file:line`` of the innermost frame of ``tb`` in the user's code, else in the
    package's own (a built-in method's line, not a library's), else ""."""
    frames = [f for f in traceback.extract_tb(tb) if not f.filename.startswith("<")]
    yours = [f for f in frames if not _under(f.filename, (_PACKAGE, *_INSTALLED))]
    ours = [f for f in frames if _under(f.filename, (_PACKAGE,))]
    frame = (yours or ours or [None])[-1]
    return "" if frame is None else f" at {frame.filename}:{frame.lineno}"


def raised(exc: BaseException) -> tuple[str, str]:
    """``(one line, traceback)`` of an exception a method raised: the line says what and where
    (:func:`where`), the traceback runs from the method's own call (the caller's frame left out)."""
    tb = exc.__traceback__.tb_next if exc.__traceback__ is not None else None
    line = f"{type(exc).__name__}: {exc}".splitlines()[0] + where(tb)
    return line, "".join(traceback.format_exception(type(exc), exc, tb)).rstrip()


__all__ = ["FORMS", "deferred", "load", "of_callable", "raised", "where"]
