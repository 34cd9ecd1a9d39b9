"""The one enum reader of typed text (app/enum_alias.py): values, aliases, refusal in the caller's words."""

from __future__ import annotations

import enum

import pytest

from app.enum_alias import parse_enum
from app.errors import InvalidInput


class Colour(enum.Enum):
    RED = "red"
    DARK_BLUE = "dark-blue"


ALIASES = {Colour.RED: ("r", "dark-blue"), Colour.DARK_BLUE: ("navy",)}


def _unknown(text: str) -> InvalidInput:
    return InvalidInput(f"unknown colour {text!r}: use red or dark-blue", code="bad_colour")


@pytest.mark.parametrize(
    ("text", "member"),
    [
        ("red", Colour.RED),
        ("  RED\t", Colour.RED),
        ("Dark-Blue", Colour.DARK_BLUE),  # a member's own value comes before an alias of it
        ("r", Colour.RED),
        (" NAVY ", Colour.DARK_BLUE),
    ],
)
def test_parse_enum_reads_values_then_aliases(text: str, member: Colour) -> None:
    assert parse_enum(Colour, text, ALIASES, _unknown) is member


@pytest.mark.parametrize("text", ["", "green", "dark blue", "RED!"])
def test_parse_enum_refuses_an_unknown_spelling_in_the_callers_words(text: str) -> None:
    with pytest.raises(InvalidInput) as caught:
        parse_enum(Colour, text, ALIASES, _unknown)
    # The text as typed (not stripped nor folded) in the message, the caller's code kept.
    assert str(caught.value) == f"unknown colour {text!r}: use red or dark-blue"
    assert caught.value.code == "bad_colour"


def test_parse_enum_without_aliases_takes_values_only() -> None:
    assert parse_enum(Colour, "dark-blue", {}, _unknown) is Colour.DARK_BLUE
    with pytest.raises(InvalidInput, match="unknown colour 'r'"):
        parse_enum(Colour, "r", {}, _unknown)
