"""Fill the Qt Linguist file from the tab-separated translation lists, report what is missing.

Usage (the Makefile's ``translations`` target runs it after ``pyside6-lupdate``)::

    python resources/translations/merge.py resources/translations/teachpad_zh_CN.ts \
        resources/translations/*_zh_CN.txt

Each ``.txt`` line is ``context<TAB>source<TAB>translation``; ``\\n`` inside a field is a newline.
A message already translated in the ``.ts`` keeps its translation. A source text whose context
the lists do not name takes the translation of the same text in another context when there is
exactly one. Exit status 1 when a message is left untranslated.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

HEADER = '<?xml version="1.0" encoding="utf-8"?>\n<!DOCTYPE TS>\n'


def _unescape(field: str) -> str:
    return field.replace("\\n", "\n").replace("\\t", "\t")


def load_lists(paths: list[Path]) -> tuple[dict[tuple[str, str], str], dict[str, set[str]]]:
    exact: dict[tuple[str, str], str] = {}
    by_source: dict[str, set[str]] = defaultdict(set)
    for path in paths:
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if not line.strip() or line.startswith("#"):
                continue
            parts = line.split("\t")
            if len(parts) != 3:
                raise SystemExit(f"{path}:{number}: expected context<TAB>source<TAB>translation")
            context, source, translation = (_unescape(p) for p in parts)
            exact[(context, source)] = translation
            by_source[source].add(translation)
    return exact, by_source


def merge(ts_path: Path, lists: list[Path]) -> list[tuple[str, str]]:
    exact, by_source = load_lists(lists)
    tree = ET.parse(ts_path)
    missing: list[tuple[str, str]] = []
    for context in tree.getroot().iter("context"):
        name = context.findtext("name") or ""
        for message in context.iter("message"):
            source = message.findtext("source") or ""
            translation = message.find("translation")
            if translation is None:
                translation = ET.SubElement(message, "translation")
            if translation.get("type") in ("obsolete", "vanished"):
                continue
            forms = translation.findall("numerusform")
            current = forms[0].text if forms else translation.text
            if current and translation.get("type") != "unfinished":
                continue
            text = exact.get((name, source))
            if text is None and len(by_source.get(source, ())) == 1:
                text = next(iter(by_source[source]))
            if text is None and current:
                text = current  # keep a draft someone typed into the .ts
            if text is None:
                missing.append((name, source))
                continue
            if message.get("numerus") == "yes":
                for form in forms:
                    translation.remove(form)
                ET.SubElement(translation, "numerusform").text = text
                translation.text = None
            else:
                translation.text = text
            translation.attrib.pop("type", None)
    ET.indent(tree, space="    ")
    body = ET.tostring(tree.getroot(), encoding="unicode")
    ts_path.write_text(HEADER + body + "\n", encoding="utf-8")
    return missing


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__)
        return 2
    missing = merge(Path(argv[0]), [Path(p) for p in argv[1:]])
    for context, source in missing:
        print(f"untranslated: [{context}] {source!r}", file=sys.stderr)
    print(f"{len(missing)} message(s) untranslated", file=sys.stderr)
    return 1 if missing else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
