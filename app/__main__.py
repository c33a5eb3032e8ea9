"""``python -m app``: the desktop window, same options as ``barymesh`` without a verb."""

import sys

from app.window import main

sys.exit(main())
