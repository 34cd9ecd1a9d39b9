"""Files with secrets (issue 19 s5): the role store is owner-only (0600) from its creation on, not
chmod-ed after; the support bundle is written 0600 and redacts by value too (URLs with
credentials, keys named like auth, private_key, pin, license, cookie), logs included."""

from __future__ import annotations

import os
import stat
import zipfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from app.safety.bundle import REMOVED, write_support_bundle
from app.safety.roles import Role, RoleStore

pytestmark = pytest.mark.skipif(os.name != "posix", reason="file modes are POSIX")


@pytest.fixture
def modes_when_replaced(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[int]]:
    """The mode of each file at the moment it takes its final name (under a umask of 022)."""
    seen: list[int] = []
    replace = os.replace

    def spy(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        seen.append(stat.S_IMODE(os.stat(src).st_mode))
        replace(src, dst)

    monkeypatch.setattr("os.replace", spy)  # (the atomic writer's, and any other during the test)
    old = os.umask(0o022)
    try:
        yield seen
    finally:
        os.umask(old)


def test_the_role_store_is_owner_only_from_its_creation(
    tmp_path: Path, modes_when_replaced: list[int]
) -> None:
    path = tmp_path / "roles.json"
    store = RoleStore(path, scrypt_n=2**8)
    store.set_password(Role.ADMINISTRATOR, "s3cret-Pa55", by=Role.ADMINISTRATOR)
    assert modes_when_replaced == [0o600]  # never readable by others, not even for a moment
    assert stat.S_IMODE(path.stat().st_mode) == 0o600


SECRETS = {
    "url": "http://bob:url-pw-1@proxy.example:8080/",
    "auth": "auth-secret-2",
    "private_key": "pk-secret-3",
    "pin": "4711",
    "license": "LIC-secret-5",
    "cookie": "sid=cookie-secret-6",
    "Authorization": "Bearer bearer-secret-7",
    "mqtt": "mqtts://device:mqtt-pw-8@broker.example",
}
LOG_SECRETS = (
    "connect to https://admin:log-pw-9@10.0.0.5/api",
    "request header Authorization: Bearer log-bearer-10",
    "Cookie: session=log-cookie-11; theme=dark",
    "config loaded: api_key=log-key-12 pin=8812 host=10.0.0.5",
    '{"license": "log-lic-13", "port": 502}',
)
NOT_SECRET = ("10.0.0.5", "proxy.example:8080", "broker.example", "spin_speed", "author")


def test_the_support_bundle_is_owner_only_and_redacts_by_value(
    tmp_path: Path, modes_when_replaced: list[int]
) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "teachpad.log").write_text("\n".join(LOG_SECRETS) + "\n", encoding="utf-8")
    settings = {"site": {**SECRETS, "spin_speed": 3, "author": "line 2"}, "events": list(LOG_SECRETS)}
    out = tmp_path / "bundle.zip"
    write_support_bundle(out, settings=settings, log_dir=logs, events=LOG_SECRETS, traffic=LOG_SECRETS)
    assert modes_when_replaced == [0o600] and stat.S_IMODE(out.stat().st_mode) == 0o600
    with zipfile.ZipFile(out) as zf:
        everything = "\n".join(zf.read(name).decode("utf-8") for name in zf.namelist())
    planted = [
        "url-pw-1", "auth-secret-2", "pk-secret-3", "4711", "LIC-secret-5", "cookie-secret-6",
        "bearer-secret-7", "mqtt-pw-8", "log-pw-9", "log-bearer-10", "log-cookie-11", "log-key-12",
        "8812", "log-lic-13",
    ]  # fmt: skip
    leaked = [secret for secret in planted if secret in everything]
    assert leaked == []
    assert REMOVED in everything and all(word in everything for word in NOT_SECRET)
