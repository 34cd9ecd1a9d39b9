"""Register reads and writes summarised in one line for the traffic inspector and the audit
trail (``GV206–GV211 = …``, ``teach enable (440 ← 0x80)``), from :mod:`app.protocol.naming`'s items."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from app.protocol.naming import (  # the register tables are naming's own
    _INT_REGISTERS,
    _KNOWN_BLOCKS,
    _NOT_FLOAT,
    _STATUS_SPARE,
    SUMMARY_LIST_LIMIT,
    ItemKind,
    RegisterItem,
    gv_register_name,
)


def _gv_span(address: int, count: int) -> str:
    first, last = address // 2, (address + count - 1) // 2
    return f"GV{first}" if first == last else f"GV{first}–GV{last}"


def _is_gv_run(address: int, count: int) -> bool:
    """Whole GVs from an even address, none of them an integer register."""
    return (
        address % 2 == 0
        and count % 2 == 0
        and count > 0
        and not any(r in _NOT_FLOAT for r in range(address, address + count))
    )


def range_label(address: int, count: int) -> str:
    """``pose X..C (GV206–GV211)``, ``GV200 (400–401)``, ``regs 107–109``, ``reg 1``."""
    known = _KNOWN_BLOCKS.get((address, count))
    if known is not None:
        return known
    last = address + count - 1
    if count <= 0:
        return f"no regs at {address}"
    if _is_gv_run(address, count):
        return f"{_gv_span(address, count)} ({address}–{last})"
    return f"reg {address}" if count == 1 else f"regs {address}–{last}"


def limited_list(texts: Sequence[str], limit: int = SUMMARY_LIST_LIMIT) -> str:
    if len(texts) <= limit:
        return ", ".join(texts)
    return ", ".join(texts[:limit]) + f", … (+{len(texts) - limit})"


def _listed(
    items: Sequence[RegisterItem], text: Callable[[RegisterItem], str], limit: int = SUMMARY_LIST_LIMIT
) -> str:
    """``limited_list`` of ``text(item)``, formatting only the items it shows."""
    if len(items) <= limit:
        return ", ".join(map(text, items))
    return ", ".join(map(text, items[:limit])) + f", … (+{len(items) - limit})"


def _text(item: RegisterItem) -> str:
    return item.text


def _short(item: RegisterItem) -> str:
    return item.short


def _plain(items: Sequence[RegisterItem]) -> bool:
    """Items that read best as one list of values: role-less GVs, or raw registers."""
    return bool(items) and (
        all(it.kind is ItemKind.FLOAT and not it.role for it in items)
        or all(it.kind is ItemKind.RAW for it in items)
    )


def _summary_items(items: Sequence[RegisterItem]) -> list[RegisterItem]:
    named = [it for it in items if it.address not in _STATUS_SPARE]
    return named or list(items)


def summarize_registers(address: int, items: Sequence[RegisterItem]) -> str:
    """``pose X..C (GV206–GV211): X=1.0, Y=2.0, …`` for a run of decoded registers."""
    if not items:
        return range_label(address, 0)
    label = range_label(address, items[-1].last - address + 1)
    shown = _summary_items(items)
    if _plain(shown):
        return f"{label} = {_listed(shown, _text)}"
    return f"{label}: {_listed(shown, _short)}"


def write_summary(address: int, items: Sequence[RegisterItem]) -> str:
    if _plain(items):
        count = items[-1].last - address + 1
        who = _gv_span(address, count) if items[0].kind is ItemKind.FLOAT else range_label(address, count)
        return f"write {who} = {_listed(items, _text)}"
    if len(items) == 1:
        return f"write {items[0].label}"
    return f"write {_listed(items, _short)}"


def single_write_text(address: int, value: int) -> str:
    """FC06 in words: ``teach enable (440 ← 0x80)``, ``write reg 1 (GV0_H) = 0x0003``."""
    spec = _INT_REGISTERS.get(address)
    if spec is None:
        return f"write reg {address} ({gv_register_name(address)}) = 0x{value:04X}"
    shown = f"0x{value:02X}" if spec.hex_value else str(value)
    return f"{spec.action(value)} ({address} ← {shown})"


__all__ = ["limited_list", "range_label", "single_write_text", "summarize_registers", "write_summary"]
