"""Reading an enum member from what a person typed: its value or one of its other spellings.

One helper for the enums the host reads from text (:class:`app.protocol.codec.WordOrder`,
:class:`app.watchlist.entry.ValueType`): case and surrounding blanks do not count, a member's own
value comes first, then the aliases; anything else is refused with the error the caller makes from
the text, so each keeps its own words. Standard library only, so any module may import it.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterable, Mapping
from typing import TypeVar

__all__ = ["parse_enum"]

E = TypeVar("E", bound=enum.Enum)


def parse_enum(
    members: type[E],
    text: str,
    aliases: Mapping[E, Iterable[str]],
    refuse: Callable[[str], Exception],
) -> E:
    """The member of ``members`` whose value, or else one of its aliases, ``text`` names.

    ``aliases`` gives a member its other spellings, in lower case. ``text`` is read stripped and
    in lower case. An unknown spelling raises ``refuse(text)`` (the text as typed, for the
    caller's message).
    """
    key = text.strip().lower()
    for member in members:
        if member.value == key:
            return member
    for member, spellings in aliases.items():
        if key in spellings:
            return member
    raise refuse(text)
