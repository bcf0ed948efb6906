"""The package's exceptions.

Every error a user can cause by bad input is an :class:`InputError`: its message
names the parameter and says how to fix it. The CLI turns it into a one-line
message and exit code 2.
"""


class SignoriniError(Exception):
    """Base class of every error raised by signorini."""


class InputError(SignoriniError, ValueError):
    """Bad input: a parameter, option, scene or method name the package cannot use."""


class BackendNotInstalled(InputError):
    """A method whose backend package is not installed."""


class SolverError(SignoriniError):
    """A backend failed in a way that is not the user's input (re-raised ``from`` it)."""


class OutputError(SignoriniError):
    """An output that could not be written (a full disk, say): nothing was left half-written."""


#: the documentation site (mkdocs.yml's site_url): what a message or a help text points to, since
#: an installed wheel holds no docs/ folder
DOCS_SITE = "https://signorini.readthedocs.io/en/latest/"


def docs_page(page: str, section: str = "") -> str:
    """The address of the documentation page ``page`` (docs/``page``.md), at ``section``'s anchor."""
    return f"{DOCS_SITE}{page}/" + (f"#{section}" if section else "")


#: the pip distribution of a module whose import name differs from it
DISTRIBUTIONS = {"sksparse": "scikit-sparse", "cvxpy": "cvxpy-base"}


def install_hint(extra: str, modules: tuple[str, ...] | list[str] = ()) -> str:
    """The pip command that installs what is missing: the package's ``extra`` when it has one
    (each extra lists its distributions in pyproject.toml), otherwise the ``modules``' own
    distributions (``pip install qpsolvers osqp``)."""
    if extra:
        return f"pip install 'signorini[{extra}]'"
    return "pip install " + " ".join(DISTRIBUTIONS.get(m, m) for m in modules)


__all__ = ["SignoriniError", "InputError", "BackendNotInstalled", "SolverError", "OutputError",
           "docs_page", "install_hint", "DOCS_SITE", "DISTRIBUTIONS"]
