"""The remote client's parts that need no bridge (``gaitd.remote``): endpoints, identities and
their client ids, encodings, event continuity, and what the Zenoh transport keeps of the samples
it is given."""

from __future__ import annotations

import ctypes
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

from gaitd import remote
from gaitd.remote import EventContinuity, RemoteClient, RemoteError, ZenohTransport
from gaitd.schema import DaemonState, Event, EventKind, FingerPhase, GoalState, Phase, ReasonCode, Status


def test_client_id_for_is_the_bridges() -> None:
    # The Rust crate's own vectors (gaitd_client::remote::protocol; "op" as the remote tests see it).
    assert remote.client_id_for("") == 0xFFD3_3721_A611_5632
    assert remote.client_id_for("op") == 0x9C7A_74C7_A516_0A35
    # FNV-1a of "gaitd-remote/dash" has its top bit clear: the id sets it.
    assert remote.client_id_for("dash") == 0xE8A1_984C_3066_EA42
    a = remote.client_id_for("operator-1")
    assert a == remote.client_id_for("operator-1") != remote.client_id_for("operator-2")
    assert a >> 63 == 1 and a < 1 << 64


@pytest.mark.parametrize(
    ("endpoint", "locator"),
    [
        ("quic/robot.lan:7460", ("quic/robot.lan:7460", "robot.lan:7460")),
        ("tls/10.0.0.2:7461", ("tls/10.0.0.2:7461", "10.0.0.2:7461")),
        ("robot.lan:7460", ("quic/robot.lan:7460", "robot.lan:7460")),
        ("quic/[::1]:7460", ("quic/[::1]:7460", "[::1]:7460")),
    ],
)
def test_parse_endpoint(endpoint: str, locator: tuple[str, str]) -> None:
    assert remote.parse_endpoint(endpoint) == locator


@pytest.mark.parametrize(
    ("endpoint", "why"),
    [
        ("tcp/robot.lan:7447", "only accepts quic/HOST:PORT or tls/HOST:PORT"),
        ("udp/robot.lan:7447", "only accepts"),
        ("quic/robot.lan", "expected quic/HOST:PORT"),
        ("quic/:7460", "expected"),
        ("quic/robot.lan:0", "expected"),
        ("quic/robot.lan:65536", "expected"),
        ("quic/robot.lan:74x", "expected"),
        ("quic/robot.lan:7460?x=1", "expected"),
    ],
)
def test_parse_endpoint_refuses(endpoint: str, why: str) -> None:
    with pytest.raises(RemoteError, match=why):
        remote.parse_endpoint(endpoint)


def test_encoding_of() -> None:
    assert remote.encoding_of(Status.type_name()) == "application/octet-stream;gaitd::Status.v8"


def test_event_continuity() -> None:
    """The Rust client's scenario (``gaitd_client::remote::continuity``)."""
    c = EventContinuity()
    assert c.accept(7, 444)
    assert c.accept(7, 445)
    # A bridge restart lost 446..=684; live events come on.
    assert c.accept(7, 685)
    assert c.missing() == 239
    assert c.holes() == [(7, 446, 684)]
    # Its cache fills part of it, with a repeat among them.
    assert c.accept(7, 600)
    assert not c.accept(7, 600)
    assert not c.accept(7, 445)
    for s in range(601, 685):
        assert c.accept(7, s)
    assert c.holes() == [(7, 446, 599)]
    assert c.missing() == 154
    # A hole split in the middle, then another daemon instance: a new sequence.
    assert c.accept(7, 500)
    assert c.holes() == [(7, 446, 499), (7, 501, 599)]
    assert c.accept(8, 1)
    assert c.missing() == 0 and c.holes() == []


def test_event_continuity_history_after_a_live_event() -> None:
    """A late joiner's history arriving after the first live event is delivered, once."""
    c = EventContinuity()
    assert c.accept(3, 28)
    assert c.accept(3, 5)
    assert c.holes() == [(3, 6, 27)]
    for s in range(6, 28):
        assert c.accept(3, s), s
    assert c.accept(3, 4)
    assert c.missing() == 0
    for s in range(4, 29):
        assert not c.accept(3, s), s
    assert c.accept(3, 29)


# --------------------------------------------------------------------------- the transport's intake


@pytest.fixture
def pki(tmp_path: Path) -> Path:
    """Files that look like PEM (the transport opens no session in these tests)."""
    for name in ("ca.pem", "op.pem", "op.key"):
        (tmp_path / name).write_text("-----BEGIN NOTHING-----\n", encoding="utf-8")
    return tmp_path


def transport(pki: Path) -> ZenohTransport:
    return ZenohTransport(
        "quic/127.0.0.1:7460", str(pki / "ca.pem"), str(pki / "op.pem"), str(pki / "op.key"), "lab", "op", 2.0
    )


@dataclass
class Payload:
    data: bytes

    def to_bytes(self) -> bytes:
        return self.data


@dataclass
class Sample:
    """What a Zenoh subscriber hands a callback: the payload and its encoding."""

    payload: Payload
    encoding: str


def sample_of(value: ctypes.Structure, type_name: str) -> Sample:
    return Sample(Payload(bytes(value)), remote.encoding_of(type_name))


def ev(instance: int, seq: int) -> Event:
    return Event(
        instance=instance,
        seq=seq,
        kind=EventKind.GoalTransition,
        finger=0xFFFF_FFFF,
        state=GoalState.Accepted,
        reason=ReasonCode.None_,
    )


def test_the_transport_names_itself(pki: Path) -> None:
    t = transport(pki)
    assert (t.locator, t.identity, t.prefix) == ("quic/127.0.0.1:7460", "op", "lab")
    assert t.client_id == remote.client_id_for("op")


def test_events_are_kept_once_and_bad_samples_counted(pki: Path) -> None:
    t = transport(pki)
    name = Event.type_name()
    for e in (ev(1, 1), ev(1, 2), ev(1, 2), ev(1, 5)):
        t._on_event(sample_of(e, name))
    t._on_event(sample_of(ev(1, 3), "gaitd::Event.v1"))  # another schema
    t._on_event(Sample(Payload(bytes(ev(1, 4))[:-8]), remote.encoding_of(name)))  # short
    bad = ev(1, 6)
    bad.kind = 0
    t._on_event(sample_of(bad, name))  # an unknown code
    got = t.receive()
    assert [(e.instance, e.seq) for e in got.events] == [(1, 1), (1, 2), (1, 5)]
    assert t.bad_samples == 3
    assert t.missed_events == 2 and t.event_holes == [(1, 3, 4)]
    assert t.receive().events == []
    t._on_event(sample_of(ev(1, 4), name))  # fills part of the hole
    assert [e.seq for e in t.receive().events] == [4]
    assert t.event_holes == [(1, 3, 3)]


def test_the_newest_status_is_kept_until_taken(pki: Path) -> None:
    t = transport(pki)
    for tick in (1, 2):
        s = Status(tick=tick, daemon_state=DaemonState.Running, phase=Phase.Hold)
        for f in s.fingers:
            f.state = FingerPhase.Free
        t._on_status(sample_of(s, Status.type_name()))
    got = t.receive()
    assert got.status is not None and got.status.tick == 2 and got.status_time_ns > 0
    assert t.receive().status is None
    t._on_status(sample_of(Status(tick=3), Status.type_name()))  # daemon_state 0: unknown
    assert t.receive().status is None and t.bad_samples == 1


def test_connect_refuses_what_it_can_tell_without_a_bridge(pki: Path, tmp_path: Path) -> None:
    ca, cert, key = (str(pki / n) for n in ("ca.pem", "op.pem", "op.key"))
    with pytest.raises(RemoteError, match="only accepts quic/HOST:PORT"):
        RemoteClient.connect("tcp/127.0.0.1:7447", ca, cert, key, identity="op")
    with pytest.raises(RemoteError, match="client key .*missing.key"):
        RemoteClient.connect("quic/127.0.0.1:7460", ca, cert, str(tmp_path / "missing.key"), identity="op")
    (tmp_path / "plain.pem").write_text("not a certificate\n", encoding="utf-8")
    with pytest.raises(RemoteError, match="CA certificate .*: not a PEM file"):
        RemoteClient.connect("quic/127.0.0.1:7460", str(tmp_path / "plain.pem"), cert, key, identity="op")


def test_the_identity_is_the_certificates_common_name(tmp_path: Path) -> None:
    key, cert = tmp_path / "k.pem", tmp_path / "c.pem"
    subprocess.run(
        ["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes"]
        + ["-keyout", str(key), "-out", str(cert), "-days", "1", "-subj", "/O=gaitd/CN=operator-7"],
        check=True,
        capture_output=True,
    )
    assert remote.common_name(str(cert)) == "operator-7"
    with pytest.raises(RemoteError, match="client certificate"):
        remote.common_name(str(tmp_path / "missing.pem"))
