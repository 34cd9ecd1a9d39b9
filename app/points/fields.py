"""A point's fields: parsing and validating values from files and editors.

The ``parse_*`` functions refuse with a :class:`FieldError` naming the field, with a code and
arguments (``not_a_number``, ``too_large``, ...) that the GUI words in the operator's language;
their English messages quote at most :data:`QUOTE_CHARS` characters of a bad value
(:func:`shown`). Shared by the points (:mod:`app.points.point`), plans, CSV and JSON.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from app.errors import InvalidInput
from app.protocol.registers import TEMP_POINT_ID_MAX, TEMP_POINT_ID_MIN, TOOL_NONE

TOOL_MAX = 199  # tool frames 0..199, shown as "tool N" (GV245's N); TOOL_NONE (200) is "no tool frame"
NAME_MAX_CHARS = 200
NOTE_MAX_CHARS = 2000


class FieldError(InvalidInput):
    """One field's value refused; ``field`` names it, ``reason`` says why."""

    def __init__(
        self,
        field_name: str,
        reason: str,
        *,
        code: str | None = None,
        params: Mapping[str, Any] | None = None,
    ) -> None:
        super().__init__(f"{field_name}: {reason}", code=code, params=params)
        self.field = field_name
        self.reason = reason


@dataclass(frozen=True)
class PointLimits:
    """Accepted temp point ids (a setting; PROTOCOL.md section 7)."""

    id_min: int = TEMP_POINT_ID_MIN
    id_max: int = TEMP_POINT_ID_MAX

    def __post_init__(self) -> None:
        if self.id_min < 0 or self.id_max < self.id_min:
            raise InvalidInput(f"bad point id range {self.id_min}..{self.id_max}")


DEFAULT_LIMITS = PointLimits()


QUOTE_CHARS = 40  # at most this much of a bad value is quoted in a message
INT_DIGITS_MAX = 30  # longer integers are refused as too large before int() sees them


class OversizedNumber:
    """A number too long to convert (a JSON decoder hook returns it instead of an ``int``:
    Python refuses ``int()`` of more than 4300 digits). Every parse function refuses it."""

    __slots__ = ("digits",)

    def __init__(self, digits: str) -> None:
        self.digits = digits

    def __repr__(self) -> str:
        return shown(self.digits)


def shown(value: object, limit: int = QUOTE_CHARS) -> str:
    """``repr``-like quote of a value for a message, at most ``limit`` characters of it."""
    if isinstance(value, OversizedNumber):
        text = value.digits
        return (text[:limit] + f"... ({len(text)} digits)") if len(text) > limit else text
    if isinstance(value, str):
        cut = value[:limit]
        quoted = repr(cut)
        return quoted + f"... ({len(value)} characters)" if len(value) > limit else quoted
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**limit:
        return f"a {len(str(abs(value))) if value.bit_length() < 14000 else 'huge'}-digit number"
    if isinstance(value, list | dict | tuple):
        return f"a {type(value).__name__}"
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "..."


def has_surrogates(text: str) -> bool:
    """True when ``text`` holds a lone surrogate (no valid UTF-8 for it: saving would fail)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def parse_float(field_name: str, value: object) -> float:
    """A finite float from a number or text; NaN, infinities and huge numbers are refused."""
    if isinstance(value, bool):
        raise FieldError(
            field_name, f"{shown(value)} is not a number", code="not_a_number", params={"value": shown(value)}
        )
    if isinstance(value, OversizedNumber):
        raise FieldError(
            field_name, f"{shown(value)} is too large", code="too_large", params={"value": shown(value)}
        )
    if isinstance(value, int | float):
        try:
            number = float(value)
        except OverflowError:
            raise FieldError(
                field_name, f"{shown(value)} is too large", code="too_large", params={"value": shown(value)}
            ) from None
    elif isinstance(value, str):
        text = value.strip()
        if not text:
            raise FieldError(field_name, "the value is empty", code="value_empty")
        try:
            number = float(text)
        except ValueError:
            raise FieldError(
                field_name,
                f"{shown(text)} is not a number",
                code="not_a_number",
                params={"value": shown(text)},
            ) from None
        if not math.isfinite(number) and text.lstrip("+-").lower() not in ("inf", "infinity", "nan"):
            raise FieldError(
                field_name, f"{shown(text)} is too large", code="too_large", params={"value": shown(text)}
            )
    else:
        raise FieldError(
            field_name, f"{shown(value)} is not a number", code="not_a_number", params={"value": shown(value)}
        )
    if not math.isfinite(number):
        raise FieldError(
            field_name,
            f"{shown(value)} is not a finite number",
            code="not_finite",
            params={"value": shown(value)},
        )
    return number


def parse_int(field_name: str, value: object) -> int:
    """An integer from an int, an integral float or text (``"5"``, ``"5.0"``)."""
    if isinstance(value, bool):
        raise FieldError(
            field_name,
            f"{shown(value)} is not an integer",
            code="not_integer",
            params={"value": shown(value)},
        )
    if isinstance(value, int):
        if value.bit_length() > 100:
            raise FieldError(
                field_name, f"{shown(value)} is too large", code="too_large", params={"value": shown(value)}
            )
        return value
    if (
        isinstance(value, str)
        and len(value.strip().lstrip("+-")) > INT_DIGITS_MAX
        and value.strip().lstrip("+-").isdigit()
    ):
        raise FieldError(
            field_name,
            f"{shown(value.strip())} is too large",
            code="too_large",
            params={"value": shown(value.strip())},
        )
    number = parse_float(field_name, value)
    if not number.is_integer():
        quoted = shown(value.strip() if isinstance(value, str) else value)
        raise FieldError(
            field_name, f"{quoted} is not an integer", code="not_integer", params={"value": quoted}
        )
    if abs(number) >= 2.0**100:
        raise FieldError(
            field_name, f"{shown(value)} is too large", code="too_large", params={"value": shown(value)}
        )
    return int(number)


def parse_point_id(value: object, limits: PointLimits = DEFAULT_LIMITS, field_name: str = "id") -> int:
    point_id = parse_int(field_name, value)
    if not limits.id_min <= point_id <= limits.id_max:
        raise FieldError(
            field_name,
            f"id {shown(point_id)} is outside {limits.id_min}..{limits.id_max}",
            code="id_out_of_range",
            params={"value": shown(point_id), "id_min": limits.id_min, "id_max": limits.id_max},
        )
    return point_id


def parse_tool(value: object, field_name: str = "tool") -> int:
    """Tool frame: 0..199 (GV245's number, as shown everywhere) or 200 (none)."""
    tool = parse_int(field_name, value)
    if not (0 <= tool <= TOOL_MAX or tool == TOOL_NONE):
        raise FieldError(
            field_name,
            f"tool {shown(tool)} is not 0..{TOOL_MAX} or {TOOL_NONE} (none)",
            code="bad_tool",
            params={"value": shown(tool), "max": TOOL_MAX, "none": TOOL_NONE},
        )
    return tool


def parse_text(field_name: str, value: object, max_chars: int) -> str:
    if value is None:
        return ""
    if not isinstance(value, str):
        raise FieldError(field_name, f"{shown(value)} is not text", code="not_text")
    if len(value) > max_chars:
        raise FieldError(
            field_name, f"is longer than {max_chars} characters", code="too_long", params={"max": max_chars}
        )
    if has_surrogates(value):
        raise FieldError(
            field_name,
            "holds an invalid character (a lone surrogate, not Unicode text)",
            code="bad_character",
        )
    if any(ch in value for ch in "\x00\r\n") and field_name == "name":
        raise FieldError(field_name, "must be one line", code="not_one_line")
    return value


def tool_text(tool: int) -> str:
    """How the GUI and CLI show a tool frame: the one number the CSV, the project file, the cell
    editor, ``--tool`` and GV245 hold (0..199; the controller's own pendant may count from 1)."""
    return "none" if tool == TOOL_NONE else f"tool {tool}"
