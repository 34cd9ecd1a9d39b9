"""The docs against the tree: the README's code map and docs/DESIGN.md name what exists, and the
code map names every folder of the code (issue 22: both redrawn after the change, kept true)."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DESIGN = ROOT / "docs" / "DESIGN.md"
CODE_ROOTS = ("app", "ui", "tests", "benchmarks", "tools", "packaging", "resources", "docs")
# a path in the docs: a root folder, then folders, then a file (or a folder: trailing /); one with
# a pattern's `*` or a placeholder's `<area>` in it is a pattern, not a path
_ROOTS = "|".join(CODE_ROOTS)
_PATH = re.compile(r"(?<![\w./-])((?:" + _ROOTS + r")/[\w./*<>-]*[\w/*>])")


def code_map() -> str:
    """The fenced block under the README's "## Code map"."""
    text = README.read_text(encoding="utf-8")
    section = text.split("\n## Code map\n", 1)[1].split("\n## ", 1)[0]
    return section.split("```", 2)[1]


CONTINUATION = 20  # a code map line indented this far is the description of the line above


def _map_paths(block: str) -> set[str]:
    """Every path the code map's names column holds. The tree is indented two spaces a level; a
    line's names come before its first two spaces, each under the last folder above it (or at the
    top); a line indented :data:`CONTINUATION` or more only goes on with a description."""
    names: set[str] = set()
    folders: list[tuple[int, str]] = []  # (indent, path)
    for line in block.splitlines():
        indent = len(line) - len(line.lstrip(" "))
        if not line.strip() or indent >= CONTINUATION:
            continue
        while folders and folders[-1][0] >= indent:
            folders.pop()
        parent = folders[-1][1] if folders else ""
        for token in line[indent:].split("  ", 1)[0].split():
            if re.fullmatch(r"[\w.-]+(/[\w.-]+)*/?", token) and ("." in token or "/" in token):
                names.add(parent + token)
                if token.endswith("/"):
                    folders.append((indent, parent + token))
    return names


def test_the_code_map_names_every_folder_and_every_module_of_the_cores_top() -> None:
    block = code_map()
    named = _map_paths(block)
    tracked = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    top = {p.split("/", 1)[0] + "/" for p in tracked if "/" in p}
    missing = sorted(folder for folder in top if not any(name.startswith(folder) for name in named))
    for package in ("app", "ui"):
        for sub in sorted((ROOT / package).iterdir()):
            if (sub / "__init__.py").is_file() and f"{package}/{sub.name}/" not in named:
                missing.append(f"{package}/{sub.name}/")
    missing += [
        f"app/{module.name}"
        for module in sorted((ROOT / "app").glob("*.py"))
        if module.name != "__init__.py" and module.name not in block
    ]
    assert missing == [], f"not in the README's code map: {missing}"


def test_every_path_the_code_map_and_design_name_exists() -> None:
    """A path the docs name that the tree does not have is a line gone stale."""
    stale: list[str] = []
    for path in sorted(_map_paths(code_map())):
        if not (ROOT / path).exists():
            stale.append(f"README code map: {path}")
    for path in sorted(set(_PATH.findall(DESIGN.read_text(encoding="utf-8")))):
        if not set("<*") & set(path) and not (ROOT / path.rstrip("/")).exists():
            stale.append(f"docs/DESIGN.md: {path}")
    assert stale == []


def test_design_says_where_a_jog_press_is_spelled() -> None:
    """DESIGN.md's figure for an operation's places (issue 22: 6 before, 3 after) is the code's:
    the files of app/ and ui/ that name the jog press."""
    spelled = sorted(
        path.relative_to(ROOT).as_posix()
        for package in ("app", "ui")
        for path in (ROOT / package).rglob("*.py")
        if re.search(r"jog_press|JogPress|JOG_PRESS", path.read_text(encoding="utf-8"))
    )
    assert spelled == ["app/link/commands.py", "app/link/ops.py", "ui/controllers/motion.py"]
    design = " ".join(DESIGN.read_text(encoding="utf-8").split())
    assert "the jog press is spelled in 3 files of `app/` and `ui/` instead of 6" in design
    assert "**Adding an operation touches three places**" in design
