"""The ``barymesh`` command's entry point: the command line, imported under a Ctrl-C guard.

Importing :mod:`barymesh.app.cli` loads numpy, scipy and the core (seconds on a busy
machine). Ctrl-C pressed meanwhile used to print a KeyboardInterrupt traceback and kill the
process by SIGINT; here it is one line and exit code 130, as it is once the command runs.
This module and ``barymesh/__init__`` import nothing heavy themselves.
"""

from __future__ import annotations

import sys

#: Exit code of a command stopped by Ctrl-C (128 + SIGINT), as the shell reports it.
INTERRUPTED = 130


def main(argv: list[str] | None = None) -> int:
    """Run ``barymesh`` (:func:`barymesh.app.cli.main`); 130 when interrupted while starting."""
    try:
        from barymesh.app.cli import main as run
    except KeyboardInterrupt:
        sys.stderr.write("barymesh: interrupted\n")
        return INTERRUPTED
    return run(argv)


if __name__ == "__main__":
    sys.exit(main())
