"""gaitd from Python: a client, the plant interface, and the MuJoCo physics hand.

Modules, by what they hold:

* :mod:`gaitd.schema` — ctypes mirror of every shared-memory payload, the
  code tables and bit constants (generated into :mod:`gaitd.layout` from the
  Rust layout code), and :func:`~gaitd.schema.check_layout` against
  ``shm_schema/LAYOUT.md``;
* :mod:`gaitd.ipc` — where the daemon's iceoryx2 resources are (prefix,
  root path, file prefix), resolved as the daemon resolves them;
* :mod:`gaitd.api` — the command API of a client over any transport: send
  goals, cancel, hold, reset; read the status and events; wait for a goal's
  outcome;
* :mod:`gaitd.client` — that API over iceoryx2, on the daemon's host;
* :mod:`gaitd.remote` — the same from another host, through gaitd-bridge
  over Zenoh with mutual TLS (extra ``[remote]``);
* :mod:`gaitd.plant` — the :class:`~gaitd.plant.Plant` base class: attach
  your own hand or simulator (PLANT-GUIDE.md);
* :mod:`gaitd.setpoint` — checked setpoints and measurements, the plant's
  values;
* :mod:`gaitd.config` — what a plant reads from the daemon's ``gaitd.toml``;
* :mod:`gaitd.hand` — the paper's start grasp; :mod:`gaitd.quat` —
  quaternions; :mod:`gaitd.trace` — ``gait-trajectory/1`` traces as setpoints;
* :mod:`gaitd.plants.mujoco_plant` — the MuJoCo physics hand (extra
  ``[mujoco]``), run as ``python -m gaitd.plants.mujoco --config gaitd.toml``.

gaitd itself (Rust) never depends on this package.
"""

__version__ = "0.1.0"
