"""Every result and error kind reads as a Chinese sentence in the zh_CN UI (ui/messages.py).

Results come from the real :class:`CommandTracker` fed status reads; errors are the typed
errors the client and the transport raise. With the shipped .qm installed, no English word may
remain: only units, register names, numbers, "Modbus", host:port and the like.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator

from app.errors import (
    AlarmRaised,
    CommandRefused,
    CommandTimeout,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ManualModeRefused,
    ModbusExceptionError,
    Reason,
    ReducedSpeedRefused,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.tracker import CommandTracker
from app.link.types import Operation, WorkerError
from app.models import CommandResult, ControllerStatus
from app.plan.checks import IssueCode
from app.plan.issue_kind import IssueKind
from app.points.point import FileFormatError
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
# what may stay ASCII in a Chinese sentence: units, register, protocol, format and product names, numbers,
# addresses
ALLOWED = re.compile(
    r"\d+(\.\d+)+:\d+|Modbus|TeachPad|TCP|RTU|CRC|UTF-8|Unicode|CSV|JSON|GV\d+|COM\d+|"
    r"mm/s|mm|\bs\b|\b[XYZABC]\b|\bJ\d+\b|\bP\d+\b|0x[0-9A-Fa-f]+"
)


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


def _status(
    code: int, mode: int = ControllerMode.MODBUS_TEACH, state: int = ProgramState.STOPPED, alarms: int = 0
) -> ControllerStatus:
    return ControllerStatus(mode, state, Alarm(alarms), code)


def _tracked(
    command: RunCommand, *reads: ControllerStatus, pre: int = 0, stop: bool = False, rule: str = "observe"
) -> CommandResult:
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
        assert now < 60.0, "a stop the controller reported never ended the command"
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
    assert set(codes.values()) >= {
        "done",
        "done_by_mode",
        "command_refused",
        "alarm_while_waiting",
        "not_acknowledged",
        "done_unconfirmed",
        "refused_unconfirmed",
        "stopped_by_operator",
        "stopped_by_controller",
        "command_timeout",
    }
    for result in results.values():
        assert_chinese(result_text(result))
    assert result_text(results["unconfirmed"]) == "创建临时点：已完成，控制器未确认。"
    assert "急停" in result_text(results["alarm while waiting"])
    assert "\u2014" not in result_text(results["alarm while waiting"])  # one sentence, no tail


def test_refused_with_every_status_of_every_kind_reads_in_chinese(zh: None) -> None:
    commands = {
        CommandKind.MOVE: RunCommand.MOVE_TO_POINT,
        CommandKind.CREATE_POINT: RunCommand.CREATE_POINT,
        CommandKind.TEACH: RunCommand.TEACH_ENABLE,
    }
    for kind, table in _STATUS_TEXT.items():
        for code in [*table, 200, STATUS_SENTINEL]:
            error = CommandRefused(CommandStatus(kind, code), params={"command": int(commands[kind])})
            result = CommandResult(
                commands[kind], kind, CommandStatus(kind, code), False, str(error), reason=error.as_reason()
            )
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
    reconnect = LinkError(
        "cannot reconnect",
        code="connection_refused",
        params={"port": 502, "endpoint": ENDPOINT, "reconnect": True},
    )
    violation = EnvelopeViolation(ViolationCode.KEEP_IN, 1250.0, 1200.0, axis="X", segment=2)
    return [
        LinkError("lost", params={"endpoint": ENDPOINT}),
        LinkError("not connected"),
        LinkError("closed", code="link_closed", params={"endpoint": ENDPOINT}),
        LinkError("dns", code="host_unresolved", params={"host": "192.168.1.10"}),
        LinkError(
            "refused",
            code="connection_refused",
            params={"port": 502, "endpoint": ENDPOINT, "reconnect": False},
        ),
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
        ManualModeRefused("go to zero", 0),
        ManualModeRefused("run program", 7),  # a mode the table does not know: not named
        ReducedSpeedRefused("go to zero"),
    ]


def test_every_error_kind_reads_in_chinese(zh: None) -> None:
    for error in _errors():
        assert_chinese(error_text(error))
        worker_error = WorkerError.from_exception(Operation.JOG, error, 7)
        assert worker_error.message == str(error)  # English beside the reason
        assert worker_error.request_id == 7
        assert error_text(worker_error) == error_text(error)
    assert error_text(_errors()[5]) == (
        "无法重新连接控制器 192.168.1.10:502：连接被拒绝：端口 502 上没有服务在监听。"
    )


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
        *(
            Reason("request_done", {"operation": op})
            for name, op in vars(Operation).items()
            if name.isupper()
        ),
    ]
    for reason in reasons:
        assert_chinese(error_text(reason))
    for name, op in vars(Operation).items():
        if name.isupper():
            assert_chinese(operation_text(op))
    assert error_text(Reason("request_done", {"operation": Operation.STOP})) == "停止：已发送。"


# --- the link's state, the plan's checks and the ledger's refusals (issue 9) -----------------------
def test_the_link_states_and_cut_short_commands_read_in_chinese(zh: None) -> None:
    from app.link.types import ConnectionState, LinkState
    from ui.messages import connection_text

    states = [
        ConnectionState(
            LinkState.NOT_ANSWERING,
            "no answer",
            ENDPOINT,
            reason=ResponseTimeout("no answer", params={"seconds": 0.2, "endpoint": ENDPOINT}).as_reason(),
        ),
        ConnectionState(
            LinkState.DOWN, "link lost: x", ENDPOINT, reason=Reason("link_lost", {"endpoint": ENDPOINT})
        ),
        ConnectionState(LinkState.DOWN, "link lost: x", ENDPOINT, reason=Reason("link_lost")),
        ConnectionState(LinkState.DOWN, "cannot reconnect", ENDPOINT, reason=_errors()[5].as_reason()),
        ConnectionState(
            LinkState.DISCONNECTED, "the link was shut down", ENDPOINT, reason=Reason("link_was_shut_down")
        ),
    ]
    for state in states:
        assert_chinese(connection_text(state))
    assert connection_text(ConnectionState(LinkState.CONNECTED)) == ""
    assert connection_text(ConnectionState(LinkState.DOWN, "older producer")) == "older producer"
    for code in ("outcome_unknown_link_lost", "outcome_unknown_link_closed"):
        result = CommandResult(
            None,
            None,
            None,
            False,
            "move to point: link lost",
            reason=Reason(code, {"operation": Operation.MOVE_TO_POINT}),
        )
        assert_chinese(result_text(result))
    for code in ("queued_link_down", "queued_link_closed"):  # requests the link never sent
        error = WorkerError(
            Operation.MOVE_TO_POINT,
            "not sent",
            7,
            reason=Reason(code, {"operation": Operation.MOVE_TO_POINT}),
        )
        assert_chinese(error_text(error))


def _plan_issues() -> list[Any]:
    """At least one issue of every code, from the real checks (and the reach check's wording)."""
    from app.plan.checks import PlanIssue, check_plan
    from app.plan.segments import Plan, Segment, SegmentKind
    from app.points.ledger import PointLedger
    from app.points.point import SyncState, make_point
    from app.safety.envelope import Envelope, EnvelopeRefused
    from app.view3d.agreement import ModelAgreement, model_issue
    from app.view3d.kinematics import Reach
    from app.view3d.reach import _issue

    on = SyncState.ON_CONTROLLER
    ledger = PointLedger(
        [
            make_point(1, "原点", (400, 0, 450, 180, 0, 0), sync=on),
            make_point(5, "西", (300, 0, 300, 180, 0, 0), sync=on),
            make_point(6, "北", (400, 100, 300, 180, 0, 0), sync=on),
            make_point(7, "东", (500, 0, 300, 180, 0, 0), sync=on),
            make_point(8, "南", (400, -100, 300, 180, 0, 0), sync=on),
            make_point(9, "中", (400, 0, 300, 180, 0, 0), sync=on),
            make_point(10, "又西", (300, 0, 300.05, 180, 0, 0), sync=on),
            make_point(11, "新", (350, 50, 300, 180, 0, 0), sync=SyncState.CHANGED),
            make_point(13, "工具点", (450, 50, 300, 180, 0, 0), tool=0, sync=on),
        ]
    )
    home = (400.0, 0.0, 450.0)
    circle = Plan("圆", [Segment.line(5, 100), Segment.arc(6, 7, 50), Segment.arc(8, 5, 50)])
    wrap = Plan("环", [Segment.arc(9, 7), Segment.line(5)], loops=3)
    issues: list[PlanIssue] = [
        *check_plan(Plan("空"), ledger),
        *check_plan(wrap, ledger, current_pose=ledger.point(6), start_index=2),
        *check_plan(
            Plan("p", [Segment.line(5, 0), Segment.arc(99, 7), Segment.line(42), Segment.line(11)]),
            ledger,
            current_pose=home,
        ),
        *check_plan(Plan("p", [Segment.line(1), Segment.line(13)]), ledger, current_pose=home),
        *check_plan(Plan("p", [Segment.arc(9, 7)]), ledger),
        *check_plan(Plan("p", [Segment.line(5), Segment.arc(9, 7)]), ledger, current_pose=home),
        *check_plan(wrap, ledger, current_pose=ledger.point(6)),
        *check_plan(Plan("p", [Segment.line(5), Segment.arc(10, 7)]), ledger, current_pose=home),
        *check_plan(Plan("p", [Segment.line(5), Segment.arc(7, 5)]), ledger, current_pose=home),
        *check_plan(Plan("p", [Segment.line(7), Segment(SegmentKind.ARC, 6)]), ledger, current_pose=home),
        *check_plan(circle, ledger, current_pose=(470.7, 70.7, 300, 180, 0, 0), start_index=1),
        *check_plan(circle, ledger, current_pose=(520.0, -40.0, 300, 180, 0, 0), start_index=1),
        *check_plan(  # reduced-speed mode: a segment faster than its cap runs at the cap (a warning)
            Plan("p", [Segment.line(5, 400)]),
            ledger,
            current_pose=home,
            envelope=Envelope(),
            reduced_speed=True,
        ),
    ]
    violation = EnvelopeViolation(ViolationCode.KEEP_OUT, 10.0, 0.0, axis="Z", box="夹具", segment=1)
    issues += [
        PlanIssue(
            1,
            IssueKind.ERROR,
            IssueCode.OUTSIDE_ENVELOPE,
            violation.message,
            args=EnvelopeRefused(violation).as_reason().args,
        ),
        _issue(0, Reach.UNREACHABLE, "P5 西", 5),
        _issue(1, Reach.UNREACHABLE, "the path", None),
        _issue(0, Reach.JOINT_LIMIT, "P5 西", 5),
        _issue(1, Reach.JOINT_LIMIT, "the path", None),
        # the robot model against the controller: off in position, in orientation, in both
        model_issue(ModelAgreement("长前臂", 200.0, 0.2)),
        model_issue(ModelAgreement("长前臂", 1.0, 3.5)),
        model_issue(ModelAgreement("长前臂", 12.0, 2.0)),
    ]
    return issues


def test_every_plan_check_reads_in_chinese(zh: None) -> None:
    from ui.messages_plan import issue_line, issue_text

    issues = _plan_issues()
    assert {i.code for i in issues} == set(IssueCode), "an issue code is not covered"
    keys = set()
    for issue in issues:
        text = issue_text(issue)
        assert text != issue.message, f"{issue.code}: no wording for {dict(issue.args)}"
        assert_chinese(text)
        assert_chinese(issue_line(issue))
        variant = ("role", "pair", "past_middle", "from")
        keys.add((issue.code, tuple(sorted(str(issue.args[k]) for k in variant if k in issue.args))))
    assert len(keys) >= 18  # the variants: both roles, the three pairs, past / larger, both contexts
    missing = next(i for i in issues if i.code is IssueCode.MISSING_POINT)
    assert issue_text(missing) == "第 2 段：中间点 P99 不存在。"


def test_the_plan_checks_stay_english_for_the_cli() -> None:
    from app.plan.presenter import run_gate, summarize_checks

    issues = _plan_issues()
    summary = summarize_checks(issues)
    first = next(i for i in issues if i.is_error and i.segment is not None)
    assert summary.first_row_error == first.message and first.message.startswith("segment ")
    assert summary.details.split("\n")[0] == str(issues[0])
    warnings = run_gate(issues).warnings
    assert (
        warnings
        and warnings == tuple(i.message for i in issues if i.kind is IssueKind.WARNING)[: len(warnings)]
    )


def test_the_ledgers_refusals_read_in_chinese(zh: None) -> None:
    from app.points.fields import PointLimits
    from app.points.ledger import PointLedger
    from app.points.ledger_import import EmptyImport, ImportMode
    from app.points.point import make_point
    from ui.messages import refusal_text

    ledger = PointLedger([make_point(1, "一", (0, 0, 0, 0, 0, 0)), make_point(2, "二", (1, 0, 0, 0, 0, 0))])
    point = make_point(2, "二", (1, 0, 0, 0, 0, 0))
    attempts: list[Callable[[], object]] = [
        lambda: ledger.point(99),
        lambda: ledger.set_sync(99, ledger[0].sync),
        lambda: ledger.remove_rows([7]),
        lambda: ledger.move(0, 5),
        lambda: ledger.replace_all([point, point]),
        lambda: ledger.import_points([point, point], ImportMode.MERGE),
        lambda: ledger.import_points([]),
        lambda: ledger.set_limits(PointLimits(id_min=5, id_max=10)),
        lambda: PointLedger(
            [make_point(1, "一", (0, 0, 0, 0, 0, 0))], PointLimits(id_min=1, id_max=1)
        ).next_free_id(),
        lambda: ledger.replace(0, make_point(2, "一", (0, 0, 0, 0, 0, 0))),
    ]
    codes = set()
    for attempt in attempts:
        with pytest.raises(InvalidInput) as caught:
            attempt()
        codes.add(caught.value.code)
        assert_chinese(refusal_text(caught.value))
        assert re.search("[a-z]{3}", str(caught.value))  # English for logs and the CLI
    assert codes == {
        "no_such_point",
        "no_such_row",
        "cannot_move_row",
        "duplicate_row_id",
        "import_duplicate_id",
        "empty_import",
        "points_outside_range",
        "no_free_point_id",
        "point_id_taken",
    }
    assert isinstance(EmptyImport(3), InvalidInput)
    assert refusal_text(InvalidInput("speed must be positive")) == "speed must be positive"  # no code: as is


def _without_quoted(text: str) -> str:
    """A refusal without the operator's own quoted input and the column names it quotes."""
    return re.sub(r"'[^']*'|“[^”]*”", "", text)


def test_a_points_fields_and_files_refusals_read_in_chinese(zh: None) -> None:
    from app.points.csv_io import decode_text, parse_points_csv
    from app.points.fields import FieldError
    from app.points.point import FileFormatError, make_point
    from ui.messages import refusal_text

    fields: list[Callable[[], object]] = [
        lambda: make_point(1, "一", ("abc", 0, 0, 0, 0, 0)),
        lambda: make_point(1, "一", ("", 0, 0, 0, 0, 0)),
        lambda: make_point(1, "一", ("1e999", 0, 0, 0, 0, 0)),
        lambda: make_point(1, "一", ("inf", 0, 0, 0, 0, 0)),
        lambda: make_point("1.5", "一"),
        lambda: make_point(100000, "一"),
        lambda: make_point(1, "一", tool=500),
        lambda: make_point(1, 5),
        lambda: make_point(1, "一" * 300),
        lambda: make_point(1, "一\n二"),
    ]
    codes = set()
    for attempt in fields:
        with pytest.raises(FieldError) as caught:
            attempt()
        codes.add(caught.value.code)
        assert_chinese(_without_quoted(refusal_text(caught.value)))
    assert codes >= {
        "not_a_number",
        "value_empty",
        "too_large",
        "not_finite",
        "not_integer",
        "id_out_of_range",
        "bad_tool",
        "not_text",
        "too_long",
        "not_one_line",
    }
    header = "id,name,x,y,z,a,b,c"
    files = [
        "",
        "id,名字\n",
        "id,id,x\n",
        "id,name,x,y\n",
        f"{header}\n1,一,0,0\n",
        f"{header}\n1,一,abc,0,0,0,0,0\n",
        f"{header}\n1,一,0,0,0,0,0,0\n1,二,0,0,0,0,0,0\n",
    ]
    problems = set()
    for text in files:
        with pytest.raises(FileFormatError) as refused:
            parse_points_csv(text, path="/data/点位.csv")
        assert refused.value.problem is not None, str(refused.value)
        problems.add(refused.value.problem.code)
        shown = refusal_text(refused.value)
        assert shown.startswith("点位.csv：") and "/data" not in shown
        columns = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
        assert_chinese(_without_quoted(shown).replace(columns, "").replace("点位.csv", "点位"))
    assert problems == {
        "empty_file",
        "unknown_column",
        "column_twice",
        "column_missing",
        "cell_count",
        "not_a_number",
        "row_id_taken",
    }
    with pytest.raises(FileFormatError) as bad_bytes:
        decode_text(b"\xff\xfe1", path="p.csv")
    assert_chinese(refusal_text(bad_bytes.value).replace("p.csv", ""))
    # a problem without a code is shown whole in English, never half translated
    bare = FileFormatError("expected a JSON object at the top level", path="a.teachpad.json")
    assert refusal_text(bare) == str(bare)


# --- project files, segment edits, the jog, unreadable files (issue 9, words2) ---------------------
def _project_texts() -> list[str]:
    """One malformed project per problem code (and per place) the loader names."""
    import json

    sample = json.loads(
        (Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json").read_text(
            encoding="utf-8"
        )
    )

    def changed(edit: Callable[[dict[str, Any]], None]) -> str:
        doc = json.loads(json.dumps(sample))
        edit(doc)
        return json.dumps(doc, ensure_ascii=False)

    def point(key: str, value: object) -> Callable[[dict[str, Any]], None]:
        return lambda d: d["points"][1].__setitem__(key, value)

    def segment(key: str, value: object, plan: int = 0, seg: int = 0) -> Callable[[dict[str, Any]], None]:
        return lambda d: d["plans"][plan]["segments"][seg].__setitem__(key, value)

    def delete(key: str) -> Callable[[dict[str, Any]], None]:
        return lambda d: d["plans"][0]["segments"][0].pop(key)

    return [
        '{"format": ',
        "[1, 2]",
        "[" * 100000,
        changed(lambda d: d.__setitem__("format", "other")),
        changed(lambda d: d.__setitem__("version", 7)),
        changed(lambda d: d.__setitem__("points", {})),
        changed(lambda d: d.__setitem__("plans", "none")),
        changed(lambda d: d.__setitem__("name", 5)),
        changed(lambda d: d["points"].__setitem__(0, 5)),
        changed(point("x", "abc")),
        changed(point("id", sample["points"][0]["id"])),
        changed(point("uploaded", [1])),
        changed(point("uploaded", {"time": 5, "endpoint": ""})),
        changed(lambda d: d["plans"].__setitem__(0, [])),
        changed(lambda d: d["plans"][1].__setitem__("name", d["plans"][0]["name"])),
        changed(lambda d: d["plans"][0].__setitem__("name", "")),
        changed(lambda d: d["plans"][0].__setitem__("loops", 10**7)),
        changed(lambda d: d["plans"][0].__setitem__("segments", {})),
        changed(lambda d: d["plans"][0]["segments"].__setitem__(0, 1)),
        changed(delete("end")),
        changed(segment("type", "circle")),
        changed(segment("orientation", "sideways")),
        changed(segment("ignore_middle", "maybe")),
        changed(segment("end", -3)),
        changed(segment("via", 2)),
        changed(lambda d: d["points"][1].__setitem__("name", "\ud800")),
    ]


def test_a_malformed_project_reads_in_chinese(zh: None) -> None:
    from app.points.project import parse_project
    from ui.messages import refusal_text

    problems, places = set(), set()
    for text in _project_texts():
        with pytest.raises(FileFormatError) as refused:
            parse_project(text, path="/data/工程.teachpad.json")
        error = refused.value
        assert error.problem is not None, str(error)
        problems.add(error.problem.code)
        places.add(error.place.code if error.place is not None else None)
        shown = refusal_text(error)
        assert shown.startswith("工程.teachpad.json：") and "/data" not in shown, shown
        left = _without_quoted(shown).replace("工程.teachpad.json", "")
        assert_chinese(re.sub(r"\[[\d, ]*\]", "", left))
        assert str(error).startswith("/data/")  # the English whole for logs and the CLI
    assert problems >= {
        "not_json",
        "not_json_object",
        "json_too_deep",
        "not_a_project",
        "version_unsupported",
        "expected_type",
        "not_a_number",
        "point_id_twice",
        "plan_name_taken",
        "plan_name_empty",
        "bad_loops",
        "value_missing",
        "not_segment_kind",
        "not_orientation",
        "not_yes_no",
        "negative_point_id",
        "line_has_no_middle",
        "bad_character",
    }
    assert places >= {
        None,
        "place_file",
        "place_line",
        "place_point",
        "place_point_id",
        "place_point_upload",
        "place_plan",
        "place_plan_named",
        "place_segment",
        "place_json_path",
    }


def test_segment_jog_and_unreadable_file_codes_read_in_chinese(zh: None, tmp_path: Path) -> None:
    from app.plan.segments import Plan, Segment
    from app.points.csv_io import parse_points_csv
    from app.points.project import load_project
    from ui.messages import os_error_text, refusal_text

    refusals: list[Callable[[], object]] = [
        lambda: Plan("p", [Segment.line(1), Segment.line(2)]).move(0, 9),
        lambda: Segment.line(1).with_field("colour", 1),
        lambda: Segment.line(1).get("colour"),
        lambda: Plan("p").rename("a\nb"),
        lambda: parse_points_csv('id,name,x,y,z,a,b,c\n1,"a,0,0,0,0,0,0\n'),
        lambda: load_project(tmp_path / "nothing.teachpad.json"),
        lambda: load_project(tmp_path),
    ]
    codes = set()
    for attempt in refusals:
        with pytest.raises(InvalidInput) as caught:
            attempt()
        error = caught.value
        codes.add(error.problem.code if isinstance(error, FileFormatError) and error.problem else error.code)
        assert_chinese(
            _without_quoted(refusal_text(error))
            .replace(str(tmp_path), "")
            .replace("nothing.teachpad.json", "")
            .replace(tmp_path.name, "")
        )
    assert codes == {
        "cannot_move_segment",
        "no_such_field",
        "plan_name_format",
        "not_csv",
        "no_such_file",
        "is_a_directory",
    }
    codes_args: list[tuple[str, dict[str, Any]]] = [
        ("arc_needs_middle", {}),
        ("segment_point_missing", {"id": 7}),
        ("speed_not_positive", {"speed": "0"}),
        ("arc_same_points", {}),
        ("file_too_large", {"size": 9, "limit": 8}),
        ("permission_denied", {}),
        ("os_error", {"errno": 28}),
        ("jog_stopped_silent", {}),
        ("left_teach_mode", {"mode": int(ControllerMode.MANUAL)}),
        ("jog_not_answering", {}),
        ("bad_jog_ratio", {"value": "120"}),
    ]
    for code, args in codes_args:
        assert_chinese(error_text(Reason(code, args)))
    assert_chinese(os_error_text("a", PermissionError(13, "Permission denied")).replace("a：", "："))
    assert_chinese(os_error_text("a", OSError(28, "No space left on device")).replace("a：", "："))


def test_a_robot_model_that_disagrees_reads_in_words(zh: None) -> None:
    from app.view3d.agreement import ModelAgreement, model_issue
    from ui.messages_plan import issue_text

    assert issue_text(model_issue(ModelAgreement("arm B", 312.4, 0.1))) == (
        "机器人模型\u201carm B\u201d与控制器的位姿相差 312 mm：可达性检查可能有误。"
    )
    assert "相差 3.5°" in issue_text(model_issue(ModelAgreement("arm B", 0.5, 3.5)))


# Codes rendered elsewhere (a file's place: ui/messages_files.py, the CLI's own) or generic.
_NOT_A_SENTENCE = re.compile(r"place_\w+|file_format|error|envelope_unchecked|jog_guard_stopped|not_kept")
_SAMPLE_ARGS: dict[str, Any] = {
    "command": int(RunCommand.MOVE_TO_POINT),
    "operation": "jog",
    "program": 7,
    "seconds": 2.0,
    "status": 13,
    "alarms": int(Alarm.ESTOP | Alarm.SERVO),
    "axis": "J1",
    "value": 1.5,
    "endpoint": ENDPOINT,
    "exception": 11,
    "mode": int(ControllerMode.MANUAL),
    "field": "unit id",
}


def _codes_the_core_uses() -> set[str]:
    """Every reason code app/ (the CLI's own folder aside) gives an error or a result."""
    found: set[str] = set()
    app = Path(__file__).resolve().parents[2] / "app"
    pattern = re.compile(r'\bcode\s*=\s*"([a-z_0-9]+)"|Reason\(\s*"([a-z_0-9]+)"')
    for path in app.rglob("*.py"):
        if path.parent.name == "cli":
            continue
        for match in pattern.finditer(path.read_text(encoding="utf-8")):
            found.add(next(group for group in match.groups() if group))
    return {code for code in found if not _NOT_A_SENTENCE.fullmatch(code)}


def test_every_code_the_core_uses_reads_in_chinese(zh: None) -> None:
    """A scan, not a list: a code added to the core without its Chinese sentence fails here (no
    English word of three letters or more inside the Chinese, units and names aside)."""
    import string

    from ui import messages
    from ui.messages import reason_text

    codes = _codes_the_core_uses() | {"refused_alarm", "alarm_while_waiting"}  # (app/link/watch.py's pair)
    assert {"no_motion", "program_not_started", "zero_already", "cancelled_by_stop"} <= codes
    wrong = []
    for code in sorted(codes):
        args = dict(_SAMPLE_ARGS)
        template = messages._TEMPLATES.get(code) or messages._BARE.get(code) or ""
        for _literal, name, _spec, _conv in string.Formatter().parse(template):
            if name and name not in args:
                args[name] = "1"
        text = reason_text(Reason(code, args))
        left = ALLOWED.sub("", text or "")
        if text is None or re.search(r"[A-Za-z]{3,}", left) or not re.search(r"[\u4e00-\u9fff]", text):
            wrong.append(f"{code}: {text!r}")
    assert wrong == [], "\n".join(wrong)
