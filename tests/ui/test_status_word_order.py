"""GV291 read in the other word order than the controller writes it (the register profile's word
order does not match it, e.g. just after switching the profile): the controller's 255.0 read as
its high word alone was "teach disable refused by the controller: unknown status 17279." -- a
refusal the controller never said (issue 21). Against a high-first simulator read low-first; the
integer encoding of GV291 still reads as before."""

from __future__ import annotations

from typing import Any

import pytest

from app.protocol.codec import WordOrder, float_to_registers
from app.protocol.enums import decode_status_registers
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from tests.ui.test_messages import assert_chinese
from ui.messages import result_level, result_text

pytestmark = pytest.mark.timeout(60)


def test_teach_disable_is_not_a_refusal_when_the_word_order_is_the_other_one(
    sim_factory: Any, make_client: Any, translator: Any
) -> None:
    sim = sim_factory(word_order="high-first")
    client = make_client(sim, word_order=WordOrder.LOW_FIRST, poll_timeout=1.0)
    result = client.teach_disable()
    assert result.ok and result.status is not None and result.status.code == 0xFF
    assert not sim.state().teach_enabled  # at the simulator: teach mode is off
    text = result_text(result)
    assert "17279" not in text and "refused" not in text and result_level(result) == "info", text
    assert translator.set_language("zh_CN")
    assert_chinese(result_text(result))


@pytest.mark.parametrize("order", list(WordOrder))
@pytest.mark.parametrize("code", [0, 1, 2, 17, 128, 254, 255])
def test_either_encoding_in_either_word_order(order: WordOrder, code: int) -> None:
    other = WordOrder.HIGH_FIRST if order is WordOrder.LOW_FIRST else WordOrder.LOW_FIRST
    assert decode_status_registers(float_to_registers(float(code), order), order) == code
    assert decode_status_registers(float_to_registers(float(code), other), order) == code
    assert decode_status_registers([code, 0], order) == code  # the integer encoding (582)
