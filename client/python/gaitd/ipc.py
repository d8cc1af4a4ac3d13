"""Where the daemon's iceoryx2 resources live, resolved exactly as gaitd does.

Daemon, Rust clients and Python peers must agree on three values: the
service-name prefix, the iceoryx2 root path and the iceoryx2 file prefix
(``shm_schema/src/ipc.rs``). Each is resolved the same way everywhere:
explicit setting → environment variable (``GAITD_PREFIX``,
``GAITD_IPC_ROOT``, ``GAITD_IPC_FILE_PREFIX``; ``GAITD_IPC_CONFIG`` names an
iceoryx2 config file) → the iceoryx2 config file → built-in default. Empty
strings count as unset, as in the daemon's ``[ipc]`` section.
"""

from __future__ import annotations

import importlib.metadata
import os
import re
import time
from dataclasses import dataclass
from typing import Any, TypeVar
from collections.abc import Callable, Mapping

from .schema import DEFAULT_PREFIX, ICEORYX2_VERSION

#: Environment variable: service-name prefix.
ENV_PREFIX = "GAITD_PREFIX"
#: Environment variable: iceoryx2 root path.
ENV_ROOT_PATH = "GAITD_IPC_ROOT"
#: Environment variable: iceoryx2 file prefix.
ENV_FILE_PREFIX = "GAITD_IPC_FILE_PREFIX"
#: Environment variable: iceoryx2 config file to load.
ENV_ICEORYX2_CONFIG = "GAITD_IPC_CONFIG"
#: Default root path of the service (under the unit's RuntimeDirectory).
SERVICE_ROOT_PATH = "/run/gaitd/iceoryx2/"
#: Default iceoryx2 file prefix.
DEFAULT_FILE_PREFIX = "gaitd_"

_PREFIX_OK = re.compile(r"^[A-Za-z0-9._/-]{1,200}$")


class IpcError(Exception):
    """The settings are unusable, or a service or port could not be opened."""


def default_root_path(uid: int, run_dir_exists: bool) -> str:
    """The service's runtime directory for root or when it exists, else a per-user /tmp path."""
    if uid == 0 or run_dir_exists:
        return SERVICE_ROOT_PATH
    return f"/tmp/gaitd-{uid}/iceoryx2/"


@dataclass(frozen=True)
class IpcSettings:
    """The resolved values all peers must agree on."""

    service_prefix: str
    root_path: str
    file_prefix: str
    iceoryx2_config: str | None = None

    def validate(self) -> None:
        """Raises :class:`IpcError` for a value iceoryx2 or the daemon would refuse."""
        if not _PREFIX_OK.match(self.service_prefix):
            raise IpcError("service prefix must be non-empty and use only [A-Za-z0-9._/-]")
        if not self.root_path.startswith("/"):
            raise IpcError("iceoryx2 root path must be an absolute path")
        if not self.file_prefix or "/" in self.file_prefix:
            raise IpcError("iceoryx2 file prefix must be a plain file name (no '/')")


def _load_config_file(path: str) -> Any:
    iox2 = iceoryx2()
    try:
        return iox2.config.from_file(iox2.FilePath.new(path))
    except Exception as e:  # the bindings raise their own error types
        raise IpcError(f"cannot load iceoryx2 config {path}: {e!r}") from e


def resolve(
    service_prefix: str | None = None,
    root_path: str | None = None,
    file_prefix: str | None = None,
    iceoryx2_config: str | None = None,
    env: Mapping[str, str] | None = None,
) -> IpcSettings:
    """Explicit values, else the environment, else the iceoryx2 config file, else the defaults."""
    env = os.environ if env is None else env

    def pick(explicit: str | None, var: str) -> str | None:
        if explicit:
            return explicit
        value = env.get(var, "")
        return value or None

    prefix = pick(service_prefix, ENV_PREFIX) or DEFAULT_PREFIX
    config_file = pick(iceoryx2_config, ENV_ICEORYX2_CONFIG)
    root = pick(root_path, ENV_ROOT_PATH)
    fprefix = pick(file_prefix, ENV_FILE_PREFIX)
    if config_file and (root is None or fprefix is None):
        cfg = _load_config_file(config_file)
        root = root or cfg.global_cfg.root_path.to_string()
        fprefix = fprefix or cfg.global_cfg.prefix.to_string()
    if root is None:
        root = default_root_path(os.getuid(), os.path.isdir("/run/gaitd"))
    if not root.endswith("/"):
        root += "/"
    s = IpcSettings(prefix, root, fprefix or DEFAULT_FILE_PREFIX, config_file)
    s.validate()
    return s


def resolve_section(ipc: Mapping[str, Any], env: Mapping[str, str] | None = None) -> IpcSettings:
    """Settings from a daemon config's ``[ipc]`` section (``""`` = unset, as gaitd reads it)."""
    return resolve(
        service_prefix=ipc.get("service_prefix") or None,
        root_path=ipc.get("root_path") or None,
        file_prefix=ipc.get("file_prefix") or None,
        iceoryx2_config=ipc.get("iceoryx2_config") or None,
        env=env,
    )


def iceoryx2() -> Any:
    """The iceoryx2 bindings, refusing any version other than the daemon's."""
    version = importlib.metadata.version("iceoryx2")
    if version != ICEORYX2_VERSION:
        raise IpcError(
            f"iceoryx2 {version} is installed, gaitd uses {ICEORYX2_VERSION} "
            f"(resource names are version-tagged): pip install iceoryx2=={ICEORYX2_VERSION}"
        )
    import iceoryx2 as iox2

    return iox2


def create_node(settings: IpcSettings, name: str) -> Any:
    """An iceoryx2 node in the daemon's namespace.

    Signal handling is left to Python (``SignalHandlingMode.Disabled``) so
    that SIGTERM/SIGINT reach the program's own handlers.
    """
    iox2 = iceoryx2()
    iox2.set_log_level(iox2.LogLevel.Error)
    if settings.iceoryx2_config:
        config = _load_config_file(settings.iceoryx2_config)
    else:
        config = iox2.config.default()
    config.global_cfg.root_path = iox2.Path.new(settings.root_path)
    config.global_cfg.prefix = iox2.FileName.new(settings.file_prefix)
    return (
        iox2.NodeBuilder.new()
        .name(iox2.NodeName.new(name))
        .config(config)
        .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
        .create(iox2.ServiceType.Ipc)
    )


def service_name(name: str) -> Any:
    """An iceoryx2 ServiceName."""
    return iceoryx2().ServiceName.new(name)


T = TypeVar("T")


class Cancelled(IpcError):
    """A wait was given up because the program is stopping."""


def retry(
    what: str,
    attempt: Callable[[], T],
    timeout: float,
    interval: float = 0.02,
    cancelled: Callable[[], bool] | None = None,
) -> T:
    """``attempt()`` until it does not raise, for at most ``timeout`` seconds (or until ``cancelled()``).

    Why: services appear only once the daemon created them, and a dead
    predecessor's ports keep their slots until dead-node cleanup; both are
    transient, so peers retry instead of failing at once.
    """
    deadline = time.monotonic() + timeout
    while True:
        try:
            return attempt()
        except Exception as e:
            if cancelled is not None and cancelled():
                raise Cancelled(f"{what}: stopped while waiting") from e
            if time.monotonic() >= deadline:
                raise IpcError(f"{what}: {e!r} (gave up after {timeout:g} s)") from e
            time.sleep(interval)


def monotonic_ns() -> int:
    """CLOCK_MONOTONIC in ns: the clock of the daemon's time stamps."""
    return time.clock_gettime_ns(time.CLOCK_MONOTONIC)
