"""``python -m signorini.cli``: the ``signorini`` command."""

import sys

from signorini.cli.app import main

sys.exit(main())
