"""HaltWatch, the policy of a write that stops motion until the controller confirms it
(app/link/halt.py), on an injected clock: what goes out when, and when it is over."""

from __future__ import annotations

from app.errors import ModbusExceptionError, ResponseTimeout
from app.link.halt import HaltWatch, HaltWrite, confirm_halt
from app.link.types import HaltKind, JogRequest, UnconfirmedHalt
from app.models import Pose
from app.protocol.enums import TeachFrame

SPEED_ZERO, STOP = HaltWrite.SPEED_ZERO, HaltWrite.STOP
JOG = JogRequest(TeachFrame.BASE, 2, 1, 10.0)
ESCALATE = 0.5
BUSY = ModbusExceptionError(0x10, 6, "busy")
ILLEGAL_ADDRESS = ModbusExceptionError(0x06, 2, "illegal data address")


def at(z: float) -> Pose:
    return Pose(500.0, 0.0, z, 180.0, 0.0, 0.0)


def release(now: float = 0.0) -> HaltWatch:
    return HaltWatch(HaltKind.RELEASE, JOG, now, escalate_after=ESCALATE)


def test_an_answered_release_is_over_at_the_second_still_pose_and_never_shown() -> None:
    halt = release()
    assert halt.due(0.0) == (SPEED_ZERO,)
    halt.took(SPEED_ZERO, 0.01)
    assert halt.due(0.02) == () and halt.state() is None
    assert not halt.pose_seen(at(600.0))  # the first pose after the answer
    assert halt.pose_seen(at(600.0))  # unchanged at the next poll: over
    assert halt.over and halt.due(10.0) == () and halt.state() is None


def test_a_refused_release_goes_out_at_every_poll_then_with_stop() -> None:
    halt = release()
    for now in (0.0, 0.1, 0.2, 0.3, 0.4):
        assert halt.due(now) == (SPEED_ZERO,)
        halt.refused(SPEED_ZERO, BUSY)
        assert not halt.pose_seen(at(600.0 + now))  # nothing answered: never over
    assert halt.state() == UnconfirmedHalt(HaltKind.RELEASE, 0.0, False)
    assert halt.due(ESCALATE) == (STOP, SPEED_ZERO)  # escalated: Stop first, speed 0 still
    assert halt.state() == UnconfirmedHalt(HaltKind.RELEASE, 0.0, True)
    halt.refused(STOP, BUSY)
    halt.took(SPEED_ZERO, 0.6)
    assert halt.due(0.7) == ()
    assert not halt.pose_seen(at(700.0)) and halt.pose_seen(at(700.0))


def test_answered_while_the_arm_keeps_moving_escalates_after_the_limit() -> None:
    halt = release()
    halt.took(SPEED_ZERO, 0.0)
    assert not halt.pose_seen(at(600.0))
    assert not halt.pose_seen(at(601.0))  # moved after the answer
    assert halt.due(0.3) == ()
    assert halt.due(0.5) == (STOP, SPEED_ZERO)
    assert halt.escalated and halt.answered_at is None


def test_the_guard_escalates_at_once_unless_answered_and_standing() -> None:
    halt = release()
    halt.refused(SPEED_ZERO, BUSY)
    assert halt.escalate() and halt.due(0.05) == (STOP, SPEED_ZERO)
    answered = release()
    answered.took(SPEED_ZERO, 0.0)
    assert not answered.escalate()  # answered, not seen moving since: the guard leaves it


def test_a_refusal_for_good_is_not_sent_again_and_a_release_goes_on_with_stop() -> None:
    halt = release()
    halt.refused(SPEED_ZERO, ILLEGAL_ADDRESS)
    assert halt.due(0.01) == (STOP,)
    halt.refused(STOP, ILLEGAL_ADDRESS)
    assert halt.due(0.02) == () and halt.given_up and halt.unconfirmed


def test_no_answer_is_tried_again_like_busy() -> None:
    halt = HaltWatch(HaltKind.STOP, None, 0.0, escalate_after=ESCALATE)
    assert halt.due(0.0) == (STOP,)
    halt.refused(STOP, ResponseTimeout("no answer"))
    assert halt.due(0.1) == (STOP,) and not halt.given_up


def test_after_a_silence_the_controller_gets_speed_0_first() -> None:
    halt = release()
    halt.silent = True
    assert halt.state() is not None  # said while silent
    halt.answering_again(5.0)
    assert halt.due(5.0) == (SPEED_ZERO,)
    assert halt.due(5.0 + ESCALATE) == (STOP, SPEED_ZERO)


def test_confirm_halt_retries_within_its_budget_and_says_when_it_could_not() -> None:
    clock = [0.0]
    sent: list[HaltWrite] = []
    refuse_until = 0.3

    def write(what: HaltWrite) -> None:
        sent.append(what)
        if clock[0] < refuse_until:
            raise BUSY

    def sleep(seconds: float) -> None:
        clock[0] += seconds

    halt = release()
    assert confirm_halt(
        write, lambda: at(600.0), halt, budget=5.0, interval=0.05, clock=lambda: clock[0], sleep=sleep
    )
    assert sent[0] is SPEED_ZERO and STOP not in sent  # taken before the escalation
    assert halt.refusals == len(sent) - 1

    refuse_until = 100.0
    clock[0], sent[:] = 0.0, []
    never = release()
    assert not confirm_halt(
        write, lambda: at(600.0), never, budget=2.0, interval=0.05, clock=lambda: clock[0], sleep=sleep
    )
    assert clock[0] >= 2.0 and STOP in sent and never.unconfirmed
    assert "did not confirm the jog's speed 0 and Stop (441)" in never.words(clock[0])


# --- a Pause the controller refused (HaltKind.PAUSE) ------------------------------------------------
PAUSE = HaltWrite.PAUSE
PAUSE_BOUND = 2.0


def pause_watch(now: float = 0.0) -> HaltWatch:
    return HaltWatch(HaltKind.PAUSE, None, now, escalate_after=PAUSE_BOUND)


def test_a_refused_pause_goes_out_at_every_poll_and_is_over_once_answered_and_still() -> None:
    halt = pause_watch()
    for now in (0.0, 0.5, 1.0, 1.5):
        assert halt.due(now) == (PAUSE,)  # never a speed 0, no Stop before the bound
        halt.refused(PAUSE, BUSY)
        assert not halt.pose_seen(at(600.0 + now)) and not halt.program_seen(False, False)
    assert halt.state() == UnconfirmedHalt(HaltKind.PAUSE, 0.0, False)
    halt.took(PAUSE, 1.6)
    assert halt.due(1.7) == ()
    assert not halt.pose_seen(at(700.0)) and halt.pose_seen(at(700.0))
    assert halt.paused and halt.state() is None


def test_a_pause_not_confirmed_within_the_bound_becomes_a_stop() -> None:
    halt = pause_watch()
    halt.refused(PAUSE, BUSY)
    assert halt.due(PAUSE_BOUND) == (STOP,)  # instead of the Pause, not beside it
    assert halt.state() == UnconfirmedHalt(HaltKind.PAUSE, 0.0, True)
    halt.took(STOP, 2.1)
    assert not halt.pose_seen(at(700.0)) and halt.pose_seen(at(700.0))
    assert halt.over and not halt.paused and halt.answered_by is STOP


def test_a_pause_refused_for_good_is_a_stop_at_once() -> None:
    halt = pause_watch()
    halt.refused(PAUSE, ILLEGAL_ADDRESS)
    assert halt.due(0.05) == (STOP,)
    halt.refused(STOP, ILLEGAL_ADDRESS)
    assert halt.given_up  # nothing left that could halt the arm


def test_a_pause_is_over_when_the_program_reads_paused_or_ended_and_still() -> None:
    paused = pause_watch()
    paused.refused(PAUSE, ResponseTimeout("no answer"))  # it may have been carried out
    assert paused.program_seen(True, False) and paused.paused
    ended = pause_watch()
    ended.refused(PAUSE, BUSY)
    assert not ended.program_seen(False, True)  # stopped: over once the pose is still
    assert not ended.pose_seen(at(600.0)) and ended.pose_seen(at(600.0))
    assert ended.over and not ended.paused
    moving = pause_watch()
    moving.refused(PAUSE, BUSY)
    moving.program_seen(False, True)
    assert not moving.pose_seen(at(600.0)) and not moving.pose_seen(at(610.0))  # still moving
