"""A synchronous Python client of gaitd, the counterpart of the Rust ``gaitd_client``.

:class:`Client` is the command API of :mod:`gaitd.api` over iceoryx2 on the
daemon's host. It opens the services the daemon created (never creates
them), matches answers by ``(client_id, request_id)``, keeps the newest
status and a backlog of events, and blocks on the daemon's ``notify`` event
service instead of spinning. Every received sample is copied out of shared
memory and its codes are checked before use (bad samples are counted and
dropped): the daemon's bytes are not trusted blindly.

Example::

    from gaitd.client import Client
    with Client.connect() as c:                 # GAITD_* environment, then defaults
        ticket = c.turn((0, 0, 1), math.pi)     # half a turn about z
        outcome = c.wait_outcome(ticket.goal_id, timeout=30)
"""

from __future__ import annotations

import collections
import math
import os
import time
from collections.abc import Callable, Sequence
from typing import Any

from . import ipc
from .api import (
    EVENT_BACKLOG,
    MAX_BLOCK,
    ClientApi,
    ClientError,
    NoDaemon,
    NotDelivered,
    Outcome,
    Received,
    Reply,
    Timeout,
    Transport,
    answer_ok,
    event_ok,
    status_ok,
)
from .schema import (
    SCHEMA_VERSION,
    VERSION_ATTRIBUTE_BUILD,
    VERSION_ATTRIBUTE_SCHEMA,
    Answer,
    Command,
    Event,
    Payload,
    ServiceNames,
    Status,
)

__all__ = [
    "EVENT_BACKLOG",
    "MAX_BLOCK",
    "Client",
    "ClientError",
    "Iceoryx2Transport",
    "NoDaemon",
    "Outcome",
    "Reply",
    "SchemaMismatch",
    "Timeout",
    "daemon_schema",
    "quat_from_axis_angle",
]


class SchemaMismatch(ClientError):
    """The daemon's services carry another schema version (type name, size or alignment)."""


# iceoryx2 open errors that a later try may not meet.
_TRANSIENT_OPEN = ("DoesNotExist", "HangsInCreation", "IsMarkedForDestruction")


def daemon_schema(node: Any, names: ServiceNames) -> tuple[str, str] | None:
    """The daemon's (schema, build) from its ``version`` service, None without one.

    Raises :class:`SchemaMismatch` naming both versions when the schema is not this
    package's (the services' type names would only say "incompatible").
    """
    iox2 = ipc.iceoryx2()
    try:
        factory = node.service_builder(ipc.service_name(names.version)).event().open()
    except iox2.EventOpenError as e:
        if "DoesNotExist" in repr(e):
            return None
        raise

    def value(key: str) -> str:
        found = factory.attributes.key_values(iox2.AttributeKey.new(key))
        return str(found[0].to_string()) if found else "?"

    schema, build = value(VERSION_ATTRIBUTE_SCHEMA), value(VERSION_ATTRIBUTE_BUILD)
    if schema != str(SCHEMA_VERSION):
        raise SchemaMismatch(
            f"the daemon speaks schema v{schema} ({build}), this client v{SCHEMA_VERSION}: "
            f"use a client built for the daemon's schema (LAYOUT.md, Schema versions)"
        )
    return schema, build


def quat_from_axis_angle(axis: Sequence[float], angle: float) -> tuple[float, float, float, float]:
    """The unit quaternion of a rotation by ``angle`` [rad] about ``axis``."""
    n = math.sqrt(sum(a * a for a in axis))
    if not (math.isfinite(n) and n > 1e-12 and math.isfinite(angle)):
        raise ValueError("axis must be finite and non-zero, angle finite")
    s, c = math.sin(angle / 2), math.cos(angle / 2)
    return (c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n)


class Iceoryx2Transport(Transport):
    """The daemon's iceoryx2 services on this host, as a :class:`~gaitd.api.Transport`.

    Ports belong to the thread that opened them, like every iceoryx2 port.
    """

    def __init__(self, settings: ipc.IpcSettings, node_name: str, client_id: int):
        self.settings = settings
        self.node_name = node_name
        self.client_id = client_id
        self._node: Any = None
        self._ports: dict[str, Any] = {}
        self._next_request = 1
        self._answers: dict[int, Answer] = {}
        self._outstanding: set[int] = set()
        self._status: Status | None = None
        self._events: collections.deque[Event] = collections.deque(maxlen=EVENT_BACKLOG)

    def open(self, timeout: float) -> None:
        """Opens the daemon's services, waiting up to ``timeout`` [s] for them to exist."""
        iox2 = ipc.iceoryx2()
        names = ServiceNames(self.settings.service_prefix)
        deadline = ipc.monotonic_ns() + int(timeout * 1e9)
        node = ipc.create_node(self.settings, self.node_name)
        self._node = node

        def open_pubsub(name: str, payload: type[Payload]) -> Any:
            sn = ipc.service_name(name)
            while True:
                try:
                    return node.service_builder(sn).publish_subscribe(payload).open()
                except iox2.PublishSubscribeOpenError as e:
                    text = repr(e)
                    if "IncompatibleTypes" in text:
                        raise SchemaMismatch(
                            f"service {name} does not carry {payload.type_name()} "
                            f"(the daemon speaks another schema version)"
                        ) from e
                    # Missing, or still being created by a starting daemon.
                    transient = any(w in text for w in _TRANSIENT_OPEN)
                    if not transient or ipc.monotonic_ns() >= deadline:
                        raise NoDaemon(
                            f"no gaitd with prefix {self.settings.service_prefix!r} under "
                            f"{self.settings.root_path} ({name}: {text})"
                        ) from e
                    time.sleep(0.01)

        def open_event(name: str) -> Any:
            sn = ipc.service_name(name)
            return ipc.retry(
                f"open {name}",
                lambda: node.service_builder(sn).event().open(),
                max(0.0, (deadline - ipc.monotonic_ns()) / 1e9),
            )

        # Which schema the daemon speaks, before a type name says "incompatible".
        versioned = daemon_schema(node, names) is not None
        try:
            commands = open_pubsub(names.commands, Command)
        except SchemaMismatch as e:
            if versioned:
                raise
            raise SchemaMismatch(
                f"the daemon speaks schema v3 or older (it has no version service), "
                f"this client v{SCHEMA_VERSION}: use a client built for the daemon's schema"
            ) from e
        answers = open_pubsub(names.answers, Answer)
        status = open_pubsub(names.status, Status)
        events = open_pubsub(names.events, Event)
        notify = open_event(names.notify)
        # A full daemon queue refuses the send instead of blocking this client.
        self._ports["commands"] = (
            commands.publisher_builder()
            .backpressure_strategy(iox2.BackpressureStrategy.DiscardData)
            .max_loaned_samples(1)
            .create()
        )
        self._ports["answers"] = answers.subscriber_builder().create()
        # Latest value only: one receive per pump is the newest status.
        self._ports["status"] = status.subscriber_builder().buffer_size(1).create()
        self._ports["events"] = events.subscriber_builder().create()
        self._ports["listener"] = notify.listener_builder().create()
        self._duration = iox2.Duration

    def close(self) -> None:
        """Releases the ports and the node; answers still outstanding are forgotten."""
        for name in ("commands", "answers", "status", "events", "listener"):
            p = self._ports.pop(name, None)
            if p is not None:
                p.delete()
        self._node = None
        self._status = None
        self._answers.clear()
        self._outstanding.clear()

    def reopen(self, timeout: float) -> None:
        """Closes and opens again (a restarted daemon has new services)."""
        self.close()
        self.reconnects += 1
        self.open(timeout)

    def _pump(self) -> None:
        """Copies out every sample waiting, checked (bad ones counted and dropped)."""
        if not self._ports:
            return  # closed: nothing arrives until opened again
        while (s := self._ports["events"].receive()) is not None:
            e = Event.from_buffer_copy(s.payload().contents)
            if event_ok(e):
                self._events.append(e)
            else:
                self.bad_samples += 1
        while (s := self._ports["answers"].receive()) is not None:
            a = Answer.from_buffer_copy(s.payload().contents)
            # Answers to every client arrive here: keep ours.
            if a.client_id == self.client_id and a.request_id in self._outstanding:
                if answer_ok(a):
                    self._answers[a.request_id] = a
                else:
                    self.bad_samples += 1
        if (s := self._ports["status"].receive()) is not None:
            st = Status.from_buffer_copy(s.payload().contents)
            if status_ok(st):
                self._status = st
            else:
                self.bad_samples += 1

    def receive(self) -> Received:
        self._pump()
        st, self._status = self._status, None
        events = list(self._events)
        self._events.clear()
        # The daemon stamps each status with this host's CLOCK_MONOTONIC.
        return Received(st, int(st.publish_time_ns) if st is not None else 0, events)

    def wait(self, seconds: float) -> None:
        listener = self._ports.get("listener")
        if listener is None:
            time.sleep(seconds)  # closed
        else:
            listener.timed_wait(self._duration.from_secs_f64(seconds))

    def send(self, cmd: Command) -> int:
        cmd.request_id = self._next_request
        self._next_request += 1
        publisher = self._ports.get("commands")
        if publisher is None:
            raise NotDelivered("not connected")
        self._outstanding.add(cmd.request_id)
        delivered = publisher.loan_uninit().write_payload(cmd).send()
        if delivered == 0:
            self._outstanding.discard(cmd.request_id)
            raise NotDelivered("no subscriber took the command")
        return int(cmd.request_id)

    def answer(self, request_id: int, timeout: float) -> Reply:
        deadline = ipc.monotonic_ns() + int(timeout * 1e9)
        try:
            while True:
                self._pump()
                a = self._answers.pop(request_id, None)
                if a is not None:
                    return Reply.of(a, request_id)
                left = (deadline - ipc.monotonic_ns()) / 1e9
                if left <= 0:
                    raise Timeout(f"timed out after {timeout:g} s waiting for the daemon's answer")
                self.wait(min(left, MAX_BLOCK))
        finally:
            self._outstanding.discard(request_id)


class Client(ClientApi):
    """A connection to a running gaitd over iceoryx2 (bound to the creating thread, like iceoryx2 ports)."""

    def __init__(self, settings: ipc.IpcSettings, timeout: float, max_status_age: float, node_name: str):
        self.settings = settings
        self.node_name = node_name
        client_id = int.from_bytes(os.urandom(8), "little") | 1
        self._iox = Iceoryx2Transport(settings, node_name, client_id)
        super().__init__(self._iox, client_id, timeout, max_status_age, first_goal=1)
        self._connect(timeout, self._iox.open)

    @classmethod
    def connect(
        cls,
        prefix: str | None = None,
        root_path: str | None = None,
        file_prefix: str | None = None,
        iceoryx2_config: str | None = None,
        timeout: float = 2.0,
        max_status_age: float = 1.0,
        node_name: str = "gaitd-py-client",
    ) -> Client:
        """Opens the daemon's services and waits for a fresh status, within ``timeout`` [s].

        Unset values come from ``GAITD_PREFIX``, ``GAITD_IPC_ROOT``,
        ``GAITD_IPC_FILE_PREFIX``, ``GAITD_IPC_CONFIG``, then the iceoryx2
        config file, then the defaults — as the daemon resolves them.
        """
        settings = ipc.resolve(prefix, root_path, file_prefix, iceoryx2_config)
        return cls(settings, timeout, max_status_age, node_name)

    def _connect(self, timeout: float, open_ports: Callable[[float], None]) -> None:
        """Opens the services (``open_ports(timeout)``) and waits for a fresh status."""
        try:
            open_ports(timeout)
            self._wait_fresh_status(timeout)
        except Timeout as e:
            self.close()
            raise NoDaemon(
                f"no fresh status from gaitd (prefix {self.settings.service_prefix!r}, root "
                f"{self.settings.root_path}) within {timeout:g} s"
            ) from e
        except BaseException:
            self.close()
            raise

    def reconnect(self, timeout: float | None = None) -> None:
        """Drops the connection and opens it again (e.g. after a daemon restart)."""
        self._forget_status()
        self._connect(self.timeout if timeout is None else timeout, self._iox.reopen)

    def command(self, cmd: Command, timeout: float | None = None) -> Reply:
        """Sends a command and waits for its answer, reconnecting once if the daemon restarted."""
        if not self.daemon_alive():
            self.reconnect(timeout)
        try:
            rid = self.send_command(cmd)
        except NoDaemon:
            self.reconnect(timeout)
            rid = self.send_command(cmd)
        return self.wait_answer(rid, timeout)
