"""Link statistics: what the wire did, counted by the transport, shown by the GUI and the CLI."""

from __future__ import annotations

from dataclasses import asdict, dataclass

__all__ = ["LinkStats"]


@dataclass(frozen=True, slots=True)
class LinkStats:
    """A snapshot of the counters of one client since it was made."""

    requests: int = 0  # requests sent
    answers: int = 0  # answers that passed every check and became values
    timeouts: int = 0  # requests the controller did not answer in time (silence)
    malformed: int = 0  # answers that did not match their request (never used as values)
    exceptions: int = 0  # Modbus exception answers
    link_errors: int = 0  # connection refused / lost / OS errors
    resyncs: int = 0  # times the link was dropped and reopened (or flushed) to get back in step
    reconnects: int = 0  # times the link was opened again after its first connection
    last_error: str = ""

    def as_dict(self) -> dict[str, int | str]:
        return asdict(self)
