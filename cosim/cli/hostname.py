"""The live view's address (``cosim run --live-host``): checked as typed, then bound to.

A value is an IPv4 or IPv6 address, or a host name as RFC 1123 allows one (letters, digits
and hyphens in dot-separated labels, the last one not all digits: ``999.1.1.1`` is a
mistyped address, not a name). Before the run, the address must resolve and belong to
this machine, so that a wrong host is blamed on ``--live-host`` and not on the port.
"""

from __future__ import annotations

import argparse
import ipaddress
import re
import socket

from cosim.core.errors import ConfigError

_LABEL = re.compile(r"[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?")
NAME_CHARS = 253
"""Longest host name (RFC 1035, without the trailing dot)."""
EXPECTED = "an IPv4 or IPv6 address (127.0.0.1, 0.0.0.0, ::1) or a host name (localhost)"


def is_host(text: str) -> bool:
    """Whether ``text`` is an IP address or a well-formed host name."""
    try:
        ipaddress.ip_address(text)
    except ValueError:
        pass
    else:
        return True
    name = text.removesuffix(".")
    if not name or len(name) > NAME_CHARS:
        return False
    labels = name.split(".")
    return all(_LABEL.fullmatch(label) for label in labels) and not labels[-1].isdigit()


def host_argument(text: str) -> str:
    """``--live-host``: an address or host name, else one line naming the value.

    Raises:
        argparse.ArgumentTypeError: naming the value and what was expected.
    """
    if not is_host(text):
        raise argparse.ArgumentTypeError(f"{text!r} is not an address; expected {EXPECTED}")
    return text


def check_live_host(host: str, flag: str = "--live-host") -> None:
    """Refuse a host flag's value that does not resolve or is not an address of this machine.

    Binds a socket to the address (any free port) and closes it; the live view's own port
    is tried later, when the run starts.

    Raises:
        ConfigError: one line naming ``flag`` (``--live-host``, ``--unity-host``), the value
            and what was expected.
    """
    try:
        found = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise ConfigError(
            f"{flag} {host!r}: cannot resolve it ({reason}); expected {EXPECTED}"
        ) from None
    family, _type, _proto, _name, address = found[0]
    try:
        with socket.socket(family, socket.SOCK_STREAM) as probe:
            probe.bind((address[0], 0, *address[2:]))
    except OSError as error:
        raise ConfigError(
            f"{flag} {host!r}: cannot listen on {address[0]} ({error.strerror or error}); "
            "expected an address of this machine (127.0.0.1, 0.0.0.0 for every interface)"
        ) from None
