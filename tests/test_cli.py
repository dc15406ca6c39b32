"""The ``sumo-ayss`` entry point: its commands are the real modules and name themselves."""

from __future__ import annotations

import importlib

import pytest

from sumo_ayss import cli


def test_every_command_is_a_module_with_main() -> None:
    assert {
        "train",
        "evaluate",
        "report",
        "pipeline",
        "rank",
        "discriminability",
        "replay",
        "networks",
    } == set(cli.COMMANDS)
    for module, _ in cli.COMMANDS.values():
        assert callable(importlib.import_module(module).main)


@pytest.mark.parametrize("command", sorted(cli.COMMANDS))
def test_help_names_the_cli_command(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        cli.main([command, "--help"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: sumo-ayss {command} ")


def test_module_help_names_the_module(capsys: pytest.CaptureFixture[str]) -> None:
    from sumo_ayss import train

    with pytest.raises(SystemExit):
        train.parse_args(["--help"])
    assert capsys.readouterr().out.startswith("usage: python -m sumo_ayss.train ")


def test_unknown_command_lists_the_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        cli.main(["evaluation"])
    assert "unknown command 'evaluation'" in str(exc.value.code)
    assert "replay" in str(exc.value.code)
