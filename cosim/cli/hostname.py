"""Where ``cosim run`` listens (``--live-host``, ``--unity-host``): checked, then bound to.

A value is an IPv4 or IPv6 address, or a host name as RFC 1123 allows one (letters, digits
and hyphens in dot-separated labels, the last one not all digits: ``999.1.1.1`` is a
mistyped address, not a name). Before the run, the address must resolve and belong to
this machine, so that a wrong host is blamed on ``--live-host`` and not on the port; and
no two of the run's servers may be given one port (:func:`check_ports`), which the
second would find taken and blame on another program.
"""

from __future__ import annotations

import argparse
import ipaddress
import itertools
import re
import socket
from typing import NamedTuple

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


class Listener(NamedTuple):
    """One server of a run, as its flags give it.

    Attributes:
        what: what listens (``the live view``).
        port_flag: the flag of its port (``--live-port``).
        host: the address it binds (a host name or an IP address).
        port: its TCP port (0: any free port).
    """

    what: str
    port_flag: str
    host: str
    port: int


WILDCARDS = frozenset({"0.0.0.0", "::"})
"""Addresses that bind every interface (``::`` takes IPv4 too, as Linux binds it)."""


def _addresses(host: str) -> set[str]:
    try:
        found = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError):
        return {host}  # :func:`check_live_host` names a host that does not resolve
    return {str(info[4][0]) for info in found}


def _overlap(one: str, other: str) -> bool:
    """Whether servers bound to ``one`` and ``other`` on one port would clash."""
    first, second = _addresses(one), _addresses(other)
    return bool(first & second or (first | second) & WILDCARDS)


def run_listeners(args: argparse.Namespace) -> list[Listener]:
    """The servers ``cosim run``'s flags ask for: the live view and the Unity endpoint."""
    listeners = []
    if args.live:
        listeners.append(Listener("the live view", "--live-port", args.live_host, args.live_port))
    if args.unity:
        listeners.append(
            Listener("the Unity endpoint", "--unity-port", args.unity_host, args.unity_port)
        )
    return listeners


def check_ports(*listeners: Listener) -> None:
    """Refuse two servers of one run given the same port (0, any free port, never clashes).

    Raises:
        ConfigError: one line naming both port flags, the port and the addresses.
    """
    for one, other in itertools.combinations(listeners, 2):
        if one.port == other.port != 0 and _overlap(one.host, other.host):
            where = (
                f"on {one.host}" if one.host == other.host else f"on {one.host} and {other.host}"
            )
            raise ConfigError(
                f"{one.port_flag} {one.port} and {other.port_flag} {other.port} name the same "
                f"port: {one.what} and {other.what} cannot both listen on it ({where}); "
                "expected two different ports (0: any free one)"
            )
