"""A remote client of gaitd: through ``gaitd-bridge`` over Zenoh with mutual TLS.

The counterpart of the Rust client's remote transport (``gaitd_client::remote``):
:class:`RemoteClient` is the command API of :mod:`gaitd.api` (the same methods
as :class:`gaitd.client.Client`) over :class:`ZenohTransport`. Needs the ``remote``
extra (PyPI ``eclipse-zenoh``, pinned to the version of the Rust crate the
bridge is built with). The wire contract is ``bridge/PROTOCOL.md``:

* ``P/status`` — :class:`~gaitd.schema.Status` bytes, downsampled by the bridge;
* ``P/events`` — :class:`~gaitd.schema.Event` bytes, an advanced publisher
  (history for late joiners, miss detection);
* ``P/cmd/<identity>/<command>`` — a query with the :class:`~gaitd.schema.Command`
  bytes, answered with the :class:`~gaitd.schema.Answer` bytes or a refusal;
* ``P/alive/bridge``, ``P/alive/daemon`` — liveliness tokens;
  ``P/clients/<identity>/<session>`` — this client's token.

``<identity>`` is the common name of this client's certificate; the bridge
derives the ``client_id`` from it (:func:`client_id_for`) and ignores the one
in a command. Payload encodings are ``application/octet-stream;<type name>``.

Example::

    from gaitd.remote import RemoteClient
    with RemoteClient.connect("quic/robot-1:7460", ca="pki/ca.pem",
                              cert="pki/operator-1.pem", key="pki/operator-1.key") as c:
        print(c.wait_status().tick)
        reply = c.turn((0, 0, 1), math.pi / 2)
        print(c.wait_outcome(reply.goal_id, timeout=30))
"""

from __future__ import annotations

import collections
import ctypes
import enum
import functools
import json
import os
import socket
import ssl
import threading
import time
from collections.abc import Iterator
from types import ModuleType
from typing import Any

from . import ipc
from .api import (
    EVENT_BACKLOG,
    ClientApi,
    ClientError,
    NoDaemon,
    Received,
    Reply,
    Timeout,
    Transport,
    answer_ok,
    event_ok,
    status_ok,
)
from .schema import Answer, Command, CommandKind, Event, Payload, Status

#: The eclipse-zenoh release matching the Rust crate of the bridge.
ZENOH_VERSION = "1.10.2"
#: How often a session beats on its own token key (the bridge's ``client_beat_timeout_ms`` is 1.5 s) [s].
CLIENT_BEAT_S = 0.5
#: Default key prefix.
DEFAULT_KEY_PREFIX = "gaitd"
#: Encoding of every payload: this prefix, ``;`` and the payload's type name.
ENCODING_PREFIX = "application/octet-stream"
#: Schema of the bridge's error replies.
REFUSAL_SCHEMA = "gaitd-bridge::Refusal.v1"
#: The least time between two sends of one command [s].
RESEND_PAUSE = 0.05
#: How long a query that ended early without a reply, everything in sight, waits for a link drop to
#: be reported before it counts as unanswered [s] (``gaitd_client``'s ``UNANSWERED_WAIT``).
UNANSWERED_WAIT = 0.2
#: Command key chunks by kind.
COMMAND_NAMES = {
    CommandKind.Goal: "reorient",
    CommandKind.Cancel: "cancel",
    CommandKind.Hold: "hold",
    CommandKind.Reset: "reset",
}


class RefusalCode(enum.IntEnum):
    """Why the bridge refused a command (``gaitd_client::remote::protocol::RefusalCode``)."""

    WrongSize = 1
    WrongSchema = 2
    WrongKey = 3
    RateLimited = 4
    NoDaemon = 5
    DaemonBusy = 6
    DaemonTimeout = 7
    NotOperator = 8


class RemoteError(ClientError):
    """A remote connection problem (endpoint, certificate, access control)."""


class Refused(RemoteError):
    """The bridge refused the command before the daemon saw it."""

    def __init__(self, code: RefusalCode, message: str):
        super().__init__(f"the bridge refused the command: {message} ({code.name})")
        self.code = code
        self.message = message


class NoAnswer(RemoteError):
    """A command query ended without a reply: access control dropped it (a monitor), or overload."""


class NoBridge(RemoteError):
    """Connected, but no bridge is visible under the prefix (wrong prefix, or an unknown identity)."""


class NoDaemonBehindBridge(NoDaemon, RemoteError):
    """The bridge is up, but no gaitd runs behind it."""


def zenoh() -> ModuleType:
    """The ``zenoh`` module, or a clear error naming the extra to install."""
    try:
        import zenoh as z
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise RemoteError(f"the remote client needs eclipse-zenoh=={ZENOH_VERSION}: pip install 'gaitd[remote]'") from e
    return z


def encoding_of(type_name: str) -> str:
    """``application/octet-stream;<type name>``."""
    return f"{ENCODING_PREFIX};{type_name}"


def client_id_for(identity: str) -> int:
    """The bridge's ``client_id`` of an identity: FNV-1a 64 of ``gaitd-remote/<identity>``, top bit set."""
    h = 0xCBF29CE484222325
    for b in b"gaitd-remote/" + identity.encode():
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFF_FFFF_FFFF_FFFF
    return h | (1 << 63)


def common_name(cert_path: str) -> str:
    """The subject common name of a PEM certificate (the identity the bridge sees)."""
    try:
        # CPython's own certificate decoder: private, so typeshed does not declare it.
        info = ssl._ssl._test_decode_cert(cert_path)  # type: ignore[attr-defined]
    except (OSError, ssl.SSLError) as e:
        raise RemoteError(f"client certificate {cert_path}: {e}") from e
    for rdn in info.get("subject", ()):
        for key, value in rdn:
            if key == "commonName":
                return str(value)
    raise RemoteError(f"client certificate {cert_path}: no common name (CN)")


def parse_endpoint(endpoint: str) -> tuple[str, str]:
    """``(locator, host:port)`` of ``quic/HOST:PORT``, ``tls/HOST:PORT`` (over TCP) or ``HOST:PORT`` (QUIC);
    other protocols are refused."""
    proto, sep, rest = endpoint.partition("/")
    if not sep:
        proto, rest = "quic", endpoint
    if proto not in ("quic", "tls"):
        raise RemoteError(
            f"bad bridge endpoint {endpoint!r}: the bridge only accepts quic/HOST:PORT or tls/HOST:PORT (mutual TLS)"
        )
    host, _, port = rest.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536 or any(c in rest for c in "?#/"):
        raise RemoteError(f"bad bridge endpoint {endpoint!r}: expected quic/HOST:PORT or tls/HOST:PORT")
    return f"{proto}/{rest}", rest


def _check_file(what: str, path: str) -> None:
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError as e:
        raise RemoteError(f"{what} {path}: {e.strerror}") from e
    if b"-----BEGIN " not in head:
        raise RemoteError(f"{what} {path}: not a PEM file")


def ctypes_size(cls: type) -> int:
    """Size of a payload type in bytes."""
    return ctypes.sizeof(cls)


def _payload_bytes(sample: Any, cls: type[Payload]) -> bytes | None:
    """A sample's bytes if its encoding names ``cls`` and its size is ``cls``'s, else None."""
    b = bytes(sample.payload.to_bytes())
    if str(sample.encoding) != encoding_of(cls.type_name()) or len(b) != ctypes.sizeof(cls):
        return None
    return b


class EventContinuity:
    """Per-instance continuity of the events received (PROTOCOL.md, "Events").

    Every event is identified by its daemon ``instance`` and ``seq``, which
    counts from 1 without gaps within an instance. A bridge's history repeats
    events and a restarted bridge's cache may fill a gap late: each event is
    delivered once, a hole in the sequence is remembered until an event fills
    it, and what is still missing is counted (``gaitd_client``'s ``Continuity``). A late joiner's
    history may arrive after the first live event: events older than the oldest seen are new too.
    """

    def __init__(self) -> None:
        self.instance = 0  # the instance the sequence belongs to (0: none yet)
        self.low = 0  # lowest seq seen (nothing below it was seen)
        self.high = 0  # highest seq seen
        self._holes: dict[int, int] = {}  # holes below high: first -> last (inclusive)

    def accept(self, instance: int, seq: int) -> bool:
        """Whether event (instance, seq) is new or fills a hole (else it is a repeat, dropped).

        A new instance (a daemon restart) starts a new sequence at its first event seen.
        """
        if instance != self.instance:
            self.instance, self.low, self.high, self._holes = instance, seq, seq, {}
            return True
        if seq < self.low:
            # History after a later event: what lies between is a hole until its events come.
            if seq + 1 < self.low:
                self._holes[seq + 1] = self.low - 1
            self.low = seq
            return True
        if seq > self.high:
            if seq > self.high + 1:
                self._holes[self.high + 1] = seq - 1
            self.high = seq
            return True
        for first, last in list(self._holes.items()):
            if first <= seq <= last:
                del self._holes[first]
                if first < seq:
                    self._holes[first] = seq - 1
                if seq < last:
                    self._holes[seq + 1] = last
                return True
        return False

    def missing(self) -> int:
        """Events of this instance still missing (holes not filled)."""
        return sum(b - a + 1 for a, b in self._holes.items())

    def holes(self) -> list[tuple[int, int, int]]:
        """The holes, oldest first: (instance, first seq, last seq)."""
        return [(self.instance, a, b) for a, b in sorted(self._holes.items())]


class ZenohTransport(Transport):
    """gaitd-bridge over Zenoh with mutual TLS, as a :class:`~gaitd.api.Transport`.

    Zenoh delivers status, events, liveliness and link changes on its own
    threads: the callbacks keep them under one condition variable, and
    :meth:`receive` hands them over to the client's thread.
    """

    def __init__(
        self, endpoint: str, ca: str, cert: str, key: str, prefix: str | None, identity: str | None, timeout: float
    ):
        self.locator, self._address = parse_endpoint(endpoint)
        for what, path in (("CA certificate", ca), ("client certificate", cert), ("client key", key)):
            _check_file(what, path)
        self._files = (ca, cert, key)
        self.identity = identity or common_name(cert)
        self.prefix = prefix or os.environ.get("GAITD_PREFIX") or DEFAULT_KEY_PREFIX
        self.client_id = client_id_for(self.identity)
        self.timeout = timeout
        self._zenoh_missed = 0
        # Random too: the bridge recognises a request sent again by its id and bytes (PROTOCOL.md,
        # "Known issue"), so sessions of one identity must not reuse one another's ids.
        self._next_request = (int.from_bytes(os.urandom(8), "little") >> 2) + 1
        self._cond = threading.Condition()
        # What arrived and was not handed over yet.
        self._status: Status | None = None
        self._status_time_ns = 0
        self._events: collections.deque[Event] = collections.deque(maxlen=EVENT_BACKLOG)
        self._continuity = EventContinuity()
        self._bridge = False
        self._bridge_seen = False
        self._daemon = False
        # The link to the bridge (Zenoh's transport events) and the times it went down.
        self._linked = False
        self._link_drops = 0
        # Request id -> (key chunk, replies, bytes, schema, when sent, link drops by then).
        self._pending: dict[int, tuple[str, Any, bytes, str, float, int]] = {}
        self._session: Any = None

    # ------------------------------------------------------------------ session

    def _config(self, lease: float) -> Any:
        ca, cert, key = self._files
        conf = {
            "mode": "client",
            "connect": {
                "endpoints": [self.locator],
                "timeout_ms": max(1, int(self.timeout * 1000)),
                "exit_on_failure": True,
                "retry": {"period_init_ms": 200, "period_max_ms": 1000, "period_increase_factor": 1.5},
            },
            "listen": {"endpoints": []},
            "scouting": {"multicast": {"enabled": False}, "gossip": {"enabled": False}},
            "transport": {
                "link": {
                    "protocols": [self.locator.partition("/")[0]],
                    "tx": {"lease": int(min(max(lease, 0.5), 600.0) * 1000), "keep_alive": 4},
                    "tls": {
                        "root_ca_certificate": ca,
                        "connect_certificate": cert,
                        "connect_private_key": key,
                        "enable_mtls": True,
                        "verify_name_on_connect": True,
                    },
                },
                "shared_memory": {"enabled": False},
            },
        }
        return zenoh().Config.from_json5(json.dumps(conf))

    def _wait_reachable(self, deadline: float) -> None:
        host, _, port = self._address.rpartition(":")
        host = host.strip("[]")
        while True:
            try:
                socket.create_connection((host, int(port)), timeout=max(0.05, deadline - time.monotonic())).close()
                return
            except OSError as e:
                if time.monotonic() >= deadline:
                    raise RemoteError(
                        f"nothing listens at {self.locator} ({e.strerror or e}): is gaitd-bridge running there?"
                    ) from e
                time.sleep(0.1)

    def open(self, lease: float, deadline: float) -> None:
        """Opens the session (by ``deadline``, time.monotonic) and declares subscribers, token and beats."""
        z = zenoh()
        from zenoh import ext

        # A TCP connect tells an absent bridge from a refused certificate; QUIC has no such probe.
        tcp = self.locator.startswith("tls/")
        if tcp:
            self._wait_reachable(deadline)
        try:
            self._session = z.open(self._config(lease))
        except z.ZError as e:
            if not tcp:
                raise RemoteError(
                    f"no session with the bridge at {self.locator} ({str(e).split(' at /')[0]}): is gaitd-bridge "
                    f"running there, did its CA sign this client's certificate (not expired), and does the "
                    f"bridge's certificate name this host?"
                ) from e
            raise RemoteError(
                f"the bridge at {self.locator} refused the TLS session: its CA did not sign this client's "
                f"certificate, the certificate expired, or the bridge's certificate does not match the host "
                f"name ({str(e).split(' at /')[0]})"
            ) from e
        p = self.prefix
        # The link itself: the bridge's token does not always blink when Zenoh reconnects at once.
        self._link_listener = self._session.info.declare_transport_events_listener(self._on_transport, history=True)
        self._subs = [
            self._session.declare_subscriber(f"{p}/status", self._on_status),
            self._session.liveliness().declare_subscriber(f"{p}/alive/*", self._on_alive, history=True),
        ]
        # History without late-publisher detection, as the Rust client (PROTOCOL.md, "Events"): with it,
        # zenoh-ext 1.10.2 may deliver a live event before the history and then drop the history as older.
        events = ext.declare_advanced_subscriber(
            self._session,
            f"{p}/events",
            self._on_event,
            history=ext.HistoryConfig(max_samples=256),
            recovery=ext.RecoveryConfig(periodic_queries=None, heartbeat=True),
        )
        self._misses = events.sample_miss_listener(self._on_miss)
        self._subs.append(events)
        token_key = f"{p}/clients/{self.identity}/{self._session.zid()}"
        self._token = self._session.liveliness().declare_token(token_key)
        # Beats (PROTOCOL.md, "Lost clients"): the bridge counts a session silent for its
        # client_beat_timeout_ms as gone, whatever the lease.
        self._beat_stop = threading.Event()
        session = self._session

        def beat() -> None:
            while not self._beat_stop.wait(CLIENT_BEAT_S):
                try:
                    session.put(token_key, b"")
                except Exception:  # noqa: BLE001 - a closed session ends the beats
                    return

        try:
            session.put(token_key, b"")
        except Exception:  # noqa: BLE001
            pass
        self._beat_thread = threading.Thread(target=beat, name="gaitd-remote-beat", daemon=True)
        self._beat_thread.start()

    def silence(self, waited: float) -> RemoteError | None:
        """Why no status came within ``waited`` [s], if the bridge's or daemon's absence says so."""
        with self._cond:
            bridge, daemon = self._bridge, self._daemon
        if not bridge:
            return NoBridge(
                f"connected to {self.locator} as {self.identity!r}, but no gaitd-bridge with key prefix "
                f"{self.prefix!r} answered within {waited:g} s: wrong prefix, or the bridge's access control "
                "does not know this identity"
            )
        if not daemon:
            return NoDaemonBehindBridge(f"gaitd-bridge at {self.locator} is up, but no gaitd is running behind it")
        return None

    def close(self) -> None:
        """Undeclares everything and closes the session."""
        session = self._session
        if session is None:
            return
        stop = getattr(self, "_beat_stop", None)
        if stop is not None:
            stop.set()
            self._beat_thread.join(timeout=1.0)
        for s in [
            *getattr(self, "_subs", []),
            getattr(self, "_misses", None),
            getattr(self, "_token", None),
            getattr(self, "_link_listener", None),
        ]:
            if s is not None:
                try:
                    s.undeclare()
                except Exception:  # noqa: BLE001 - closing anyway
                    pass
        session.close()
        self._session = None

    # ------------------------------------------------------------------ callbacks (Zenoh's threads)

    def _on_status(self, sample: Any) -> None:
        b = _payload_bytes(sample, Status)
        with self._cond:
            s = Status.from_buffer_copy(b) if b is not None else None
            if s is not None and status_ok(s):
                # Judged by arrival: the daemon's clock is another host's.
                self._status, self._status_time_ns = s, ipc.monotonic_ns()
            else:
                self.bad_samples += 1
            self._cond.notify_all()

    def _on_event(self, sample: Any) -> None:
        b = _payload_bytes(sample, Event)
        with self._cond:
            e = Event.from_buffer_copy(b) if b is not None else None
            if e is None or not event_ok(e):
                self.bad_samples += 1
            elif self._continuity.accept(int(e.instance), int(e.seq)):
                self._events.append(e)
            self._cond.notify_all()

    def _on_miss(self, miss: Any) -> None:
        with self._cond:
            self._zenoh_missed += int(miss.nb)

    def _on_transport(self, event: Any) -> None:
        up = event.kind == zenoh().SampleKind.PUT
        with self._cond:
            if self._linked and not up:
                self._link_drops += 1
            self._linked = up
            self._cond.notify_all()

    def _on_alive(self, sample: Any) -> None:
        up = sample.kind == zenoh().SampleKind.PUT
        key = str(sample.key_expr)
        with self._cond:
            if key == f"{self.prefix}/alive/bridge":
                if up and not self._bridge and self._bridge_seen:
                    self.reconnects += 1
                self._bridge_seen |= up
                self._bridge = up
            elif key == f"{self.prefix}/alive/daemon":
                self._daemon = up
            self._cond.notify_all()

    @property
    def missed_events(self) -> int:
        """Events of the daemon's current sequence never received, or Zenoh's count of missed samples if more."""
        with self._cond:
            return max(self._continuity.missing(), self._zenoh_missed)

    @property
    def event_holes(self) -> list[tuple[int, int, int]]:
        """The holes in the events received, oldest first: (instance, first seq, last seq)."""
        with self._cond:
            return self._continuity.holes()

    def _in_sight(self) -> bool:
        return self._linked and self._bridge and self._daemon

    def _link_changed(self, drops: int) -> bool:
        """Whether the link dropped since ``drops`` were counted, or bridge or daemon went out of sight."""
        return self._link_drops != drops or not self._in_sight()

    # ------------------------------------------------------------------ Transport

    def receive(self) -> Received:
        with self._cond:
            got = Received(self._status, self._status_time_ns, list(self._events))
            self._status = None
            self._events.clear()
        return got

    def wait(self, seconds: float) -> None:
        with self._cond:
            if self._status is None and not self._events:
                self._cond.wait(seconds)

    def send(self, cmd: Command, name: str | None = None, schema: str | None = None) -> int:
        """Sends ``cmd`` to the command key of its kind (or ``name``) with encoding schema ``schema``."""
        cmd.request_id = self._next_request
        self._next_request += 1
        if name is None:
            try:
                name = COMMAND_NAMES[CommandKind(cmd.kind)]
            except ValueError:
                name = "reorient"
        return self._query(name, bytes(cmd), schema or Command.type_name(), int(cmd.request_id))

    def send_raw(self, name: str, payload: bytes, schema: str) -> int:
        """Sends any bytes to command key ``name`` with encoding schema ``schema``; returns a request id."""
        rid = self._next_request
        self._next_request += 1
        return self._query(name, payload, schema, rid)

    def _query(self, name: str, payload: bytes, schema: str, rid: int) -> int:
        with self._cond:
            drops = self._link_drops
        self._pending[rid] = (name, self._get(name, payload, schema), payload, schema, time.monotonic(), drops)
        return rid

    def _get(self, name: str, payload: bytes, schema: str) -> Any:
        return self._session.get(
            f"{self.prefix}/cmd/{self.identity}/{name}",
            payload=payload,
            encoding=zenoh().Encoding(encoding_of(schema)),
            timeout=max(1.0, self.timeout),
        )

    def answer(self, request_id: int, timeout: float) -> Reply:
        """The answer to ``request_id``; raises :class:`Refused` or :class:`NoAnswer` otherwise.

        The query's own timeout (the connect timeout, at least 1 s) bounds the wait.
        """
        name, replies, payload, schema, sent, drops = self._pending.pop(request_id)
        for reply in self._replies(name, replies, payload, schema, sent, drops):
            if reply.ok is not None:
                s = reply.ok
                b = bytes(s.payload.to_bytes())
                if str(s.encoding) != encoding_of(Answer.type_name()) or len(b) != ctypes.sizeof(Answer):
                    raise RemoteError(f"undecodable answer from the bridge ({s.encoding}, {len(b)} bytes)")
                a = Answer.from_buffer_copy(b)
                if not answer_ok(a):
                    raise RemoteError("undecodable answer codes from the bridge")
                return Reply.of(a, request_id)
            err = reply.err
            b = bytes(err.payload.to_bytes())
            if str(err.encoding) == encoding_of(REFUSAL_SCHEMA) and len(b) >= 4:
                code = int.from_bytes(b[:4], "little")
                if code in RefusalCode._value2member_map_:
                    raise Refused(RefusalCode(code), b[4:].decode(errors="replace"))
            raise RemoteError(f"undecodable error reply from the bridge ({err.encoding})")
        with self._cond:
            unanswered = self._in_sight() and self._link_drops == drops
        if unanswered:
            raise NoAnswer(
                f"the bridge did not answer {name!r} from identity {self.identity!r} although it is up: its "
                "access control does not let this identity send commands (a monitor certificate?), or the "
                "daemon is overloaded"
            )
        raise RemoteError(f"the connection to the bridge at {self.locator} is lost (reconnecting)")

    def _replies(self, name: str, replies: Any, payload: bytes, schema: str, sent: float, drops: int) -> Iterator[Any]:
        """The query's replies; if it ended early without one because its link dropped with it in
        flight (PROTOCOL.md "Known issue"), those of the same bytes sent again once the link is back,
        at most every ``RESEND_PAUSE``, until the query timeout has passed since the first send."""
        limit = max(1.0, self.timeout)
        deadline = sent + limit
        last = sent
        while True:
            got = False
            for reply in replies:  # ends when the query is finalised (or times out)
                got = True
                yield reply
            if got:
                return
            with self._cond:
                if self._in_sight() and self._link_drops == drops:
                    if time.monotonic() - last > 0.9 * limit:
                        return  # ran out its timeout in sight: unanswered
                    # Ended early in sight: a link drop may be reported in a moment; if not, nobody
                    # answers (access control dropped it: a monitor's command).
                    self._cond.wait_for(functools.partial(self._link_changed, drops), timeout=UNANSWERED_WAIT)
                    if self._in_sight() and self._link_drops == drops:
                        return
                # The link dropped: sent again, with the same request id, when it is back.
                if not self._cond.wait_for(self._in_sight, timeout=max(0.0, deadline - time.monotonic())):
                    return
            time.sleep(max(0.0, last + RESEND_PAUSE - time.monotonic()))
            with self._cond:
                drops = self._link_drops
            last = time.monotonic()
            replies = self._get(name, payload, schema)


class RemoteClient(ClientApi):
    """A connection to gaitd through gaitd-bridge (the methods of :class:`gaitd.client.Client`)."""

    def __init__(
        self,
        endpoint: str,
        ca: str,
        cert: str,
        key: str,
        prefix: str | None,
        identity: str | None,
        timeout: float,
        max_status_age: float,
        lease: float,
    ):
        deadline = time.monotonic() + timeout
        self._zenoh = ZenohTransport(endpoint, ca, cert, key, prefix, identity, timeout)
        #: ``quic/HOST:PORT`` or ``tls/HOST:PORT``.
        self.locator = self._zenoh.locator
        #: The common name of this client's certificate, as the bridge sees it.
        self.identity = self._zenoh.identity
        #: The bridge's key prefix.
        self.prefix = self._zenoh.prefix
        # Every session of an identity shares its client id: goal ids start where none did.
        first_goal = (int.from_bytes(os.urandom(4), "little") >> 1) + 1
        super().__init__(self._zenoh, self._zenoh.client_id, timeout, max_status_age, first_goal)
        try:
            self._zenoh.open(lease, deadline)
            waited = max(0.0, deadline - time.monotonic())
            try:
                self._wait_fresh_status(waited)
            except Timeout as e:
                why = self._zenoh.silence(waited)
                if why is not None:
                    raise why from e
                raise
        except BaseException:
            self.close()
            raise

    @classmethod
    def connect(
        cls,
        endpoint: str,
        ca: str,
        cert: str,
        key: str,
        prefix: str | None = None,
        identity: str | None = None,
        timeout: float = 2.0,
        max_status_age: float = 1.0,
        lease: float = 3.0,
    ) -> RemoteClient:
        """Opens a session to the bridge at ``endpoint`` and waits for a fresh status, within ``timeout`` [s]."""
        return cls(endpoint, ca, cert, key, prefix, identity, timeout, max_status_age, lease)

    @property
    def missed_events(self) -> int:
        """Events of the daemon's current sequence never received (holes no later event filled),
        or Zenoh's count of missed samples if more."""
        return self._zenoh.missed_events

    @property
    def event_holes(self) -> list[tuple[int, int, int]]:
        """The holes in the events received, oldest first: (instance, first seq, last seq)."""
        return self._zenoh.event_holes

    def send_command(self, cmd: Command, name: str | None = None, schema: str | None = None) -> int:
        """Sends ``cmd`` (only ``request_id`` filled in) to its command key and returns the request id.

        ``name`` overrides the key chunk and ``schema`` the encoding's type name (tests of bad bytes).
        """
        return self._zenoh.send(cmd, name, schema)

    def send_raw(self, name: str, payload: bytes, schema: str) -> int:
        """Sends any bytes to command key ``name`` with encoding schema ``schema``; returns a request id."""
        return self._zenoh.send_raw(name, payload, schema)

    def wait_answer(self, request_id: int, timeout: float | None = None) -> Reply:
        """The answer to ``request_id``; raises :class:`Refused` or :class:`NoAnswer` otherwise."""
        return super().wait_answer(request_id, timeout)
