"""Fault knobs of the simulator. A refusal: one point's create-point parameters answered with a
Modbus exception, a given number of times (:meth:`app.sim.server.SimController.refuse_point_write`);
and which requests a delay or an exception touches (by register range and connection).

A controller that does not take a point id refuses the write of GV200-202 (point id, pose
source, first pose GV) with an exception (illegal data value, say) instead of accepting it and
failing the command: the controller answered, the link is fine, the write is not stored.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

from pymodbus.constants import ExcCodes

from app.protocol.codec import WordOrder, registers_to_float
from app.protocol.registers import GV_PARAM0, gv_reg

__all__ = ["PointWriteRefusals", "at_text", "on_text", "touches"]

_POINT_ID_REG = gv_reg(GV_PARAM0)  # GV200: the point id of a create point


class PointWriteRefusals:
    """Point id -> (exception, writes still to refuse). Thread-safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._refusals: dict[int, tuple[ExcCodes, int]] = {}

    def set(self, point_id: int, code: ExcCodes, times: int) -> None:
        """Refuse the next ``times`` writes of GV200 that name ``point_id`` (0: refuse none)."""
        with self._lock:
            if times > 0:
                self._refusals[int(point_id)] = (code, times)
            else:
                self._refusals.pop(int(point_id), None)

    def check(self, address: int, values: Sequence[int], order: WordOrder) -> ExcCodes | None:
        """The exception for this write (one refusal used up), or None when it is accepted."""
        offset = _POINT_ID_REG - address
        if not self._refusals or offset < 0 or offset + 2 > len(values):
            return None
        value = registers_to_float(values[offset : offset + 2], order)
        with self._lock:
            entry = self._refusals.get(int(value)) if value.is_integer() else None
            if entry is None:
                return None
            code, left = entry
            if left > 1:
                self._refusals[int(value)] = (code, left - 1)
            else:
                del self._refusals[int(value)]
            return code


def touches(addresses: range | None, address: int, count: int) -> bool:
    """A request of ``count`` registers at ``address`` touches ``addresses`` (None: every request)."""
    return addresses is None or (address < addresses.stop and addresses.start < address + count)


def on_text(connection: int | None) -> str:
    """For the log: on which connection a fault applies."""
    return "" if connection is None else f" on connection {connection}"


def at_text(addresses: range | None) -> str:
    """For the log: which registers a fault touches."""
    return "" if addresses is None else f" on {addresses.start}..{addresses.stop - 1}"
