"""``python -m barymesh``: the ``barymesh`` command (verbs, or the window without one)."""

import sys

from barymesh.app.cli import main

sys.exit(main())
