"""Every client command against a relay that misbehaves on one chosen request: the judge.

For each command of :class:`~app.link.client.RobotClient` (:data:`COMMANDS`: reads, writes, the
plain commands, the four functions, go to zero, run program, a jog, an upload) and each request
it makes (by index: the relay counts them), one misbehaviour (:data:`MISBEHAVIOURS`: a wrong
function code, byte count, write echo, transaction id, an exception code, silence, a hang-up, a
late answer to the request before...) is aimed at that request, the command runs on a fresh
client, and :func:`judge` says whether what it returned is right:

* **success** only when every write of the command got its own well-formed answer (a write that
  did not is acceptable only when the command sent it again and that one was answered: an
  upload's busy retry), no misbehaving answer was taken as an answer (the transport's count of
  answers is at most the answers relayed as they were), and a read returns the simulator's values;
  a read that failed and was read again is fine (reads change nothing);
* otherwise a **clear error** (a :class:`~app.errors.TeachPadError` with words) or a failed
  result; when a motion's trigger (440 / 445) went out and its answer was not its confirmation,
  the outcome is *unknown* (:func:`app.link.outcome.outcome_of`, the audit's and the GUI's word),
  never *refused* or *done*; an exception answer counts as a refusal only when its code says
  the request was not carried out (1, 2, 3, 6, 0x0A);
* and never past **twice its budget** (its clean run's time plus one request timeout plus
  ``timing.OUTCOME_READ_BUDGET``).

The deterministic tests (tests/link/hostile/test_commands.py) run every (command, request,
misbehaviour); ``python -m tests.link.hostile.command_fuzz`` runs random ones for a long time.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

from app.connection import ConnectionSettings
from app.errors import OutcomeUnknown, TeachPadError
from app.link.client import RobotClient
from app.link.outcome import Outcome, outcome_of
from app.link.types import StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, TeachFrame, WorkMode
from tests.link.hostile.relay import Exchange, HostileRelay, Later, Misbehaviour
from tests.link.hostile.server import Answer, Reply

# -- misbehaviours -----------------------------------------------------------------------------


def _word(pdu: bytes, at: int, delta: int) -> bytes:
    (value,) = struct.unpack_from(">H", pdu, at)
    return pdu[:at] + struct.pack(">H", (value + delta) & 0xFFFF) + pdu[at + 2 :]


def _framed(change: Callable[[Answer], bytes]) -> Misbehaviour:
    return lambda a, _prev: Reply(a.frame(change(a)))


def _wrong_function(a: Answer) -> bytes:
    other = {0x03: 0x04, 0x06: 0x10, 0x10: 0x06}[a.function]
    return bytes([other]) + a.pdu[1:]


def _wrong_size(a: Answer) -> bytes:
    """A read: its byte count 2 more (and 2 bytes more data); a write: its echo's second word
    (the 0x06's value, the 0x10's quantity) one off."""
    if a.function == 0x03:
        return bytes([0x03, a.pdu[1] + 2]) + a.pdu[2:] + b"\x00\x00"
    return _word(a.pdu, 3, 1)


def exception_answer(code: int) -> Misbehaviour:
    """A well-formed exception answer with ``code``."""
    return _framed(lambda a: bytes([a.function | 0x80, code]))


def _late(a: Answer, previous: bytes) -> Reply:
    """The answer to the request before comes now (late), then this one's."""
    return Reply(previous + a.correct)


def _late_apart(a: Answer, previous: bytes) -> Reply:
    """The answer to the request before, alone, and this one's a moment later."""
    return Later(previous, then=a.correct)


def _stale_only(a: Answer, previous: bytes) -> Reply:
    """Only the answer to the request before (this one's never comes)."""
    return Reply(previous or a.correct[:3])


def _cut_then_close(a: Answer, _prev: bytes) -> Reply:
    return Reply(a.correct[: len(a.correct) // 2], close=True)


#: name -> what the client gets instead of the answer
MISBEHAVIOURS: dict[str, Misbehaviour] = {
    "function code": _framed(_wrong_function),
    "byte count or echo value": _framed(_wrong_size),
    "echo address": _framed(lambda a: _word(a.pdu, 1, 1) if a.function != 0x03 else a.pdu[:1] + b"\x00"),
    "transaction id +1": lambda a, _p: Reply(a.frame(tid=a.tid + 1)),
    "late answer first": _late,
    "late answer, then the own": _late_apart,
    "stale answer only": _stale_only,
    "answered twice": lambda a, _p: Reply(a.correct + a.correct),
    "bytes after it": lambda a, _p: Reply(a.correct + b"\x00\x01\x02"),
    "exception 2 (illegal address)": exception_answer(2),
    "exception 4 (device failure)": exception_answer(4),
    "exception 5 (acknowledge)": exception_answer(5),
    "exception 6 (busy)": exception_answer(6),
    "exception 0x0B (gateway target)": exception_answer(0x0B),
    "exception 0x37 (unknown code)": exception_answer(0x37),
    "exception 0 (no code)": exception_answer(0),
    "exception of another function": _framed(lambda a: bytes([(a.function ^ 0x13) | 0x80, 2])),
    "hang-up, no answer": lambda a, _p: Reply(None, close=True),
    "half an answer, hang-up": _cut_then_close,
    "silence": lambda a, _p: Reply(None),
}
#: Misbehaviours that cost a whole request timeout: aimed at fewer requests in the fast tests.
SLOW = frozenset({"silence", "stale answer only"})

#: Exception codes that say the request was not carried out (a refusal may be said "refused").
NOT_CARRIED_OUT = frozenset({1, 2, 3, 6, 0x0A})

# -- the commands ----------------------------------------------------------------------------

TRIGGERS = (registers.REG_RUN_COMMAND, registers.REG_GO_ZERO)
POINT = 7
POSE = (400.0, 0.0, 500.0, 180.0, 0.0, 0.0)


@dataclass(frozen=True)
class Command:
    """A client call: how to set the simulator up for it (directly, not through the relay), the
    call, and whether it moves (its trigger's unconfirmed answer must make it *unknown*)."""

    name: str
    call: Callable[[RobotClient], Any]
    motion: bool = False
    setup: Callable[[Any], None] = lambda sim: None
    expect: Callable[[Any, Any], str] = lambda sim, value: ""  # "" or what is wrong with a success


def _follow(client: RobotClient, start: Callable[[], Any], *, until_started: bool = False) -> Any:
    return client.follow(start(), until_started=until_started)


def _jog(c: RobotClient) -> CommandResult:
    result = c.teach_enable(TeachFrame.JOINT, 0, 1)
    c.teach_set_ratio(5.0)
    c.teach_set_ratio(0.0)
    return c.teach_disable() if result.ok else result


def _direct(sim: Any) -> RobotClient:
    """A client straight to the simulator (not through the relay)."""
    return RobotClient(ConnectionSettings(port=sim.port, framer=sim.config.framer, timeout=5.0))


def _registers_read(sim: Any, value: Any) -> str:
    with _direct(sim) as direct:
        expected = direct.read_registers(100, 10)
    return "" if value == expected else f"read {value}, the simulator holds {expected}"


def _gv_written(sim: Any, value: Any) -> str:
    with _direct(sim) as direct:
        got = direct.read_gv(60, 2)
    return "" if got == [1.5, -2.25] else f"GV60..61 hold {got} after a write said done"


def _off_zero(sim: Any) -> None:
    sim.set_joint(1, 0.5)


def _with_point(sim: Any) -> None:
    """A temp point 2 mm from where the arm is (the move takes a few polls, not seconds)."""
    x, y, z, a, b, c = sim.state().pose
    sim.add_point(POINT, (x + 2.0, y, z, a, b, c))


def _upload(c: RobotClient) -> list[CommandResult]:
    return c.upload_points([(POINT, POSE), (POINT + 1, (410.0, 0.0, 500.0, 180.0, 0.0, 0.0))])


COMMANDS: dict[str, Command] = {
    c.name: c
    for c in (
        Command("read_status", lambda c: c.read_status()),
        Command("read_pose", lambda c: c.read_pose()),
        Command("read_registers", lambda c: c.read_registers(100, 10), expect=_registers_read),
        Command("write_gv", lambda c: c.write_gv(60, [1.5, -2.25]), expect=_gv_written),
        Command("set_work_mode", lambda c: c.set_work_mode(WorkMode.AUTO)),
        Command("stop", lambda c: c.stop()),
        Command("pause", lambda c: c.pause()),
        Command("resume", lambda c: c.resume()),
        Command("step", lambda c: c.step(StepFrame.BASE, [1.0, 0, 0, 0, 0, 0], speed=200.0), motion=True),
        Command("create_point", lambda c: c.create_point(POINT, pose=POSE), motion=True),
        Command(
            "move_to_point", lambda c: c.move_to_point(POINT, speed=500.0), motion=True, setup=_with_point
        ),
        Command("go_zero", lambda c: _follow(c, lambda: c.go_zero(0)), motion=True, setup=_off_zero),
        Command(
            "run_program",
            lambda c: _follow(c, lambda: c.run_program(2, ProgramMotionMode.SINGLE_RUN), until_started=True),
            motion=True,
        ),
        Command("jog", _jog, motion=True),
        Command("upload_points", _upload, motion=True),
    )
}

# -- running one case and judging it ---------------------------------------------------------


@dataclass
class Run:
    """What one call did: its value or error, its time, the relay's exchanges, the link's counts."""

    value: Any
    error: BaseException | None
    seconds: float
    exchanges: list[Exchange]
    answers: int  # the transport's accepted answers
    delivered: bool  # the misbehaviour met its request


def run_case(
    sim: Any, relay: HostileRelay, command: Command, aims: dict[int, tuple[str, Misbehaviour]], timeout: float
) -> Run:
    sim.restart_controller()
    command.setup(sim)
    framer: Literal["socket", "rtu"] = "rtu" if relay.framing == "rtu" else "socket"
    client = RobotClient(ConnectionSettings(port=relay.port, framer=framer, timeout=timeout))
    try:
        client.connect()
        relay.arm(aims)
        t0 = time.monotonic()
        value: Any = None
        error: BaseException | None = None
        try:
            value = command.call(client)
        except TeachPadError as exc:
            error = exc
        seconds = time.monotonic() - t0
        return Run(value, error, seconds, relay.exchanges(), client.stats.answers, relay.delivered)
    finally:
        client.close()


def _succeeded(run: Run) -> bool:
    if run.error is not None:
        return False
    values = run.value if isinstance(run.value, list) else [run.value]
    return all(v.ok for v in values if isinstance(v, CommandResult))


def _unconfirmed_writes(exchanges: list[Exchange]) -> list[Exchange]:
    """Writes whose answer was not their own and that were not sent again and answered."""
    out = []
    for i, ex in enumerate(exchanges):
        if not ex.is_write or ex.answered_correctly:
            continue
        again = any(
            later.is_write
            and (later.function, later.address, later.count_or_value)
            == (ex.function, ex.address, ex.count_or_value)
            and later.answered_correctly
            for later in exchanges[i + 1 :]
        )
        if not again and not _probe_refused(ex) and not _staging_refused(ex):
            out.append(ex)
    return out


def _probe_refused(ex: Exchange) -> bool:
    """The completion probe's GV291 write refused with a code that says GV291 cannot be written:
    the command goes on with the observe rule (app/link/command_client.py), rightly."""
    gv291 = registers.gv_reg(registers.GV_COMMAND_STATUS)
    code = _exception_code(ex)
    return ex.address == gv291 and code in (1, 2, 3)


def _staging_refused(ex: Exchange) -> bool:
    """An upload's staging write (the next point's pose into the spare block, GV6.., registers
    12..23) refused: the upload writes that pose again into the first block after the result
    (app/link/client.py upload_points), so the refused one is never used."""
    return ex.address == registers.gv_reg(6) and _exception_code(ex) is not None


def _exception_code(ex: Exchange) -> int | None:
    """The code of the well-formed exception answer ``ex`` got (None: it got something else)."""
    sent = ex.sent or b""
    pdu = sent[7:] if ex.framing == "tcp" else sent[1:-2]
    return pdu[1] if len(pdu) == 2 and pdu[0] == ex.function | 0x80 and pdu[1] else None


def _outcome(run: Run) -> Outcome | None:
    if isinstance(run.error, OutcomeUnknown):
        return Outcome.UNKNOWN
    if isinstance(run.error, TeachPadError):
        result = CommandResult(None, None, None, False, str(run.error), reason=run.error.as_reason())
        return outcome_of(result)
    values = run.value if isinstance(run.value, list) else [run.value]
    for v in values:
        if isinstance(v, CommandResult) and not v.ok:
            return outcome_of(v)
    return None


def judge(command: Command, run: Run, budget: float, sim: Any) -> list[str]:
    """What is wrong with ``run`` (empty: right). See the module docstring."""
    wrong: list[str] = []
    if run.seconds > 2 * budget:
        wrong.append(f"took {run.seconds:.2f} s, more than twice its budget {budget:.2f} s")
    relayed_as_is = sum(1 for ex in run.exchanges if ex.sent is not None and ex.correct in ex.sent)
    if run.answers > relayed_as_is:
        wrong.append(f"{run.answers} answers taken, only {relayed_as_is} relayed as they were")
    if _succeeded(run):
        unconfirmed = _unconfirmed_writes(run.exchanges)
        if unconfirmed:
            what = ", ".join(
                f"#{ex.index} {ex.function:#04x}@{ex.address} ({ex.aimed})" for ex in unconfirmed
            )
            wrong.append(f"success although the write(s) {what} got no answer of their own")
        problem = command.expect(sim, run.value)
        if problem:
            wrong.append(problem)
        return wrong
    if run.error is not None and not str(run.error).strip():
        wrong.append(f"an error without words: {type(run.error).__name__}")
    # the last trigger the command sent (an upload's busy retry sends one again) ended it when
    # its answer was not its confirmation (a late answer before its own, over TCP, is dropped)
    triggers = [ex for ex in run.exchanges if ex.function == 0x06 and ex.address in TRIGGERS]
    last = triggers[-1] if triggers else None
    if command.motion and last is not None and last.aimed and not last.answered_correctly:
        code = _exception_code(last)
        refusal = code is not None and code in NOT_CARRIED_OUT
        outcome = _outcome(run)
        later = any(ex.aimed and ex.index > last.index for ex in run.exchanges)
        if refusal and outcome is not Outcome.REFUSED and not (later and outcome is Outcome.UNKNOWN):
            # (a refusal, then the retry's write got no answer of its own: unknown is the safe word)
            wrong.append(f"the trigger was refused (exception {code}) but the outcome reads {outcome}")
        elif not refusal and outcome is not Outcome.UNKNOWN:
            wrong.append(f"the trigger went out unconfirmed ({last.aimed}) but the outcome reads {outcome}")
    return wrong
