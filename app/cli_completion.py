"""Shell completion of ``barymesh`` (bash, zsh, tcsh, fish), made by shtab from the parser.

::

    barymesh --print-completion bash > ~/.local/share/bash-completion/completions/barymesh
    barymesh --print-completion zsh > ~/.zfunc/_barymesh     # a folder on $fpath

The script is generated from :func:`barymesh.app.cli.build_parser`, so it knows every
subcommand and option of this version. Options that name files complete file names
(``-o``, ``--params``, ``--cell``, ``--mesh``, ``info FILE``, ``study SPEC.json``), and
``--preset`` and ``--cell-preset`` complete the names of the shipped presets.
"""

from __future__ import annotations

import argparse
from typing import Any

#: Metavars of the arguments that name a file (completed with the shell's file names).
FILE_METAVARS = frozenset(
    {"FILE", "FILE.json", "FILE.cell.json", "OUT", "PNG", "PATH", "PATH|-", "SPEC.json"}
)
#: The shells shtab writes for.
SHELLS = ("bash", "zsh", "tcsh", "fish")
#: What ``--print-completion`` accepts: ``shtab.SUPPORTED_SHELLS``, named here so that shtab
#: is imported only when a script is asked for (tests/test_cli_completion.py compares them).
COMPLETION_SHELLS = (*SHELLS, "powershell")


def _walk(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """Every action of ``parser`` and of its subcommands' parsers."""
    actions = []
    for action in parser._actions:
        actions.append(action)
        if isinstance(action, argparse._SubParsersAction):
            for sub in dict.fromkeys(action.choices.values()):  # aliases share a parser
                actions += _walk(sub)
    return actions


def _preamble(presets: list[str], cells: list[str]) -> dict[str, str]:
    """Shell functions listing the preset names (bash, zsh), named in ``complete``."""
    return {
        "bash": (
            f'_barymesh_presets() {{ compgen -W "{" ".join(presets)}" -- "$1"; }}\n'
            f'_barymesh_cell_presets() {{ compgen -W "{" ".join(cells)}" -- "$1"; }}\n'
        ),
        "zsh": (
            f"_barymesh_presets() {{ compadd -- {' '.join(presets)} }}\n"
            f"_barymesh_cell_presets() {{ compadd -- {' '.join(cells)} }}\n"
        ),
    }


def add_completion(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Add ``--print-completion SHELL`` to ``parser``; returns ``parser``.

    shtab and the preset names are looked up only when the option is given
    (:func:`completion_script`): ``barymesh --help`` and every command start without them.
    """
    parser.add_argument(
        "--print-completion",
        choices=COMPLETION_SHELLS,
        default=None,
        action=_PrintCompletion,
        help=f"print the shell completion script for {', '.join(SHELLS)} and exit",
    )
    return parser


class _PrintCompletion(argparse.Action):
    """``--print-completion SHELL``: print the script of the parser that has it and exit."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        print(completion_script(parser, str(values)))
        parser.exit(0)


def completion_script(parser: argparse.ArgumentParser, shell: str) -> str:
    """shtab's completion script of ``parser`` for ``shell``, file and preset arguments marked."""
    import shtab

    from barymesh.cell import cell_preset_names
    from barymesh.presets import preset_names

    presets = {"bash": "_barymesh_presets", "zsh": "_barymesh_presets"}
    cells = {"bash": "_barymesh_cell_presets", "zsh": "_barymesh_cell_presets"}
    for action in _walk(parser):
        if "--preset" in action.option_strings:
            action.complete = presets  # type: ignore[attr-defined]
        elif "--cell-preset" in action.option_strings:
            action.complete = cells  # type: ignore[attr-defined]
        elif action.metavar in FILE_METAVARS:
            action.complete = shtab.FILE  # type: ignore[attr-defined]
        elif isinstance(action, _PrintCompletion):
            # as shtab's own action: nothing is completed after it
            action.__class__ = type(
                "_PrintCompletionMarked", (_PrintCompletion, shtab._ShtabPrintCompletionAction), {}
            )
    preamble = _preamble(preset_names(), cell_preset_names())  # per shell, as shtab takes it
    return shtab.complete(parser, shell, preamble=preamble)  # type: ignore[arg-type]
