"""Operator roles: who may do what, passwords as salted scrypt hashes, idle lock-back.

Three roles, each with everything of the one before: the **operator** jogs, steps, teaches,
runs plans and programs and reconnects to the controller of the last connection (its settings
unchanged); the **engineer** also edits points, plans and the envelope and changes the robot
model (it feeds the reach checks that block or allow a run); the **administrator** also changes
the connection (another controller, other settings), the register profile, roles and passwords.
:func:`permission_reason` answers the GUI's question "why is this control disabled?".

Passwords never touch the disk: :class:`RoleStore` keeps ``hashlib.scrypt`` hashes with a
random salt per password, compared in constant time (``hmac.compare_digest``). The operator
needs no password (the pendant starts as operator). The store is a JSON file in the user's
config directory, saved atomically with owner-only permissions.

:class:`IdleLock` is a clock-driven state machine: after ``idle_timeout`` seconds without
activity, the session falls back to operator.
"""

from __future__ import annotations

import enum
import json
import time
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path

from app.errors import InvalidInput, TeachPadError
from app.points.atomic import atomic_write_bytes, read_limited
from app.points.point import FileFormatError
from app.safety.location import safety_location

STORE_FORMAT = "teachpad-roles"
STORE_VERSION = 1
#: scrypt cost (n = 2**14, r = 8: ~16 MB, ~50 ms); stored per hash so it can grow later.
SCRYPT_N = 2**14
SCRYPT_R = 8
SCRYPT_P = 1
SALT_BYTES = 16
HASH_BYTES = 32
MIN_PASSWORD_LENGTH = 4
IDLE_TIMEOUT_DEFAULT = 300.0  # s without activity before the window locks back to operator


class Role(enum.IntEnum):
    OPERATOR = 0
    ENGINEER = 1
    ADMINISTRATOR = 2

    @property
    def text(self) -> str:
        return self.name.lower()

    @classmethod
    def parse(cls, text: str) -> Role:
        key = text.strip().lower()
        for role in cls:
            if role.text == key or (len(key) >= 3 and role.text.startswith(key)):
                return role
        raise InvalidInput(f"unknown role {text[:20]!r}: operator, engineer or administrator")


class Action(enum.Enum):
    """What a control does, for the permission table."""

    JOG = "jog"
    STEP = "step"
    TEACH = "teach"  # create / re-teach a temp point at the current pose
    RUN_PLAN = "run plan"
    RUN_PROGRAM = "run program"
    STOP = "stop"  # stop, pause, resume: always allowed
    REDUCED_SPEED = "reduced speed"  # switch reduced-speed mode on (off needs ENGINEER)
    EDIT_POINTS = "edit points"
    EDIT_PLANS = "edit plans"
    EDIT_ENVELOPE = "edit envelope"
    ROBOT_MODEL = "change robot model"  # the 3D view's robot model profile (reach checks)
    LEAVE_REDUCED_SPEED = "leave reduced speed"
    RECONNECT = "reconnect to the same controller"  # its last settings, unchanged
    CONNECTION = "change connection"
    REGISTER_PROFILE = "change register profile"
    MANAGE_ROLES = "manage roles and passwords"
    SUPPORT_BUNDLE = "write a support bundle"
    WRITE_REGISTERS = "write controller registers directly"  # teachpad-cli write: any GV, unchecked
    WRITE_WATCHED = "write a watched value"  # View -> Watch list: one GV / register, confirmed, audited


#: The least role that may do each action.
REQUIRED_ROLE: dict[Action, Role] = {
    Action.JOG: Role.OPERATOR,
    Action.STEP: Role.OPERATOR,
    Action.TEACH: Role.OPERATOR,
    Action.RUN_PLAN: Role.OPERATOR,
    Action.RUN_PROGRAM: Role.OPERATOR,
    Action.STOP: Role.OPERATOR,
    Action.REDUCED_SPEED: Role.OPERATOR,
    Action.SUPPORT_BUNDLE: Role.OPERATOR,
    Action.RECONNECT: Role.OPERATOR,
    Action.EDIT_POINTS: Role.ENGINEER,
    Action.EDIT_PLANS: Role.ENGINEER,
    Action.EDIT_ENVELOPE: Role.ENGINEER,
    Action.ROBOT_MODEL: Role.ENGINEER,
    Action.LEAVE_REDUCED_SPEED: Role.ENGINEER,
    Action.WRITE_WATCHED: Role.ENGINEER,
    Action.CONNECTION: Role.ADMINISTRATOR,
    Action.REGISTER_PROFILE: Role.ADMINISTRATOR,
    Action.MANAGE_ROLES: Role.ADMINISTRATOR,
    Action.WRITE_REGISTERS: Role.ADMINISTRATOR,
}


#: The **plant** role: a Sparkplug host application writing through ``teachpad-gateway`` (a DCMD).
#: Not a login role of the pendant (no password, not in :class:`Role`): it may do only the writes
#: named here, each only where an administrator enabled it for one robot (the cell file's
#: ``plant_writes``); nothing is enabled by default. Its audit records say ``plant (ROBOT)``.
PLANT_ROLE = "plant"
PLANT_WRITES: dict[str, Action] = {
    "program/run": Action.RUN_PROGRAM,
    "program/stop": Action.STOP,
    "speed_ratio": Action.RUN_PROGRAM,  # the program speed ratio (449)
}


def plant_reason(write: str, enabled: Collection[str]) -> str | None:
    """None when the plant may make ``write`` (it is one of :data:`PLANT_WRITES` and ``enabled``);
    else why not, in words."""
    if write not in PLANT_WRITES:
        return f"{write} is not a write the plant may make ({', '.join(PLANT_WRITES)})"
    if write not in enabled:
        return (
            f"{write} is not enabled for this robot "
            "(an administrator enables it in the cell file's plant_writes)"
        )
    return None


def allowed(role: Role, action: Action) -> bool:
    return role >= REQUIRED_ROLE[action]


def permission_reason(role: Role, action: Action) -> str | None:
    """None when ``role`` may do ``action``; else why not, for a disabled control's tooltip."""
    need = REQUIRED_ROLE[action]
    if role >= need:
        return None
    return f"{action.value}: needs the {need.text} role (logged in as {role.text})"


class RoleStoreError(TeachPadError):
    """The role store file cannot be read or written."""


class WrongPassword(TeachPadError):
    """A login with a wrong password, or for a role that has none set."""


def default_config_dir() -> Path:
    """The folder of the role store, the envelope and the register profile: machine-wide when an
    administrator made one, else the user's config folder (:mod:`app.safety.location`)."""
    return safety_location().config_dir


def default_store_path() -> Path:
    return safety_location().roles


@dataclass(frozen=True)
class PasswordHash:
    salt: bytes
    digest: bytes
    n: int = SCRYPT_N
    r: int = SCRYPT_R
    p: int = SCRYPT_P

    @classmethod
    def make(cls, password: str, *, n: int = SCRYPT_N) -> PasswordHash:
        import secrets  # (hashlib, hmac, secrets: imported by the first password, not at start-up)

        salt = secrets.token_bytes(SALT_BYTES)
        return cls(salt, _scrypt(password, salt, n, SCRYPT_R, SCRYPT_P), n)

    def matches(self, password: str) -> bool:
        import hmac

        return hmac.compare_digest(_scrypt(password, self.salt, self.n, self.r, self.p), self.digest)

    def to_dict(self) -> dict[str, object]:
        return {
            "scheme": "scrypt",
            "salt": self.salt.hex(),
            "hash": self.digest.hex(),
            "n": self.n,
            "r": self.r,
            "p": self.p,
        }

    @classmethod
    def from_dict(cls, data: object) -> PasswordHash:
        if not isinstance(data, dict) or data.get("scheme") != "scrypt":
            raise ValueError("not an scrypt hash")
        n, r, p = data.get("n"), data.get("r"), data.get("p")
        if not all(isinstance(v, int) and v > 0 for v in (n, r, p)):
            raise ValueError("bad scrypt parameters")
        assert isinstance(n, int) and isinstance(r, int) and isinstance(p, int)
        return cls(bytes.fromhex(str(data["salt"])), bytes.fromhex(str(data["hash"])), n, r, p)


def _scrypt(password: str, salt: bytes, n: int, r: int, p: int) -> bytes:
    import hashlib

    return hashlib.scrypt(
        password.encode("utf-8"), salt=salt, n=n, r=r, p=p, dklen=HASH_BYTES, maxmem=256 * 1024 * 1024
    )


class RoleStore:
    """Passwords of the engineer and administrator roles, on disk as salted scrypt hashes."""

    def __init__(self, path: Path | None = None, *, scrypt_n: int = SCRYPT_N) -> None:
        self.path = path or default_store_path()
        self.scrypt_n = scrypt_n  # tests may lower the cost
        self._hashes: dict[Role, PasswordHash] = {}
        self.idle_timeout = IDLE_TIMEOUT_DEFAULT
        if self.path.exists():
            self._load()

    def _load(self) -> None:
        try:
            doc = json.loads(read_limited(self.path, 1024 * 1024).decode("utf-8"))
        except (FileFormatError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RoleStoreError(
                f"the role store {self.path.name} cannot be read ({exc}); an "
                "administrator must restore or delete it"
            ) from None
        if not isinstance(doc, dict) or doc.get("format") != STORE_FORMAT:
            raise RoleStoreError(f"{self.path.name} is not a TeachPad role store")
        version = doc.get("version")
        if not isinstance(version, int) or version > STORE_VERSION:
            raise RoleStoreError(f"{self.path.name} was written by a newer TeachPad")
        roles = doc.get("passwords", {})
        if not isinstance(roles, dict):
            raise RoleStoreError(f"{self.path.name}: 'passwords' must be an object")
        for name, data in roles.items():
            try:
                role = Role.parse(str(name))
                self._hashes[role] = PasswordHash.from_dict(data)
            except (InvalidInput, ValueError, KeyError) as exc:
                raise RoleStoreError(
                    f"{self.path.name}: the entry for {str(name)[:20]!r} is damaged ({exc})"
                ) from None
        idle = doc.get("idle_timeout", IDLE_TIMEOUT_DEFAULT)
        if isinstance(idle, int | float) and not isinstance(idle, bool) and idle > 0:
            self.idle_timeout = float(idle)

    def save(self) -> None:
        doc = {
            "format": STORE_FORMAT,
            "version": STORE_VERSION,
            "idle_timeout": self.idle_timeout,
            "passwords": {role.text: h.to_dict() for role, h in sorted(self._hashes.items())},
        }
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # owner-only from its creation on (not chmod-ed after: readable by others meanwhile)
        atomic_write_bytes(self.path, (json.dumps(doc, indent=2) + "\n").encode("utf-8"), mode=0o600)

    def has_password(self, role: Role) -> bool:
        return role in self._hashes

    def set_password(self, role: Role, password: str, *, by: Role) -> None:
        """Set (and save) ``role``'s password; only an administrator may (the first one: anyone,
        while no administrator password exists yet)."""
        if role is Role.OPERATOR:
            raise InvalidInput("the operator role has no password")
        if by is not Role.ADMINISTRATOR and self.has_password(Role.ADMINISTRATOR):
            raise InvalidInput(permission_reason(by, Action.MANAGE_ROLES) or "not allowed")
        if len(password) < MIN_PASSWORD_LENGTH:
            raise InvalidInput(f"a password needs at least {MIN_PASSWORD_LENGTH} characters")
        self._hashes[role] = PasswordHash.make(password, n=self.scrypt_n)
        self.save()

    def clear_password(self, role: Role, *, by: Role) -> None:
        if by is not Role.ADMINISTRATOR:
            raise InvalidInput(permission_reason(by, Action.MANAGE_ROLES) or "not allowed")
        self._hashes.pop(role, None)
        self.save()

    def verify(self, role: Role, password: str) -> bool:
        """True when ``password`` is ``role``'s. Operator: always. No password set: False."""
        if role is Role.OPERATOR:
            return True
        stored = self._hashes.get(role)
        if stored is None:
            # spend the same time, so a missing password is not told apart by timing
            PasswordHash.make(password, n=self.scrypt_n)
            return False
        return stored.matches(password)

    def login(self, role: Role, password: str) -> Role:
        if not self.verify(role, password):
            if not self.has_password(role):
                raise WrongPassword(f"no password is set for the {role.text} role; an administrator sets it")
            raise WrongPassword(f"wrong password for the {role.text} role")
        return role


class IdleLock:
    """The session's role, falling back to operator after ``timeout`` s without activity.

    Drive it with :meth:`touch` on every user input and :meth:`poll` from a timer; the clock
    is injectable (``time.monotonic`` by default). ``on_lock`` is called once per lock-back.
    """

    def __init__(
        self,
        timeout: float = IDLE_TIMEOUT_DEFAULT,
        *,
        clock: Callable[[], float] = time.monotonic,
        on_lock: Callable[[Role], None] | None = None,
    ) -> None:
        if not timeout > 0:
            raise InvalidInput("the idle time must be > 0 s")
        self.timeout = timeout
        self._clock = clock
        self.on_lock = on_lock
        self._role = Role.OPERATOR
        self._last = clock()

    @property
    def role(self) -> Role:
        return self._role

    def login(self, role: Role) -> None:
        self._role = role
        self._last = self._clock()

    def logout(self) -> None:
        self._role = Role.OPERATOR

    def touch(self) -> None:
        self._last = self._clock()

    def remaining(self) -> float:
        """Seconds until the lock-back (inf as operator)."""
        if self._role is Role.OPERATOR:
            return float("inf")
        return max(0.0, self.timeout - (self._clock() - self._last))

    def poll(self) -> Role:
        """Lock back to operator when idle too long; returns the role now in force."""
        if self._role is not Role.OPERATOR and self._clock() - self._last >= self.timeout:
            previous = self._role
            self._role = Role.OPERATOR
            if self.on_lock is not None:
                self.on_lock(previous)
        return self._role
