"""The Sparkplug B payload schema: our .proto read into protobuf's own message classes."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.gateway import payload as pb
from app.gateway.proto_text import ProtoSyntaxError, parse_proto

from . import conftest


def test_the_metric_fields_have_the_specifications_numbers_and_types() -> None:
    fields = {f.name: (f.number, f.type) for f in pb.Metric.DESCRIPTOR.fields}
    t = pb.Metric.DESCRIPTOR.fields_by_name["name"].__class__
    assert fields["name"] == (1, t.TYPE_STRING)
    assert fields["alias"] == (2, t.TYPE_UINT64)
    assert fields["timestamp"] == (3, t.TYPE_UINT64)
    assert fields["datatype"] == (4, t.TYPE_UINT32)
    assert fields["is_historical"] == (5, t.TYPE_BOOL)
    assert fields["is_null"] == (7, t.TYPE_BOOL)
    assert fields["int_value"] == (10, t.TYPE_UINT32)
    assert fields["long_value"] == (11, t.TYPE_UINT64)
    assert fields["double_value"] == (13, t.TYPE_DOUBLE)
    assert fields["boolean_value"] == (14, t.TYPE_BOOL)
    assert fields["string_value"] == (15, t.TYPE_STRING)
    payload = {f.name: f.number for f in pb.Payload.DESCRIPTOR.fields}
    assert payload == {"timestamp": 1, "metrics": 2, "seq": 3, "uuid": 4, "body": 5}


def test_wire_bytes_as_the_specification_encodes_them() -> None:
    # Payload{timestamp: 5, seq: 3, metrics: [{name: "a", alias: 7, datatype: Double, double_value: 1.5}]}
    wire = bytes.fromhex("080512100a01611007200a69000000000000f83f1803")
    decoded = pb.decode(wire)
    assert (decoded.timestamp, decoded.seq) == (5, 3)
    metric = decoded.metrics[0]
    assert (metric.name, metric.alias, metric.datatype, pb.metric_value(metric)) == ("a", 7, 10, 1.5)
    assert pb.encode(decoded) == wire


def test_signed_values_and_null() -> None:
    message = pb.Payload()
    for datatype, value in (
        (pb.DataType.INT32, -2),
        (pb.DataType.INT64, -(2**40)),
        (pb.DataType.STRING, None),
    ):
        pb.set_value(message.metrics.add(datatype=datatype), datatype, value)
    assert [pb.metric_value(m) for m in pb.decode(pb.encode(message)).metrics] == [-2, -(2**40), None]


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ('syntax = "proto3";', "only proto2"),
        ('syntax = "proto2";\nmessage A {\n  optional Missing b = 1;\n}', "line 3: unknown type 'Missing'"),
        ('syntax = "proto2";\nmessage A {\n  map<string, int32> m = 1;\n}', "line 3"),
        ('syntax = "proto2";\nmessage A {\n  optional int32 b = x;\n}', "expected a number"),
    ],
)
def test_text_outside_the_subset_is_refused_naming_the_line(text: str, said: str) -> None:
    with pytest.raises(ProtoSyntaxError, match=said):
        parse_proto(text, "x.proto")


def test_the_proto_file_is_in_the_package() -> None:
    assert pb.PROTO_FILE.parent == Path(pb.__file__).parent
    assert "org.eclipse.tahu.protobuf" in pb.PROTO_FILE.read_text()


def test_without_mosquitto_the_tests_fail_saying_how_to_install_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("shutil.which", lambda _name: None)
    monkeypatch.setattr(conftest, "MOSQUITTO_PATHS", ("/nonexistent/mosquitto",))
    with pytest.raises(pytest.fail.Exception, match=r"mosquitto is not installed.*apt-get install"):
        conftest.mosquitto_binary()
