"""``nylonflex completion``: shell completion made by shtab from the console script's own
parser (issue 50)."""

import shutil
import subprocess

import pytest

from nylonflex.cli import COMMANDS, main


def _script(shell, capsys):
    assert main(["completion", shell]) == 0
    return capsys.readouterr().out


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash here")
def test_bash_completes_commands_and_flags(tmp_path, capsys):
    path = tmp_path / "nylonflex.bash"
    path.write_text(_script("bash", capsys))
    assert subprocess.run(["bash", "-n", str(path)]).returncode == 0

    def complete(*words):
        line = " ".join(words)
        probe = (f"source {path}; COMP_WORDS=({line}); COMP_CWORD={len(words) - 1}; "
                 f"COMP_LINE='{line}'; COMP_POINT={len(line)}; _shtab_nylonflex; "
                 "printf '%s\\n' \"${COMPREPLY[@]}\"")
        out = subprocess.run(["bash", "-c", probe], capture_output=True, text=True)
        return set(out.stdout.split())

    assert complete("nylonflex", "sw") == {"sweep"}
    assert set(COMMANDS) <= complete("nylonflex", "''")
    assert "--resume" in complete("nylonflex", "sweep", "--re")
    assert complete("nylonflex", "completion", "z") == {"zsh"}


def test_zsh_and_tcsh_scripts_name_every_command(capsys):
    for shell in ("zsh", "tcsh"):
        text = _script(shell, capsys)
        assert all(name in text for name in COMMANDS), shell


def test_an_unknown_shell_is_refused_in_one_line(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["completion", "fish"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "invalid choice: 'fish'" in err[0]
