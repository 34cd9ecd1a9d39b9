"""Seeded random mutations of correct answers, sent by the HostileServer to a RobotClient.

``python -m tests.link.hostile.fuzz [frames] [seed]`` prints the figures for both framings.

Each request (a read of 1..125 registers, a 0x06 or a 0x10 write) is answered with its correct
frame mutated once: a bit flipped or a byte replaced in a checked field, the frame cut short,
bytes appended, inserted or deleted, the frame replaced by random bytes, or sent twice. The
server hangs up after each answer (so a cut-short frame ends at once instead of after the
timeout) and the client closes its end too: each frame is tried on a fresh link. Modbus TCP
has no checksum: a changed register value inside a read's data is a well-formed answer, so
over TCP the register data of a read is left alone; over RTU the CRC covers it, and every byte
is fair game.
"""

from __future__ import annotations

import random
import sys
import time
from dataclasses import dataclass
from typing import Any

from app.connection import ConnectionSettings
from app.errors import MalformedResponse, TeachPadError
from app.link.client import RobotClient
from tests.link.hostile.server import Answer, Framing, HostileServer, Reply

_CONTROL = range(440, 446)


@dataclass
class FuzzFigures:
    framing: str
    frames: int = 0  # answers sent
    identical: int = 0  # mutations that happened to give back the correct frame
    accepted_identical: int = 0  # ... and were taken as the (correct) value
    accepted_mutated: int = 0  # mutated answers taken as values (must be 0)
    wrong_values: int = 0  # accepted answers whose values are not the server's (must be 0)
    malformed: int = 0  # refused as MalformedResponse
    other_errors: int = 0  # refused otherwise (a hang-up before the first byte: LinkError)
    resyncs: int = 0
    reconnects: int = 0
    seconds: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def mutate(rng: random.Random, answer: Answer) -> bytes:
    frame = answer.correct
    # Over TCP a read's register data has no checksum: only MBAP, function and byte count.
    tcp_read = answer.framing == "tcp" and answer.function == 0x03
    checked = range(0, 9) if tcp_read else range(len(frame))
    op = rng.randrange(8)
    if op == 0:  # flip a bit
        at = rng.choice(checked)
        return frame[:at] + bytes([frame[at] ^ (1 << rng.randrange(8))]) + frame[at + 1 :]
    if op == 1:  # replace a byte
        at = rng.choice(checked)
        return frame[:at] + bytes([rng.randrange(256)]) + frame[at + 1 :]
    if op == 2:  # cut short
        return frame[: rng.randrange(1, len(frame))]
    if op == 3:  # bytes appended
        return frame + rng.randbytes(rng.randint(1, 4))
    if op == 4:  # a byte inserted
        at = rng.randrange(len(frame) + 1) if answer.framing == "rtu" else rng.choice(checked)
        return frame[:at] + bytes([rng.randrange(256)]) + frame[at:]
    if op == 5:  # a byte deleted
        at = rng.randrange(len(frame))
        return frame[:at] + frame[at + 1 :]
    if op == 6:  # random bytes
        return rng.randbytes(rng.randint(1, len(frame) + 4))
    return frame + frame  # answered twice


def _request(rng: random.Random, client: RobotClient, server: HostileServer) -> tuple[Any, list[int]]:
    """Send a random request; (result, the values the server holds for it afterwards)."""
    kind = rng.randrange(3)
    if kind == 0:
        count = rng.randint(1, 125)
        address = rng.randrange(0, 2000)
        return client.read_registers(address, count), server.registers[address : address + count]
    if kind == 1:
        address = rng.choice([rng.randrange(0, 440), rng.randrange(446, 2000)])
        value = rng.randrange(0x10000)
        client.write_register(address, value)
        return None, []
    count = rng.randint(1, 10)
    address = rng.randrange(446, 2000)
    client.write_registers(address, [rng.randrange(0x10000) for _ in range(count)])
    return None, []


def run(framing: Framing, frames: int, seed: int) -> FuzzFigures:
    rng = random.Random(seed)
    figures = FuzzFigures(framing)
    with HostileServer(framing) as server:
        server.default = lambda a: Reply(mutate(rng, a), close=True)
        settings = ConnectionSettings(
            port=server.port, framer="rtu" if framing == "rtu" else "socket", timeout=1.0
        )
        client = RobotClient(settings)
        t0 = time.monotonic()
        try:
            for _ in range(frames):
                try:
                    result, expected = _request(rng, client, server)
                except MalformedResponse:
                    figures.malformed += 1
                    outcome = "refused"
                except TeachPadError:
                    figures.other_errors += 1
                    outcome = "refused"
                else:
                    outcome = "accepted"
                    if result is not None and result != expected:
                        figures.wrong_values += 1
                client.close()  # the server hung up: the next frame on a fresh link
                assert server.last is not None
                correct, sent = server.last
                figures.frames += 1
                if sent == correct:
                    figures.identical += 1
                    figures.accepted_identical += outcome == "accepted"
                elif outcome == "accepted":
                    figures.accepted_mutated += 1
        finally:
            figures.seconds = time.monotonic() - t0
            figures.resyncs = client.stats.resyncs
            figures.reconnects = client.stats.reconnects
            client.close()
    return figures


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    framing_: Framing
    for framing_ in ("tcp", "rtu"):
        print(run(framing_, n, seed).as_dict())
