"""Every tr() string ships in Simplified Chinese, and the shipped .qm is the compiled .ts."""

from __future__ import annotations

import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TS = ROOT / "resources" / "translations" / "teachpad_zh_CN.ts"
TOOL_TIMEOUT = 90.0  # s for lupdate over every source file (a loaded machine), or lrelease
QM = ROOT / "ui" / "i18n" / "teachpad_zh_CN.qm"
BIN = Path(sys.executable).parent


def _tool(name: str) -> str:
    path = BIN / name
    found = str(path) if path.exists() else shutil.which(name)
    if not found:
        pytest.fail(f"{name} is missing: PySide6-Essentials ships it")
    return found


def _messages(ts: Path) -> dict[tuple[str, str], str]:
    out: dict[tuple[str, str], str] = {}
    for context in ET.parse(ts).getroot().iter("context"):
        name = context.findtext("name") or ""
        for message in context.iter("message"):
            translation = message.find("translation")
            assert translation is not None
            if translation.get("type") in ("obsolete", "vanished"):
                continue
            forms = translation.findall("numerusform")
            text = forms[0].text if forms else translation.text
            if translation.get("type") == "unfinished":
                text = ""
            out[(name, message.findtext("source") or "")] = text or ""
    return out


def test_every_source_string_has_a_chinese_translation(tmp_path: Path) -> None:
    fresh = tmp_path / "fresh.ts"
    sources = sorted(str(p) for p in (ROOT / "app").rglob("*.py")) + sorted(
        str(p) for p in (ROOT / "ui").rglob("*.py")
    )
    subprocess.run(
        [_tool("pyside6-lupdate"), *sources, "-ts", str(fresh)],
        check=True,
        capture_output=True,
        timeout=TOOL_TIMEOUT,
    )
    wanted = set(_messages(fresh))
    shipped = _messages(TS)
    missing = sorted(key for key in wanted if not shipped.get(key))
    assert missing == [], f"run `make translations`: {len(missing)} untranslated, e.g. {missing[:5]}"


def test_the_shipped_qm_is_the_compiled_ts(tmp_path: Path) -> None:
    out = tmp_path / "check.qm"
    subprocess.run(
        [_tool("pyside6-lrelease"), str(TS), "-qm", str(out)],
        check=True,
        capture_output=True,
        timeout=TOOL_TIMEOUT,
    )
    assert out.read_bytes() == QM.read_bytes(), "run `make translations` to rebuild the .qm"


def test_the_qm_translates_protocol_words(qapp: object) -> None:
    from PySide6.QtCore import QTranslator

    translator = QTranslator()
    assert translator.load(str(QM))
    assert translator.translate("Protocol", "emergency stop") == "急停"
