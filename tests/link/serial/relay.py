"""A serial line between two pseudo-terminals, in Python (CI has no socat).

Two pty pairs: the simulator opens one slave device, the client the other; a thread copies
bytes between the two master sides, delivering them no faster than the baud rate would
(10 bits a byte, 8N1), and can corrupt a frame's CRC or put line noise before a request.

A noisy line: ``damage_one_in=N`` damages one byte in N on average, in both directions (each
byte passing the relay is damaged with probability 1/N, by a seeded ``random.Random``: the same
seed damages the same bytes of the same traffic), XOR-ing it with a non-zero value. Every damage
is counted (:attr:`PtyRelay.damaged`, by direction).
"""

from __future__ import annotations

import os
import random
import select
import threading
import time
import tty
from collections.abc import Callable


class PtyRelay:
    def __init__(self, baudrate: int, *, damage_one_in: int = 0, seed: int = 0) -> None:
        self.baudrate = baudrate
        self.damage_one_in = damage_one_in  # 0: a clean line
        self.damaged = {"request": 0, "answer": 0}  # bytes damaged so far, by direction
        self._random = random.Random(seed)
        self._sim_master, self._sim_slave = os.openpty()
        self._host_master, self._host_slave = os.openpty()
        for fd in (self._sim_slave, self._host_slave):
            tty.setraw(fd)  # no echo, no line discipline: bytes pass as they are
        self.sim_port = os.ttyname(self._sim_slave)
        self.host_port = os.ttyname(self._host_slave)
        self.corrupt_next_request = False
        self.corrupt_next_answer = False
        self.noise_before_next_request = b""
        # a request it returns True for has its answer's CRC corrupted (once each time it matches)
        self.corrupt_answer_to: Callable[[bytes], bool] | None = None
        self.drop_requests = False  # a controller gone silent: requests go nowhere
        self.noise_gap = 0.06  # s of silence between the noise and the request
        self.requests = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="pty-relay", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        for fd in (self._sim_master, self._sim_slave, self._host_master, self._host_slave):
            os.close(fd)

    def wire_time(self, nbytes: int) -> float:
        return nbytes * 10 / self.baudrate

    def _run(self) -> None:
        masters = [self._host_master, self._sim_master]
        while not self._stop.is_set():
            ready, _, _ = select.select(masters, [], [], 0.02)
            for fd in ready:
                try:
                    data = os.read(fd, 4096)
                except OSError:  # nobody has the other side open (yet)
                    time.sleep(0.005)
                    continue
                if fd == self._host_master:
                    self._forward_request(data)
                else:
                    self._forward(self._host_master, self._damage(self._corrupt_answer(data), "answer"))

    def _forward_request(self, data: bytes) -> None:
        self.requests += 1
        if self.drop_requests:
            return
        if self.corrupt_answer_to is not None and self.corrupt_answer_to(data):
            self.corrupt_next_answer = True
        if self.noise_before_next_request:
            self._forward(self._sim_master, self.noise_before_next_request)
            self.noise_before_next_request = b""
            time.sleep(self.noise_gap)
        if self.corrupt_next_request:
            self.corrupt_next_request = False
            data = data[:-1] + bytes([data[-1] ^ 0x5A])
        self._forward(self._sim_master, self._damage(data, "request"))

    def _damage(self, data: bytes, direction: str) -> bytes:
        """One byte in ``damage_one_in`` XOR-ed with a non-zero value (line noise)."""
        if not self.damage_one_in:
            return data
        out = bytearray(data)
        for i in range(len(out)):
            if self._random.randrange(self.damage_one_in) == 0:
                out[i] ^= self._random.randrange(1, 256)
                self.damaged[direction] += 1
        return bytes(out)

    def _corrupt_answer(self, data: bytes) -> bytes:
        if self.corrupt_next_answer:
            self.corrupt_next_answer = False
            return data[:-1] + bytes([data[-1] ^ 0x5A])
        return data

    def _forward(self, fd: int, data: bytes) -> None:
        time.sleep(self.wire_time(len(data)))  # the bytes take this long on a real line
        os.write(fd, data)
