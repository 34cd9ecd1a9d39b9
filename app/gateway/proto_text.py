"""Message classes from the text of a small ``.proto`` file, built at import (no generated code).

Why not a committed ``_pb2.py``: protobuf's generated modules (5.26 on) check at import that the
runtime is not older than the protoc that generated them, which ties the runtime pin to a code
generator nobody on the team runs (protoc or grpcio-tools, ~10 MB, not a runtime dependency); and a
committed module can drift from its ``.proto``. Here the ``.proto`` in the repository *is* the
schema: :func:`message_classes` parses it into a ``FileDescriptorProto`` and lets protobuf's own
descriptor pool build the classes, so the wire format is protobuf's, not ours.

The grammar read is the subset the Sparkplug B payload needs, and anything else is refused with the
line it is on: ``syntax = "proto2";``, ``package``, ``enum`` (``NAME = NUMBER;``), ``message`` with
nested messages and enums, ``optional`` / ``repeated`` / ``required`` fields of the scalar types or
of a message or enum declared in the file, and ``oneof`` groups.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

__all__ = ["ProtoSyntaxError", "message_classes", "parse_proto"]

_FDP = descriptor_pb2.FieldDescriptorProto
_SCALARS: dict[str, int] = {
    "double": _FDP.TYPE_DOUBLE,
    "float": _FDP.TYPE_FLOAT,
    "int64": _FDP.TYPE_INT64,
    "uint64": _FDP.TYPE_UINT64,
    "int32": _FDP.TYPE_INT32,
    "fixed64": _FDP.TYPE_FIXED64,
    "fixed32": _FDP.TYPE_FIXED32,
    "bool": _FDP.TYPE_BOOL,
    "string": _FDP.TYPE_STRING,
    "bytes": _FDP.TYPE_BYTES,
    "uint32": _FDP.TYPE_UINT32,
    "sfixed32": _FDP.TYPE_SFIXED32,
    "sfixed64": _FDP.TYPE_SFIXED64,
    "sint32": _FDP.TYPE_SINT32,
    "sint64": _FDP.TYPE_SINT64,
}
_LABELS = {"optional": _FDP.LABEL_OPTIONAL, "repeated": _FDP.LABEL_REPEATED, "required": _FDP.LABEL_REQUIRED}
_TOKEN = re.compile(r'\s*(?:(//[^\n]*)|("[^"\n]*")|([A-Za-z_][A-Za-z0-9_.]*)|(-?\d+)|([{};=]))', re.S)


class ProtoSyntaxError(ValueError):
    """The ``.proto`` text is outside the subset read here; the message names the line."""


@dataclass
class _Tokens:
    items: list[tuple[str, int]]
    at: int = 0

    def peek(self) -> str:
        return self.items[self.at][0] if self.at < len(self.items) else ""

    def line(self) -> int:
        return self.items[min(self.at, len(self.items) - 1)][1] if self.items else 1

    def take(self, expected: str | None = None) -> str:
        token = self.peek()
        if not token or (expected is not None and token != expected):
            want = f"{expected!r}" if expected is not None else "more text"
            raise ProtoSyntaxError(f"line {self.line()}: expected {want}, found {token or 'the end'!r}")
        self.at += 1
        return token

    def number(self) -> int:
        token = self.take()
        if not re.fullmatch(r"-?\d+", token):
            raise ProtoSyntaxError(f"line {self.line()}: expected a number, found {token!r}")
        return int(token)


def _tokenize(text: str) -> _Tokens:
    out: list[tuple[str, int]] = []
    pos = 0
    while True:
        match = _TOKEN.match(text, pos)
        if match is None:
            rest = text[pos:]
            if rest.strip():
                at = pos + len(rest) - len(rest.lstrip())
                raise ProtoSyntaxError(
                    f"line {text.count(chr(10), 0, at) + 1}: cannot read {rest.strip()[:20]!r}"
                )
            return _Tokens(out)
        group = match.lastindex or 0
        if group != 1:  # not a comment
            out.append((match.group(group), text.count("\n", 0, match.start(group)) + 1))
        pos = match.end()


@dataclass
class _Scope:
    """Names declared in the file, fully qualified (``.pkg.Outer.Inner``), and which are enums."""

    package: str
    types: dict[str, bool] = field(default_factory=dict)  # name -> is an enum

    def resolve(self, name: str, where: str, line: int) -> tuple[str, bool]:
        """``name`` as used inside ``where`` (a qualified message name): innermost scope first."""
        parts = where.split(".")
        while parts:
            candidate = ".".join([*parts, name])
            if candidate in self.types:
                return candidate, self.types[candidate]
            parts.pop()
        raise ProtoSyntaxError(f"line {line}: unknown type {name!r}")


def _declared(tokens: _Tokens, scope: _Scope) -> None:
    """First pass: every message and enum name (a field may name one declared later)."""
    stack: list[str] = [f".{scope.package}" if scope.package else ""]
    pending: str | None = None
    for i, (token, _line) in enumerate(tokens.items):
        if token in ("message", "enum") and i + 1 < len(tokens.items):
            name = f"{stack[-1]}.{tokens.items[i + 1][0]}"
            scope.types[name] = token == "enum"
            pending = name
        elif token == "{":
            stack.append(pending or stack[-1])
            pending = None
        elif token == "}":
            stack.pop()


def _enum(tokens: _Tokens) -> descriptor_pb2.EnumDescriptorProto:
    tokens.take("enum")
    enum = descriptor_pb2.EnumDescriptorProto(name=tokens.take())
    tokens.take("{")
    while tokens.peek() != "}":
        value = enum.value.add(name=tokens.take())
        tokens.take("=")
        value.number = tokens.number()
        tokens.take(";")
    tokens.take("}")
    return enum


def _field(
    tokens: _Tokens, scope: _Scope, where: str, label: str, oneof: int | None
) -> descriptor_pb2.FieldDescriptorProto:
    line = tokens.line()
    kind = tokens.take()
    out = descriptor_pb2.FieldDescriptorProto(label=_LABELS[label])
    out.name = tokens.take()
    tokens.take("=")
    out.number = tokens.number()
    tokens.take(";")
    if kind in _SCALARS:
        out.type = _SCALARS[kind]
    else:
        out.type_name, is_enum = scope.resolve(kind, where, line)
        out.type = _FDP.TYPE_ENUM if is_enum else _FDP.TYPE_MESSAGE
    if oneof is not None:
        out.oneof_index = oneof
    return out


def _message(tokens: _Tokens, scope: _Scope, outer: str) -> descriptor_pb2.DescriptorProto:
    tokens.take("message")
    message = descriptor_pb2.DescriptorProto(name=tokens.take())
    where = f"{outer}.{message.name}"
    tokens.take("{")
    while tokens.peek() != "}":
        _member(tokens, scope, where, message)
    tokens.take("}")
    return message


def _member(tokens: _Tokens, scope: _Scope, where: str, message: descriptor_pb2.DescriptorProto) -> None:
    token = tokens.peek()
    if token == "message":
        message.nested_type.append(_message(tokens, scope, where))
    elif token == "enum":
        message.enum_type.append(_enum(tokens))
    elif token == "oneof":
        tokens.take()
        index = len(message.oneof_decl)
        message.oneof_decl.add(name=tokens.take())
        tokens.take("{")
        while tokens.peek() != "}":
            message.field.append(_field(tokens, scope, where, "optional", index))
        tokens.take("}")
    elif token in _LABELS:
        message.field.append(_field(tokens, scope, where, tokens.take(), None))
    else:
        raise ProtoSyntaxError(f"line {tokens.line()}: {token or 'the end'!r} is not read here")


def _header(tokens: _Tokens) -> str:
    tokens.take("syntax")
    tokens.take("=")
    if tokens.take() != '"proto2"':
        raise ProtoSyntaxError(f"line {tokens.line()}: only proto2 is read here")
    tokens.take(";")
    package = ""
    if tokens.peek() == "package":
        tokens.take()
        package = tokens.take()
        tokens.take(";")
    return package


def parse_proto(text: str, filename: str) -> descriptor_pb2.FileDescriptorProto:
    """The ``.proto`` ``text`` as a descriptor; :class:`ProtoSyntaxError` naming the line."""
    tokens = _tokenize(text)
    package = _header(tokens)
    out = descriptor_pb2.FileDescriptorProto(name=filename, package=package, syntax="proto2")
    scope = _Scope(package)
    _declared(tokens, scope)
    outer = f".{package}" if package else ""
    while tokens.peek():
        if tokens.peek() == "enum":
            out.enum_type.append(_enum(tokens))
        else:
            out.message_type.append(_message(tokens, scope, outer))
    return out


def _walk(prefix: str, messages: Any) -> Iterator[str]:
    for message in messages:
        name = f"{prefix}.{message.name}" if prefix else message.name
        yield name
        yield from _walk(name, message.nested_type)


def message_classes(text: str, filename: str) -> dict[str, type[Any]]:
    """Every message class of the file by its full name (``pkg.Outer.Inner``), in a pool of its own."""
    proto = parse_proto(text, filename)
    pool = descriptor_pool.DescriptorPool()
    pool.Add(proto)
    names = _walk(proto.package, proto.message_type)
    return {name: message_factory.GetMessageClass(pool.FindMessageTypeByName(name)) for name in names}
