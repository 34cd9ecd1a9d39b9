"""Sparkplug B payloads: the message classes of ``sparkplug_b.proto`` and the metric datatypes.

The classes are built at import from the ``.proto`` next to this module (:mod:`app.gateway.proto_text`
says why there is no generated ``_pb2``). :func:`encode` / :func:`decode` are what the edge node and
an independent subscriber (the tests) use.
"""

from __future__ import annotations

import enum
from pathlib import Path
from typing import Any

from app.gateway.proto_text import message_classes

__all__ = ["PROTO_FILE", "DataType", "Metric", "Payload", "decode", "encode", "metric_value"]

PROTO_FILE = Path(__file__).with_name("sparkplug_b.proto")
_CLASSES = message_classes(PROTO_FILE.read_text(encoding="utf-8"), "sparkplug_b.proto")
Payload: type[Any] = _CLASSES["org.eclipse.tahu.protobuf.Payload"]
Metric: type[Any] = _CLASSES["org.eclipse.tahu.protobuf.Payload.Metric"]


class DataType(enum.IntEnum):
    """The Sparkplug B datatypes TeachPad sends (numbers: the specification's ``DataType``)."""

    INT32 = 3
    INT64 = 4
    UINT16 = 6
    UINT32 = 7
    UINT64 = 8
    DOUBLE = 10
    BOOLEAN = 11
    STRING = 12


#: which ``value`` field of a Metric carries each datatype (Sparkplug 3.0, 6.4.16)
VALUE_FIELD: dict[DataType, str] = {
    DataType.INT32: "int_value",
    DataType.UINT16: "int_value",
    DataType.UINT32: "int_value",
    DataType.INT64: "long_value",
    DataType.UINT64: "long_value",
    DataType.DOUBLE: "double_value",
    DataType.BOOLEAN: "boolean_value",
    DataType.STRING: "string_value",
}

Value = bool | int | float | str | None


def set_value(metric: Any, datatype: DataType, value: Value) -> None:
    """Put ``value`` in the field ``datatype`` says; None is ``is_null``. Int32 and Int64 are sent
    as their two's complement in the unsigned field, as the specification says."""
    if value is None:
        metric.is_null = True
        return
    name = VALUE_FIELD[datatype]
    if datatype is DataType.INT32:
        value = int(value) & 0xFFFFFFFF
    elif datatype is DataType.INT64:
        value = int(value) & 0xFFFFFFFFFFFFFFFF
    setattr(metric, name, value)


def metric_value(metric: Any) -> Value:
    """What a decoded metric carries (signed for Int32 / Int64 when its datatype says so)."""
    if metric.is_null:
        return None
    which = metric.WhichOneof("value")
    if which is None:
        return None
    value: Value = getattr(metric, which)
    if metric.datatype == DataType.INT32 and isinstance(value, int) and value >= 1 << 31:
        value -= 1 << 32
    elif metric.datatype == DataType.INT64 and isinstance(value, int) and value >= 1 << 63:
        value -= 1 << 64
    return value


def encode(payload: Any) -> bytes:
    data: bytes = payload.SerializeToString()
    return data


def decode(data: bytes | bytearray) -> Any:
    payload = Payload()
    payload.ParseFromString(data)
    return payload
