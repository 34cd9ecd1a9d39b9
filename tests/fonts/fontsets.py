"""Font sets made for a test run: a fontconfig file that lists only some font folders.

Qt finds its fonts through fontconfig, and fontconfig reads ``FONTCONFIG_FILE`` when it is set:
a file that names a few folders (and the system's rules for generic names, less the ones that
add the user's own font folders) gives a process exactly those fonts, no root needed. Each
:class:`FontSet` names the Debian packages that bring its folders, so CI can install what is
missing (``.ci/run``) and a developer can see what to install.

``FONTSET_ROOT`` (default ``/``; several joined with ``:``) is where the folders are looked for,
each in the first root that has it: a tree made with ``dpkg -x`` of the packages
(``apt-get download``) tries a set without installing it.

``python -m tests.fonts.fontsets NAME DIR`` writes ``DIR/fonts.conf`` for the set and prints its
path; ``python -m tests.fonts.fontsets --packages`` prints every package the sets need.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import escape

__all__ = ["FONT_SETS", "FontSet", "describe_fonts", "write_config"]

SYSTEM_RULES = Path("/etc/fonts/conf.d")
# Rules that add font folders of their own (the user's ~/.fonts, a site's local.conf): left out,
# or the set would not be only its folders.
FOLDER_RULES = ("50-user.conf", "51-local.conf")


@dataclass(frozen=True)
class FontSet:
    name: str
    folders: tuple[str, ...]  # under FONTSET_ROOT
    packages: tuple[str, ...]  # Debian packages that bring the folders
    what: str

    def located(self, roots: list[Path]) -> list[Path] | None:
        """Each folder of the set in the first of ``roots`` where it holds fonts; None when one
        is nowhere."""
        found = []
        for folder in self.folders:
            where = next((root / folder for root in roots if _has_fonts(root / folder)), None)
            if where is None:
                return None
            found.append(where)
        return found


FONT_SETS: tuple[FontSet, ...] = (
    FontSet(
        "dejavu",
        ("usr/share/fonts/truetype/dejavu",),
        ("fonts-dejavu-core",),
        "DejaVu Sans / Sans Mono only (no CJK font: Chinese glyphs are boxes)",
    ),
    FontSet(
        "urw",
        ("usr/share/fonts/opentype/urw-base35", "usr/share/fonts/truetype/droid"),
        ("fonts-urw-base35", "fonts-droid-fallback"),
        "URW base35 (Nimbus Sans, Nimbus Mono PS) with Droid Sans Fallback for Chinese",
    ),
    FontSet(
        "noto",
        ("usr/share/fonts/truetype/noto", "usr/share/fonts/opentype/noto"),
        ("fonts-noto-core", "fonts-noto-mono", "fonts-noto-cjk"),
        "Noto Sans, Noto Sans Mono, Noto Sans CJK",
    ),
    FontSet(
        "dejavu-cjk",
        ("usr/share/fonts/truetype/dejavu", "usr/share/fonts/opentype/noto"),
        ("fonts-dejavu-core", "fonts-noto-cjk"),
        "DejaVu Sans / Sans Mono with Noto Sans CJK for Chinese (a Debian desktop with fonts-noto-cjk): "
        "the Chinese lines are taller than the Latin font's (18 px against 14 at 9 pt)",
    ),
)


def _has_fonts(folder: Path) -> bool:
    if not folder.is_dir():
        return False
    return any(p.suffix.lower() in {".ttf", ".otf", ".ttc", ".pfb"} for p in folder.rglob("*"))


def font_set(name: str) -> FontSet:
    for candidate in FONT_SETS:
        if candidate.name == name:
            return candidate
    raise SystemExit(f"no font set {name!r}: the sets are {', '.join(s.name for s in FONT_SETS)}")


def fontset_roots() -> list[Path]:
    return [Path(p) for p in os.environ.get("FONTSET_ROOT", "/").split(":") if p]


def write_config(folders: list[Path], directory: Path) -> Path:
    """``directory/fonts.conf`` listing only ``folders`` (with a cache of its own)."""
    directory.mkdir(parents=True, exist_ok=True)
    lines = [
        '<?xml version="1.0"?>',
        '<!DOCTYPE fontconfig SYSTEM "urn:fontconfig:fonts.dtd">',
        "<fontconfig>",
    ]
    lines += [f"  <dir>{escape(str(folder))}</dir>" for folder in folders]
    lines.append(f"  <cachedir>{escape(str(directory / 'cache'))}</cachedir>")
    if SYSTEM_RULES.is_dir():
        for rule in sorted(SYSTEM_RULES.iterdir()):
            if rule.name.endswith(".conf") and rule.name not in FOLDER_RULES:
                lines.append(f'  <include ignore_missing="yes">{escape(str(rule))}</include>')
    lines.append("</fontconfig>")
    path = directory / "fonts.conf"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def describe_fonts(env: dict[str, str] | None = None) -> str:
    """What fontconfig gives for the generic names and for Chinese, e.g. for a test report header."""
    fc_match = shutil.which("fc-match")
    if fc_match is None:
        return "fc-match not found (fontconfig's tools are not installed)"
    found = []
    for pattern in ("sans-serif", "monospace", "sans-serif:lang=zh-cn"):
        result = subprocess.run(
            [fc_match, "-f", "%{family[0]}", pattern],
            capture_output=True,
            text=True,
            env=env,
            check=False,
            timeout=60,
        )
        found.append(f"{pattern} → {result.stdout.strip() or '?'}")
    return ", ".join(found)


def main(argv: list[str]) -> int:
    if argv == ["--packages"]:
        print(" ".join(dict.fromkeys(p for s in FONT_SETS for p in s.packages)))  # each once
        return 0
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    fonts = font_set(argv[0])
    folders = fonts.located(fontset_roots())
    if folders is None:
        print(f"font set {fonts.name}: missing; install {' '.join(fonts.packages)}", file=sys.stderr)
        return 1
    print(write_config(folders, Path(argv[1])))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
