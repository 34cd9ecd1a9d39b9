"""Every result and error kind reads as a Chinese sentence in the zh_CN UI (ui/messages.py).

Results come from the real :class:`CommandTracker` fed status reads; errors are the typed
errors the client and the transport raise. With the shipped .qm installed, no English word may
remain: only units, register names, numbers, "Modbus", host:port and the like.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator

from app.errors import (
    AlarmRaised,
    CommandRefused,
    CommandTimeout,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.tracker import CommandTracker
from app.link.types import Operation, WorkerError
from app.models import CommandResult, ControllerStatus
from app.protocol.enums import (
    _STATUS_TEXT,
    STATUS_SENTINEL,
    Alarm,
    CommandKind,
    CommandStatus,
    ControllerMode,
    ProgramState,
    RunCommand,
)
from app.safety.envelope import EnvelopeRefused, EnvelopeViolation, ViolationCode
from ui.messages import LEVEL_ERROR, LEVEL_INFO, LEVEL_WARNING, error_text, result_level, result_text

QM = Path(__file__).resolve().parents[2] / "ui" / "i18n" / "teachpad_zh_CN.qm"
ENDPOINT = "192.168.1.10:502"
# what may stay ASCII in a Chinese sentence: units, register and protocol names, numbers, addresses
ALLOWED = re.compile(r"\d+(\.\d+)+:\d+|Modbus|TCP|RTU|CRC|GV\d+|COM\d+|mm/s|mm|\bs\b|\b[XYZABC]\b|"
                     r"\bJ\d+\b|\bP\d+\b|0x[0-9A-Fa-f]+")


@pytest.fixture
def zh(qapp: object) -> Iterator[None]:
    translator = QTranslator()
    assert translator.load(str(QM))
    QCoreApplication.installTranslator(translator)
    yield
    QCoreApplication.removeTranslator(translator)


def assert_chinese(text: str) -> None:
    left = ALLOWED.sub("", text)
    assert not re.search(r"[A-Za-z]", left), f"English left in {text!r}"
    assert re.search(r"[\u4e00-\u9fff]", text), f"no Chinese in {text!r}"


def _status(code: int, mode: int = ControllerMode.MODBUS_TEACH, state: int = ProgramState.STOPPED,
            alarms: int = 0) -> ControllerStatus:
    return ControllerStatus(mode, state, Alarm(alarms), code)


def _tracked(command: RunCommand, *reads: ControllerStatus, pre: int = 0, stop: bool = False,
             rule: str = "observe") -> CommandResult:
    tracker = CommandTracker(command, _status(pre), None, 0.0, rule=rule)  # type: ignore[arg-type]
    now = 0.0
    for read in reads:
        now += 0.05
        result = tracker.update(read, None, now)
        if result is not None:
            return result
    if stop:
        return tracker.stopped(now + 0.01)
    now += 100.0
    result = tracker.update(reads[-1] if reads else _status(pre), None, now)
    assert result is not None
    return result


def _results() -> dict[str, CommandResult]:
    move = RunCommand.MOVE_TO_POINT
    return {
        "ok": _tracked(move, _status(6), _status(0xFF)),
        "ok by mode": _mode_result(),
        "refused": _tracked(move, _status(13)),
        "alarm while waiting": _tracked(RunCommand.TEACH_ENABLE, _status(0, alarms=int(Alarm.ESTOP))),
        "not acknowledged": _tracked(move, _status(0)),
        "unconfirmed": _tracked(RunCommand.CREATE_POINT, _status(0xFF), pre=0xFF),
        "refused unconfirmed": _tracked(RunCommand.CREATE_POINT, _status(1), pre=1),
        "stopped by operator": _tracked(move, _status(6), stop=True),
        "stopped by controller": _stopped_by_controller(),
        "timeout": _timeout(),
    }


def _mode_result() -> CommandResult:
    tracker = CommandTracker(RunCommand.TEACH_ENABLE, _status(0, mode=ControllerMode.MANUAL), None, 0.0)
    result = tracker.update(_status(0, mode=ControllerMode.MODBUS_TEACH), None, 0.05)
    assert result is not None and result.ok
    return result


def _stopped_by_controller() -> CommandResult:
    tracker = CommandTracker(RunCommand.MOVE_TO_POINT, _status(0xFF), None, 0.0)
    assert tracker.update(_status(6, state=ProgramState.RUNNING), None, 0.05) is None
    now = 0.1
    result = None
    while result is None:
        now += 0.1
        result = tracker.update(_status(0, state=ProgramState.STOPPED), None, now)
    return result


def _timeout() -> CommandResult:
    tracker = CommandTracker(RunCommand.MOVE_TO_POINT, _status(0), None, 0.0, timeout=1.0)
    assert tracker.update(_status(6, state=ProgramState.RUNNING), None, 0.05) is None
    result = tracker.update(_status(6, state=ProgramState.RUNNING), None, 2.0)
    assert result is not None
    return result


def test_every_result_kind_reads_in_chinese(zh: None) -> None:
    results = _results()
    codes = {name: r.reason.code for name, r in results.items() if r.reason is not None}
    assert len(codes) == len(results), "every tracked result carries a reason"
    assert set(codes.values()) >= {"done", "done_by_mode", "command_refused", "alarm_while_waiting",
                                   "not_acknowledged", "done_unconfirmed", "refused_unconfirmed",
                                   "stopped_by_operator", "stopped_by_controller", "command_timeout"}
    for result in results.values():
        assert_chinese(result_text(result))
    assert result_text(results["unconfirmed"]) == "创建临时点：已完成，控制器未确认。"
    assert "急停" in result_text(results["alarm while waiting"])
    assert "\u2014" not in result_text(results["alarm while waiting"])  # one sentence, no tail


def test_refused_with_every_status_of_every_kind_reads_in_chinese(zh: None) -> None:
    commands = {CommandKind.MOVE: RunCommand.MOVE_TO_POINT, CommandKind.CREATE_POINT: RunCommand.CREATE_POINT,
                CommandKind.TEACH: RunCommand.TEACH_ENABLE}
    for kind, table in _STATUS_TEXT.items():
        for code in [*table, 200, STATUS_SENTINEL]:
            error = CommandRefused(CommandStatus(kind, code), params={"command": int(commands[kind])})
            result = CommandResult(commands[kind], kind, CommandStatus(kind, code), False, str(error),
                                   reason=error.as_reason())
            assert_chinese(result_text(result))


def test_the_operators_stop_is_neutral_and_an_unconfirmed_success_a_warning(zh: None) -> None:
    results = _results()
    assert result_level(results["stopped by operator"]) == LEVEL_INFO
    assert result_text(results["stopped by operator"]) == "运动到临时点：已由操作员停止。"
    assert "operator" in results["stopped by operator"].message  # the English stays for logs and CLI
    assert result_level(results["unconfirmed"]) == LEVEL_WARNING
    assert result_level(results["stopped by controller"]) == LEVEL_ERROR
    assert result_level(results["ok"]) == LEVEL_INFO


def _errors() -> list[TeachPadError]:
    reconnect = LinkError("cannot reconnect", code="connection_refused",
                          params={"port": 502, "endpoint": ENDPOINT, "reconnect": True})
    violation = EnvelopeViolation(ViolationCode.KEEP_IN, 1250.0, 1200.0, axis="X", segment=2)
    return [
        LinkError("lost", params={"endpoint": ENDPOINT}),
        LinkError("not connected"),
        LinkError("closed", code="link_closed", params={"endpoint": ENDPOINT}),
        LinkError("dns", code="host_unresolved", params={"host": "192.168.1.10"}),
        LinkError("refused", code="connection_refused", params={"port": 502, "endpoint": ENDPOINT,
                                                                 "reconnect": False}),
        reconnect,
        LinkError("timeout", code="connect_timeout", params={"seconds": 1.0}),
        LinkError("os", code="connect_failed", params={"errno": 113}),
        LinkError("serial", code="serial_open_failed", params={"port": "COM3"}),
        ResponseTimeout("no answer", params={"seconds": 1.0, "endpoint": ENDPOINT}),
        ResponseTimeout("no answer"),
        MalformedResponse("bad", field="CRC", expected=0x1234, got=0x4321),
        MalformedResponse("bad", field="function", expected=3, got=0x83),
        MalformedResponse("bad", field="length", expected=9, got=4),
        ModbusExceptionError(3, 2, "illegal data address"),
        ModbusExceptionError(3, 0x55, "exception 85"),
        WriteBlocked("monitor-only mode: write to GV291 was not sent"),
        InvalidInput("speed must be positive"),
        CommandTimeout("no ack", code="not_acknowledged", params={"command": 0x42, "seconds": 1.0}),
        AlarmRaised(int(Alarm.ESTOP | Alarm.SERVO), "alarm", params={"command": 0x80}),
        EnvelopeRefused(violation, "move"),
        EnvelopeRefused(EnvelopeViolation(ViolationCode.KEEP_OUT, 10.0, 0.0, axis="Z", box="夹具")),
        EnvelopeRefused(EnvelopeViolation(ViolationCode.JOINT_LIMIT, 181.0, 170.0, axis="J1")),
        EnvelopeRefused(EnvelopeViolation(ViolationCode.SPEED, 500.0, 250.0, reduced=True)),
        EnvelopeRefused(EnvelopeViolation(ViolationCode.JOG_RATIO, 80.0, 30.0)),
        EnvelopeRefused(EnvelopeViolation(ViolationCode.KEEP_IN, 1190.0, 1200.0, axis="Y", approaching=True)),
    ]


def test_every_error_kind_reads_in_chinese(zh: None) -> None:
    for error in _errors():
        assert_chinese(error_text(error))
        worker_error = WorkerError.from_exception(Operation.JOG, error, 7)
        assert worker_error.message == str(error)  # English beside the reason
        assert worker_error.request_id == 7
        assert error_text(worker_error) == error_text(error)
    assert error_text(_errors()[5]) == ("无法重新连接控制器 192.168.1.10:502："
                                        "连接被拒绝：端口 502 上没有服务在监听。")


def test_an_error_without_a_reason_falls_back_to_its_message(zh: None) -> None:
    assert error_text(WorkerError(Operation.STOP, "stop: sent")) == "stop: sent"
    unexpected = WorkerError.from_exception(Operation.POLL, RuntimeError("boom"))
    assert unexpected.reason == Reason("unexpected", {"type": "RuntimeError"})
    assert_chinese(error_text(unexpected))


def test_the_english_stays_plain_for_the_cli() -> None:
    error = CommandRefused(CommandStatus(CommandKind.MOVE, 13), params={"command": 0x42})
    assert error.as_reason().code == "command_refused"
    assert "bad end point id" in str(error)


def test_the_codes_the_worker_and_the_cli_use_read_in_chinese(zh: None) -> None:
    from ui.messages import operation_text

    reasons = [
        Reason("sent", {"command": int(RunCommand.STEP_BASE)}),
        Reason("no_motion", {"command": int(RunCommand.RUN_PROGRAM), "seconds": 2.0}),
        Reason("program_not_started", {"program": 99}),
        Reason("upload_done", {"uploaded": 3, "total": 5}),
        Reason("busy", {"operation": Operation.UPLOAD_POINTS}),
        Reason("link_shut_down"),
        Reason("not_connected"),
        *(Reason("request_done", {"operation": op})
          for name, op in vars(Operation).items() if name.isupper()),
    ]
    for reason in reasons:
        assert_chinese(error_text(reason))
    for name, op in vars(Operation).items():
        if name.isupper():
            assert_chinese(operation_text(op))
    assert error_text(Reason("request_done", {"operation": Operation.STOP})) == "停止：已发送。"
