"""``python -m barymesh``: the ``barymesh`` command (verbs, or the window without one)."""

import sys

from barymesh.app.launch import main

sys.exit(main())
