"""简体中文 everywhere (issue 21): Qt's own dialogs, the keep-out zone headers, sentences built from
parts (full-width separators, no ", " or ": " inside Chinese) and one word for the unit id."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from PySide6.QtWidgets import QFileDialog, QLabel

from app.protocol.enums import Alarm
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.controllers.safety import SafetyController
from ui.dialogs.envelope_dialog import EnvelopeDialog
from ui.joins import join_clauses, join_names, join_sentences, labelled

TS = Path(__file__).resolve().parents[2] / "resources" / "translations" / "teachpad_zh_CN.ts"
ENGLISH_WORD = re.compile(r"[A-Za-z]{3,}")


def test_qts_file_dialog_reads_in_chinese(qtbot: Any, translator: Any) -> None:
    assert translator.set_language("zh_CN")
    dialog = QFileDialog(None, "x", "", "CSV (*.csv)")
    dialog.setOption(QFileDialog.Option.DontUseNativeDialog)
    qtbot.addWidget(dialog)
    texts = [label.text() for label in dialog.findChildren(QLabel) if label.text()]
    assert any("查找范围" in t for t in texts) and any("文件类型" in t for t in texts), texts
    assert [t for t in texts if ENGLISH_WORD.search(t)] == []


def test_the_keep_out_zone_headers_read_in_chinese(qtbot: Any, translator: Any) -> None:
    assert translator.set_language("zh_CN")
    safety = SafetyController(None, scrypt_n=2**4)
    safety.set_idle_polling(False)
    dialog = EnvelopeDialog(safety)
    qtbot.addWidget(dialog)
    items = [dialog.keep_out.horizontalHeaderItem(c) for c in range(dialog.keep_out.columnCount())]
    headers = [item.text() if item is not None else "" for item in items]
    assert headers == ["名称", "X 最小", "Y 最小", "Z 最小", "X 最大", "Y 最大", "Z 最大"]


def test_sentences_from_parts_use_full_width_separators(qapp: Any, translator: Any) -> None:
    assert join_names(["a", "b"]) == "a, b" and labelled("E-stop", "x") == "E-stop: x"
    assert join_clauses(["a", "b"]) == "a, b" and join_sentences(["a", "b"]) == "a; b"
    assert translator.set_language("zh_CN")
    assert join_names(["急停", "伺服报警"]) == "急停、伺服报警"
    assert join_clauses(["3 个错误", "4 个点需要上传"]) == "3 个错误，4 个点需要上传"
    assert join_sentences(["甲", "乙"]) == "甲；乙"
    assert labelled("急停", "按下了急停按钮") == "急停：按下了急停按钮"


def test_the_alarm_banner_joins_in_chinese(qtbot: Any, translator: Any) -> None:
    from tests.ui.fake_link import FakeLink
    from tests.ui.panels.test_pose_strip import poll, status
    from ui.panels.alarm_banner import AlarmBanner

    assert translator.set_language("zh_CN")
    link = FakeLink(connected=True)
    banner = AlarmBanner()
    qtbot.addWidget(banner)
    banner.bind(link.state)
    poll(link, st=status(alarms=int(Alarm.ESTOP) | int(Alarm.SERVO)))
    text = banner.text()
    link.set_connected(False)  # stops the state's freshness timer
    assert "、" in text, text
    assert not re.search(r"[\u4e00-\u9fff][,;:]|[,;:] ?[\u4e00-\u9fff]", text), text


def _translations() -> list[tuple[str, str, str]]:
    out = []
    for context in ET.parse(TS).getroot().iter("context"):
        name = context.findtext("name") or ""
        for message in context.iter("message"):
            translation = message.find("translation")
            assert translation is not None
            forms = translation.findall("numerusform")
            text = (forms[0].text if forms else translation.text) or ""
            out.append((name, message.findtext("source") or "", text))
    return out


def test_chinese_sentences_use_full_width_punctuation() -> None:
    # (";;" separates the entries of a file filter, not words)
    half = re.compile(r"[\u4e00-\u9fff][,;:!?]|[,;:!?] ?[\u4e00-\u9fff]")
    assert [
        (c, t) for c, _s, t in _translations() if half.search(t.replace(";;", "\n"))
    ] == []  # ";;": a file filter list


def test_one_word_for_the_unit_id_and_no_split_words() -> None:
    found = _translations()
    assert [t for _c, _s, t in found if "站号" in t or "分字" in t] == []
    unit = [t for _c, s, t in found if re.search(r"\bunit( id)?\b", re.sub(r"{\w+}", "", s), re.IGNORECASE)]
    assert unit and all("从站地址" in t for t in unit), unit


def test_a_named_command_runs_into_the_chinese_that_follows() -> None:
    """ "{command} 被控制器拒绝" read "运行程序 被控制器拒绝": Chinese puts no space after a word."""
    spaced = re.compile(r"\{(command|operation)\} [\u4e00-\u9fff]")
    assert [t for _c, _s, t in _translations() if spaced.search(t)] == []


def test_every_list_in_the_gui_is_joined_with_a_translatable_separator() -> None:
    """No ", ".join / "; ".join in the GUI's code: ui/joins.py says it in the operator's language."""
    ui = Path(__file__).resolve().parents[2] / "ui"
    english = re.compile(r'"[,;] "\.join\(')
    found = [
        f"{path.relative_to(ui)}:{number}"
        for path in sorted(ui.rglob("*.py"))
        if path.name != "joins.py"
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if english.search(line)
    ]
    assert found == []
