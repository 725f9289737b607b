"""The live view's address: checked as typed (``--live-host``), then bound to before the run."""

from __future__ import annotations

import argparse
import socket

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.cli.hostname import (
    EXPECTED,
    NAME_CHARS,
    Listener,
    check_live_host,
    check_ports,
    host_argument,
    is_host,
    run_listeners,
)
from cosim.core.errors import ConfigError


@pytest.mark.parametrize(
    "text",
    [
        "127.0.0.1",
        "0.0.0.0",
        "::1",
        "fe80::1",
        "localhost",
        "localhost.",
        "robot-1.lab.example.org",
        "a",
        "x1",
        "1x",
        "a" * 63,
    ],
)
def test_addresses_and_well_formed_host_names_are_hosts(text):
    assert is_host(text)


@pytest.mark.parametrize(
    "text",
    [
        "",
        ".",
        "999.1.1.1",  # a mistyped address, not a name: the last label is all digits
        "10.0.0",
        "-robot",
        "robot-",
        "a..b",
        "under_score",
        "two words",
        "a" * 64,  # a label of more than 63 characters
        "http://localhost",
        "localhost:8765",
    ],
)
def test_mistyped_addresses_and_malformed_names_are_not_hosts(text):
    assert not is_host(text)


def test_a_name_longer_than_253_characters_is_not_a_host_even_of_valid_labels():
    name = ".".join(["a" * 63] * 4)  # 255 characters
    assert len(name) > NAME_CHARS and not is_host(name)
    assert is_host(name[: NAME_CHARS - 1].rstrip("."))


_LABEL = st.from_regex(r"[a-z0-9]([a-z0-9-]{0,20}[a-z0-9])?", fullmatch=True)


@settings(max_examples=60, deadline=None)
@given(
    labels=st.lists(_LABEL, min_size=1, max_size=5),
    last=st.from_regex(r"[a-z]{1,8}", fullmatch=True),
)
def test_any_name_of_dotted_labels_ending_in_letters_is_a_host(labels, last):
    assert is_host(".".join([*labels, last]))


@settings(max_examples=100, deadline=None)
@given(text=st.text(max_size=300))
def test_any_typed_text_is_accepted_or_refused_in_one_line_naming_it(text):
    if is_host(text):
        assert host_argument(text) == text
        return
    with pytest.raises(argparse.ArgumentTypeError) as refused:
        host_argument(text)
    message = str(refused.value)
    assert message == f"{text!r} is not an address; expected {EXPECTED}"
    assert "\n" not in message


def test_this_machine_s_loopback_address_and_name_can_be_listened_on():
    check_live_host("127.0.0.1")
    check_live_host("localhost")


def test_an_address_of_another_machine_is_refused_naming_the_flag_and_the_value():
    with pytest.raises(ConfigError) as refused:
        check_live_host("192.0.2.1", "--unity-host")  # TEST-NET-1: no machine's address
    message = str(refused.value)
    assert message.startswith("--unity-host '192.0.2.1': cannot listen on 192.0.2.1 (")
    assert message.endswith(
        "expected an address of this machine (127.0.0.1, 0.0.0.0 for every interface)"
    )


def test_a_name_that_does_not_resolve_is_refused_naming_the_flag_value_and_reason(monkeypatch):
    def unknown(*_args, **_kwargs):
        raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")

    monkeypatch.setattr(socket, "getaddrinfo", unknown)
    with pytest.raises(ConfigError) as refused:
        check_live_host("no-such-host.invalid")
    assert str(refused.value) == (
        "--live-host 'no-such-host.invalid': cannot resolve it (Name or service not known); "
        f"expected {EXPECTED}"
    )


def _server(host: str, port: int) -> socket.socket:
    family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
    return socket.create_server((host, port), family=family)  # as the Unity endpoint binds


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("127.0.0.1", "127.0.0.1"),
        ("127.0.0.1", "localhost"),
        ("0.0.0.0", "127.0.0.1"),
        ("127.0.0.1", "0.0.0.0"),
        ("127.0.0.1", "127.0.0.2"),
        ("127.0.0.1", "::1"),
        ("::1", "::1"),
    ],
)
def test_two_servers_on_one_port_are_refused_exactly_when_the_second_could_not_listen(
    first, second
):
    with _server(first, 0) as taken:
        port = taken.getsockname()[1]
        try:
            _server(second, port).close()
            clash = False
        except OSError:
            clash = True
    one = Listener("the live view", "--live-port", first, port)
    other = Listener("the Unity endpoint", "--unity-port", second, port)
    if not clash:
        check_ports(one, other)
        return
    with pytest.raises(ConfigError) as refused:
        check_ports(one, other)
    where = f"on {first}" if first == second else f"on {first} and {second}"
    assert str(refused.value) == (
        f"--live-port {port} and --unity-port {port} name the same port: the live view and "
        f"the Unity endpoint cannot both listen on it ({where}); expected two different ports "
        "(0: any free one)"
    )


def test_port_0_is_any_free_port_for_each_server_and_different_ports_never_clash():
    check_ports(Listener("a", "--a-port", "0.0.0.0", 0), Listener("b", "--b-port", "0.0.0.0", 0))
    check_ports(Listener("a", "--a-port", "0.0.0.0", 1), Listener("b", "--b-port", "0.0.0.0", 2))
    check_ports(Listener("a", "--a-port", "127.0.0.1", 5))  # one server alone


def test_every_interface_of_ipv6_counts_as_taking_ipv4_too():
    with pytest.raises(ConfigError, match=r"^--a-port 9 and --b-port 9 name the same port"):
        check_ports(Listener("a", "--a-port", "::", 9), Listener("b", "--b-port", "127.0.0.1", 9))


@pytest.mark.parametrize(
    ("live", "unity"), [(True, True), (True, False), (False, True), (False, False)]
)
def test_the_servers_of_a_run_are_those_its_flags_turn_on(live, unity):
    args = argparse.Namespace(
        live=live, live_host="0.0.0.0", live_port=9, unity=unity, unity_host="::1", unity_port=9
    )
    expected = [Listener("the live view", "--live-port", "0.0.0.0", 9)] * live + [
        Listener("the Unity endpoint", "--unity-port", "::1", 9)
    ] * unity
    assert run_listeners(args) == expected
