"""``python -m signorini.cli``: the ``signorini`` command."""

from signorini.cli.app import run

run()
