"""Is a host a valid IP address or host name? Checked before the resolver sees it.

A typo such as ``cell3..local`` (an empty label) or a label longer than 63 characters makes
Python's resolver raise ``UnicodeError`` (the IDNA codec), not ``socket.gaierror``: the
connection dialog refuses such a host in words before it is accepted, and
:class:`~app.link.streams.TcpStream` refuses it as a link error (teachpad-cli: exit 3).

:func:`host_problem` returns a code (None: fine); :data:`HOST_PROBLEMS` says each in words.
"""

from __future__ import annotations

import ipaddress
import re

__all__ = ["HOST_PROBLEMS", "MAX_HOST_LENGTH", "MAX_LABEL_LENGTH", "host_problem", "host_problem_text"]

MAX_HOST_LENGTH = 253  # characters of a whole host name (RFC 1035, without the trailing dot)
MAX_LABEL_LENGTH = 63  # characters of one label (between two dots)

# Letters, digits, hyphens (and underscores, which some local names carry); not starting or
# ending with a hyphen.
_LABEL = re.compile(r"^[A-Za-z0-9_](?:[A-Za-z0-9_-]*[A-Za-z0-9_])?$")

HOST_PROBLEMS: dict[str, str] = {
    "empty": "no host is given",
    "space": "it contains a space",
    "too_long": f"it is longer than {MAX_HOST_LENGTH} characters",
    "empty_label": "it has an empty part (two dots in a row, or a dot at the start)",
    "long_label": f"a part between two dots is longer than {MAX_LABEL_LENGTH} characters",
    "bad_character": "it contains a character a host name cannot have",
    "bad_hyphen": "a part between two dots starts or ends with a hyphen",
    "bad_ip": "it looks like an IP address but is not one",
}


def host_problem(host: str) -> str | None:
    """What is wrong with ``host`` as an IP address or host name (a key of :data:`HOST_PROBLEMS`),
    or None when it is fine. Non-ASCII names (IDN) are checked in their IDNA form."""
    if not host:
        return "empty"
    if any(c.isspace() for c in host):
        return "space"
    try:
        ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        pass
    else:
        return None
    name = host[:-1] if host.endswith(".") else host
    if not name.isascii():
        try:
            name = name.encode("idna").decode("ascii")
        except UnicodeError:
            return _label_problem(name.split(".")) or "bad_character"
    if len(name) > MAX_HOST_LENGTH:
        return "too_long"
    labels = name.split(".")
    problem = _label_problem(labels)
    if problem is not None:
        return problem
    if all(label.isdigit() for label in labels):
        return "bad_ip"  # 192.168.1.300, 10.0.1
    return None


def _label_problem(labels: list[str]) -> str | None:
    for label in labels:
        if not label:
            return "empty_label"
        if len(label) > MAX_LABEL_LENGTH:
            return "long_label"
    for label in labels:
        if label.isascii() and not _LABEL.match(label):
            return "bad_hyphen" if re.fullmatch(r"[A-Za-z0-9_-]+", label) else "bad_character"
    return None


def host_problem_text(host: str) -> str | None:
    """:func:`host_problem` in words, or None."""
    problem = host_problem(host)
    return None if problem is None else HOST_PROBLEMS[problem]
