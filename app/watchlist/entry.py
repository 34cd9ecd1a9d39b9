"""One watched value: a GV or a holding register by number, with a name and a type.

A :class:`WatchEntry` says where a value is and how its registers read:

* ``float32`` -- two registers in the register profile's word order (PROTOCOL.md section 1):
  a GV's pair ``2n``/``2n+1``, or a register ``r`` and ``r+1``;
* ``int16`` -- one register as a signed 16-bit integer (a GV's low register ``GVn_L``);
* ``bits`` -- one register as 16 bits (the alarm word 562, say; a GV's low register).

A GV is float32 unless told otherwise, a register int16. Every bad value (a GV or register out
of range, an unknown type, a name of several lines, NaN written to a float) is refused with an
:class:`~app.errors.InvalidInput` saying what and why, before anything is sent. Qt-free.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from app.enum_alias import parse_enum
from app.errors import InvalidInput
from app.protocol.codec import FLOAT32_MAX, WordOrder, decode_floats, encode_floats

__all__ = [
    "GV_MAX",
    "MAX_ENTRIES",
    "NAME_MAX",
    "REGISTER_MAX",
    "Source",
    "ValueType",
    "WatchEntry",
    "WatchValue",
    "format_value",
    "parse_spec",
]

REGISTER_MAX = 0xFFFF
GV_MAX = REGISTER_MAX // 2  # GVn is at registers 2n, 2n+1
NAME_MAX = 60  # characters of an entry's name
MAX_ENTRIES = 200  # entries in one watch list


class Source(enum.Enum):
    """Where a watched value is: a GV (float32 pair) or a holding register by its address."""

    GV = "gv"
    REGISTER = "reg"


class ValueType(enum.Enum):
    """How a watched value's registers read."""

    FLOAT32 = "float32"
    INT16 = "int16"
    BITS = "bits"

    @property
    def count(self) -> int:
        """Registers the value takes."""
        return 2 if self is ValueType.FLOAT32 else 1

    @classmethod
    def parse(cls, text: str) -> ValueType:
        """Accept ``float32``/``int16``/``bits`` (and ``float``, ``f32``, ``int``, ``i16``, ``bit``)."""
        aliases = {cls.FLOAT32: ("float", "f32"), cls.INT16: ("i16", "int"), cls.BITS: ("bit",)}
        return parse_enum(cls, text, aliases, _unknown_type)


def _unknown_type(text: str) -> InvalidInput:
    return InvalidInput(
        f"unknown type {text[:20]!r}: use float32, int16 or bits",
        code="watch_bad_type",
        params={"type": text[:20]},
    )


def _number(value: object, hi: int, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidInput(
            f"{what} must be a whole number, got {str(value)[:20]!r}",
            code="watch_bad_number",
            params={"text": str(value)[:20]},
        )
    if not 0 <= value <= hi:
        raise InvalidInput(
            f"{what} {value} is out of range (0..{hi})",
            code="watch_gv_out_of_range" if what == "GV" else "watch_register_out_of_range",
            params={"value": value, "max": hi},
        )
    return value


@dataclass(frozen=True)
class WatchEntry:
    """A watched GV or register (see the module docstring); make one with :meth:`make`."""

    source: Source
    number: int
    type: ValueType
    name: str = ""

    @classmethod
    def make(
        cls, source: Source | str, number: object, value_type: ValueType | str | None = None, name: str = ""
    ) -> WatchEntry:
        """A checked entry (``value_type`` None: float32 for a GV, int16 for a register)."""
        src = source if isinstance(source, Source) else _source(source)
        if value_type is None:
            kind = ValueType.FLOAT32 if src is Source.GV else ValueType.INT16
        else:
            kind = value_type if isinstance(value_type, ValueType) else ValueType.parse(value_type)
        if src is Source.GV:
            n = _number(number, GV_MAX, "GV")
        else:
            n = _number(number, REGISTER_MAX - kind.count + 1, "register")
        text = str(name).strip()
        if "\n" in text or "\r" in text:
            raise InvalidInput(
                "a watched value's name is one line", code="watch_bad_name", params={"max": NAME_MAX}
            )
        if len(text) > NAME_MAX:
            raise InvalidInput(
                f"a watched value's name has at most {NAME_MAX} characters",
                code="watch_bad_name",
                params={"max": NAME_MAX},
            )
        return cls(src, n, kind, text)

    @property
    def address(self) -> int:
        """The first register (a GV: its low register ``2n``)."""
        return 2 * self.number if self.source is Source.GV else self.number

    @property
    def count(self) -> int:
        return self.type.count

    @property
    def label(self) -> str:
        """``GV10``, ``reg 560``: where it is, in the protocol's words."""
        return f"GV{self.number}" if self.source is Source.GV else f"reg {self.number}"

    @property
    def key(self) -> str:
        """One word for it (CSV columns, CLI output): ``GV10``, ``reg560``, ``GV10.int16`` ..."""
        base = f"GV{self.number}" if self.source is Source.GV else f"reg{self.number}"
        default = ValueType.FLOAT32 if self.source is Source.GV else ValueType.INT16
        return base if self.type is default else f"{base}.{self.type.value}"

    @property
    def title(self) -> str:
        """Its name, else its label."""
        return self.name or self.label

    def same_place(self, other: WatchEntry) -> bool:
        """The same registers read the same way (the name aside)."""
        return (self.source, self.number, self.type) == (other.source, other.number, other.type)

    def decode(self, regs: Sequence[int], order: WordOrder) -> float | int:
        """The value its registers hold."""
        if self.type is ValueType.FLOAT32:
            return decode_floats(regs[:2], order)[0]
        word = int(regs[0]) & 0xFFFF
        if self.type is ValueType.INT16:
            return word - 0x10000 if word >= 0x8000 else word
        return word

    def parse_value(self, value: object) -> float | int:
        """``value`` (a number or its text: ``7.5``, ``-2``, ``0b101``, ``0x1F``) checked for this
        entry's type; refused in words: NaN, out of range, not a number."""
        if self.type is ValueType.FLOAT32:
            return _finite(value, self.title)
        if self.type is ValueType.INT16:
            return _whole(value, self.title, -0x8000, 0x7FFF)
        return _whole(value, self.title, 0, 0xFFFF)

    def encode(self, value: object, order: WordOrder) -> list[int]:
        """The registers that hold ``value`` (checked as :meth:`parse_value` does)."""
        number = self.parse_value(value)
        if self.type is ValueType.FLOAT32:
            return encode_floats([float(number)], order)
        return [int(number) & 0xFFFF]

    def to_dict(self) -> dict[str, object]:
        """As the project file holds it (docs/PROJECT_FORMAT.md, ``watch_list``)."""
        return {
            "source": self.source.value,
            "number": self.number,
            "type": self.type.value,
            "name": self.name,
        }


def _source(text: str) -> Source:
    key = str(text).strip().lower()
    for member in Source:
        if member.value == key:
            return member
    if key in ("register", "r"):
        return Source.REGISTER
    raise InvalidInput(
        f"unknown source {str(text)[:20]!r}: use gv or reg",
        code="watch_bad_source",
        params={"source": str(text)[:20]},
    )


def _finite(value: object, name: str) -> float:
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            raise _not_a_number(name, value) from None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _not_a_number(name, value)
    number = float(value)
    if not math.isfinite(number):
        raise InvalidInput(
            f"{name}: {number} is not a finite number", code="watch_not_finite", params={"name": name}
        )
    if abs(number) > FLOAT32_MAX:
        raise InvalidInput(
            f"{name}: {number:g} does not fit a float32",
            code="watch_value_out_of_range",
            params={
                "name": name,
                "value": f"{number:g}",
                "min": f"{-FLOAT32_MAX:.7g}",
                "max": f"{FLOAT32_MAX:.7g}",
            },
        )
    return number


def _not_a_number(name: str, value: object) -> InvalidInput:
    text = str(value).strip()[:20]
    return InvalidInput(
        f"{name}: {text!r} is not a number", code="watch_not_a_number", params={"name": name, "text": text}
    )


def _whole(value: object, name: str, lo: int, hi: int) -> int:
    if isinstance(value, str):
        text = value.strip().lower().replace("_", "")
        try:
            value = int(text, 0) if text[:2] in ("0b", "0x") else int(text)
        except ValueError:
            raise _not_a_number(name, text) from None
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise _not_a_number(name, value)
    if not lo <= value <= hi:
        raise InvalidInput(
            f"{name}: {value} is out of range ({lo}..{hi})",
            code="watch_value_out_of_range",
            params={"name": name, "value": value, "min": lo, "max": hi},
        )
    return value


@dataclass(frozen=True, slots=True)
class WatchValue:
    """One entry's reading: its value (None when the read failed: ``error`` says why), the raw
    registers and when they were read (``time.monotonic()`` of the answer)."""

    entry: WatchEntry
    value: float | int | None
    raw: tuple[int, ...]
    read_at: float
    error: str | None = None


def format_value(entry: WatchEntry, value: float | int | None) -> str:
    """The value as text: a float with up to 6 significant digits, bits as ``0b0000 0000 0000 0101``."""
    if value is None:
        return ""
    if entry.type is ValueType.BITS:
        bits = f"{int(value):016b}"
        return "0b" + " ".join(bits[i : i + 4] for i in range(0, 16, 4))
    if entry.type is ValueType.INT16:
        return str(int(value))
    return f"{float(value):.6g}"


def parse_spec(source: Source, text: str) -> WatchEntry:
    """The CLI's ``--gv 10``, ``--gv 10:int16``, ``--reg 562:bits=alarms``: number, then
    ``:type`` and ``=name``, both optional."""
    spec, _, name = text.partition("=")
    number_text, _, type_text = spec.partition(":")
    try:
        number = int(number_text.strip())
    except ValueError:
        what = "GV" if source is Source.GV else "register"
        raise InvalidInput(
            f"{what} {number_text.strip()[:20]!r} is not a number (e.g. 10, 10:int16, 562:bits=alarms)",
            code="watch_bad_number",
            params={"text": number_text.strip()[:20]},
        ) from None
    return WatchEntry.make(source, number, type_text.strip() or None, name)
