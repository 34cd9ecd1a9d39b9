"""What a number field may offer the on-screen keypad besides its own range (no Qt here).

A field whose allowed values depend on more than its fixed range -- an axis's offset, allowed
from where the axis stands to each of its limits -- has ``keypad_range()`` (:class:`RangedField`):
the keypad (:mod:`ui.keypad`) then offers that range, with the note saying where it comes from.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

__all__ = ["KeypadRange", "RangedField"]


@dataclass(frozen=True)
class KeypadRange:
    """The values the keypad accepts now, and what they come from (translated, "" for none)."""

    low: float
    high: float
    note: str = ""


@runtime_checkable
class RangedField(Protocol):
    def keypad_range(self) -> KeypadRange | None: ...
