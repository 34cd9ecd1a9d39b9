"""The CLI's help is a screen too: every option has help, every command an example.

:data:`EXAMPLES` gives each command (by its path, e.g. ``"point create"``) one example line,
added to its help's epilog by :func:`add_examples`. :func:`help_defects` lists what a command
line tool must not ship without: an option without help, a command without an example (the
tests walk the whole parser with it).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from typing import Any

__all__ = ["EXAMPLES", "add_examples", "help_defects", "walk"]

EXAMPLES: dict[str, str] = {
    "status": "teachpad-cli --host 192.168.1.10 status --json",
    "watch": "teachpad-cli watch --rate 10 --count 50",
    "mode": "teachpad-cli mode auto",
    "step": "teachpad-cli step --frame base X=10 Z=-5 --speed 20",
    "jog": "teachpad-cli jog --axis Z --dir + --ratio 10 --seconds 1.5",
    "point create": "teachpad-cli point create 12 --xyzabc 400 0 300 180 0 0 --tool 1",
    "move": "teachpad-cli move 12 --via 11 --speed 80 --project cell.teachpad.json",
    "zero": "teachpad-cli zero J3",
    "program run": "teachpad-cli program run 1 --mode cycle --cycles 3 --speed 50",
    "stop": "teachpad-cli stop",
    "pause": "teachpad-cli pause",
    "resume": "teachpad-cli resume",
    "read": "teachpad-cli read 291 2",
    "write": "teachpad-cli write 200 400 0 300",
    "points list": "teachpad-cli points list cell.teachpad.json",
    "points upload": "teachpad-cli --host 192.168.1.10 points upload cell.teachpad.json --ids 1,2,5-9",
    "points export": "teachpad-cli points export cell.teachpad.json --csv points.csv",
    "points import": "teachpad-cli points import cell.teachpad.json --csv points.csv --merge",
    "points diff": "teachpad-cli points diff cell.teachpad.json points.csv --tol-mm 0.1 --tol-deg 0.1",
    "run": "teachpad-cli --host 192.168.1.10 run cell.teachpad.json --plan weld --from 3 --max-speed 250",
    "selftest": "teachpad-cli --host 192.168.1.10 --register-profile cell.registers.json selftest",
    "support-bundle": "teachpad-cli support-bundle support.zip --project cell.teachpad.json --days 3",
    "audit": "teachpad-cli audit --from 2026-05-01 --to 2026-05-02T18:00 --result refused",
    "roles show": "teachpad-cli roles show",
    "roles set-password": "teachpad-cli roles set-password engineer",
    "roles clear-password": "teachpad-cli roles clear-password engineer",
}


def walk(parser: argparse.ArgumentParser, path: str = "") -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """Every (command path, parser) under ``parser``, itself first (path "")."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from walk(sub, f"{path} {name}".strip())


def _subcommands(parser: argparse.ArgumentParser) -> Any:
    """The parser's subcommands action, or None."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action
    return None


def add_examples(parser: argparse.ArgumentParser) -> None:
    """Append each command's example from :data:`EXAMPLES` to its epilog."""
    for path, sub in walk(parser):
        example = EXAMPLES.get(path)
        if example and "example:" not in (sub.epilog or ""):
            sub.epilog = f"{sub.epilog}\n\n" if sub.epilog else ""
            sub.epilog += f"example: {example}"
            sub.formatter_class = argparse.RawDescriptionHelpFormatter


def help_defects(parser: argparse.ArgumentParser) -> list[str]:
    """What the help lacks: options without help, commands without help or an example."""
    defects: list[str] = []
    for path, sub in walk(parser):
        where = path or "teachpad-cli"
        subcommands = _subcommands(sub)
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction) or action is subcommands:
                continue
            if action.help == argparse.SUPPRESS:
                continue  # hidden on purpose (an old spelling kept for scripts)
            if not action.help:
                name = "/".join(action.option_strings) or action.metavar or action.dest
                defects.append(f"{where}: {name} has no help")
        if subcommands is not None:
            for choice in subcommands._choices_actions:
                if not choice.help:
                    defects.append(f"{where} {choice.dest}: no help line")
        elif path and "example:" not in (sub.epilog or "").lower() + (sub.description or "").lower():
            defects.append(f"{where}: no example")
    return defects
