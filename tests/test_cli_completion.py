"""Shell completion (``barymesh --print-completion SHELL``, shtab): the bash script is
sourced in a real bash and asked to complete, as the shell does on Tab."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from barymesh.app.cli import main
from barymesh.cell import cell_preset_names
from barymesh.presets import preset_names


def completion_script(capsys, shell: str) -> str:
    assert main(["--print-completion", shell]) == 0
    return capsys.readouterr().out


@pytest.fixture
def complete(capsys, tmp_path):
    """``complete(*words)``: what bash offers for the last word, in ``tmp_path``."""
    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is not installed")
    script = tmp_path / "barymesh.bash"
    script.write_text(completion_script(capsys, "bash"))

    def run(*words: str) -> list[str]:
        quoted = " ".join(f"'{w}'" for w in words)
        code = (
            f"source '{script}'\n"
            f"COMP_WORDS=({quoted}); COMP_CWORD={len(words) - 1}\n"
            'COMP_LINE="${COMP_WORDS[*]}"; COMP_POINT=${#COMP_LINE}; COMPREPLY=()\n'
            "_shtab_barymesh\n"
            "printf '%s\\n' \"${COMPREPLY[@]}\"\n"
        )
        out = subprocess.run(
            [bash, "--norc", "-c", code],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=60,
            check=True,
        )
        return sorted(line for line in out.stdout.splitlines() if line)

    return run


def test_bash_completes_subcommands_and_options(complete):
    assert complete("barymesh", "s") == ["solve", "study", "sweep"]
    assert complete("barymesh", "mesh", "--msh") == ["--msh-version"]
    assert complete("barymesh", "mesh", "-o", "x.msh", "--msh-version", "") == ["2.2", "4.1"]


def test_bash_completes_preset_names(complete):
    assert complete("barymesh", "mesh", "--preset", "paper-fig12") == [
        f"paper-fig12{x}" for x in "abcd"
    ]
    assert complete("barymesh", "solve", "--cell-preset", "") == sorted(cell_preset_names())
    assert len(preset_names()) > 10


def test_bash_completes_the_library_command(complete, tmp_path):
    assert complete("barymesh", "l") == ["library"]
    assert complete("barymesh", "library", "--cell-preset", "") == sorted(cell_preset_names())
    (tmp_path / "patch.cell.json").write_text("")
    assert complete("barymesh", "library", "--cell", "pa") == ["patch.cell.json"]
    assert complete("barymesh", "library", "--parameter", "pa") == []  # a path, not a file


def test_bash_completes_file_names(complete, tmp_path):
    (tmp_path / "ring.msh").write_text("")
    (tmp_path / "ring.cell.json").write_text("")
    assert complete("barymesh", "info", "ring.m") == ["ring.msh"]
    assert complete("barymesh", "mesh", "--cell", "ring.c") == ["ring.cell.json"]


def test_zsh_script_and_bad_shell(capsys):
    zsh = completion_script(capsys, "zsh")
    assert zsh.startswith("#compdef barymesh")
    assert "_barymesh_presets" in zsh and "--msh-version" in zsh
    assert main(["--print-completion", "cmd.exe"]) == 2
    assert "invalid choice: 'cmd.exe'" in capsys.readouterr().err


def test_the_option_accepts_the_shells_shtab_writes_for():
    # named in barymesh.app.cli_completion so that shtab is imported only for a script
    import shtab

    from barymesh.app.cli_completion import COMPLETION_SHELLS

    assert list(COMPLETION_SHELLS) == list(shtab.SUPPORTED_SHELLS)
