"""The Modbus exception codes in words: one table for the frame decoder and the client.

The codes are the standard's (Modbus Application Protocol v1.1b3, section 7); the controller
answers 0x02 / 0x03 / 0x04 / 0x06 in practice (PROTOCOL.md), the rest are here so that a
gateway or another device on the line is named too.
"""

from __future__ import annotations

from typing import Final

MODBUS_EXCEPTION_TEXT: Final[dict[int, str]] = {
    0x01: "illegal function",
    0x02: "illegal data address",
    0x03: "illegal data value",
    0x04: "server device failure",
    0x05: "acknowledge",
    0x06: "server device busy",
    0x07: "negative acknowledge",
    0x08: "memory parity error",
    0x0A: "gateway path unavailable",
    0x0B: "gateway target device failed to respond",
}


#: The codes that say the request was *not carried out*: refused before acting on it (illegal
#: function, address or value), busy ("retransmit later"), or not forwarded by a gateway. Any other
#: code -- server device failure (4, it may have acted part-way), acknowledge (5: taken, still
#: working), negative acknowledge, memory parity error, a gateway's target that did not respond
#: (0x0B: it may have acted), a code the standard does not define -- leaves open what the
#: controller did with the request.
NOT_CARRIED_OUT: Final[frozenset[int]] = frozenset({0x01, 0x02, 0x03, 0x06, 0x0A})


#: The codes a gateway answers when nothing answers at the request's unit id (path unavailable,
#: target device failed to respond): most often a wrong unit id -- a link problem, not the
#: controller's refusal of the command (the CLI's exit 3; the GUI says to check the unit id).
GATEWAY_EXCEPTIONS: Final[frozenset[int]] = frozenset({0x0A, 0x0B})


def not_carried_out(code: int) -> bool:
    """Exception ``code`` says the request was not carried out (see :data:`NOT_CARRIED_OUT`)."""
    return code in NOT_CARRIED_OUT


def exception_text(code: int, unknown: str = "unknown exception") -> str:
    """The standard's name of exception ``code``; ``unknown`` for a code it does not define."""
    return MODBUS_EXCEPTION_TEXT.get(code, unknown)


__all__ = [
    "GATEWAY_EXCEPTIONS",
    "MODBUS_EXCEPTION_TEXT",
    "NOT_CARRIED_OUT",
    "exception_text",
    "not_carried_out",
]
