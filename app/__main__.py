"""``python -m barymesh.app``: the desktop window, same options as ``barymesh`` without a verb."""

import sys

from barymesh.app.window_main import main

sys.exit(main())
