#!/usr/bin/env python3
"""The ``gaitd`` package's ctypes mirror matches LAYOUT.md, and a broken mirror does not.

Run by ``tests/tests/python_schema.rs``. Prints one JSON object:
``problems`` (must be empty) for the real mirror, and for each deliberate
mutation the problems ``check_layout`` reported (each must be caught):

* ``swapped_fields``: ``PlantFingerMeasurement`` with ``roll`` and
  ``normal_force`` swapped (same size: only the offsets differ);
* ``missing_padding``: ``PlantCommand`` without its ``reserved`` word
  (every later offset moves by 4);
* ``old_type_name``: ``Status`` named ``gaitd::Status.v1``;
* ``renumbered_code``: ``PlantFault`` with ``Diverged`` = 5;
* ``wrong_bit``: ``CommandFlags`` with ``HOLD`` = 8.

Usage: schema_check.py LAYOUT.md
"""

from __future__ import annotations

import ctypes
import enum
import json
import sys

from gaitd import schema
from gaitd.schema import layout_problems


def replace_payload(cls: type[ctypes.Structure], fields: list, type_name: str | None = None) -> list:
    """The payload list with ``cls`` replaced by a copy that has ``fields`` (and a type name)."""
    name = type_name or cls.type_name()
    broken = type(cls.__name__, (ctypes.Structure,), {"_fields_": fields})
    broken.type_name = classmethod(lambda _c: name)
    return [broken if c is cls else c for c in schema.PAYLOADS]


def main() -> int:
    layout = sys.argv[1]
    out: dict = {"problems": layout_problems(layout), "mutations": {}}

    f = list(schema.PlantFingerMeasurement._fields_)
    i, j = [n for n, _ in f].index("roll"), [n for n, _ in f].index("normal_force")
    f[i], f[j] = f[j], f[i]
    out["mutations"]["swapped_fields"] = layout_problems(layout, replace_payload(schema.PlantFingerMeasurement, f))

    f = [x for x in schema.PlantCommand._fields_ if x[0] != "reserved"]
    out["mutations"]["missing_padding"] = layout_problems(layout, replace_payload(schema.PlantCommand, f))

    out["mutations"]["old_type_name"] = layout_problems(
        layout, replace_payload(schema.Status, list(schema.Status._fields_), "gaitd::Status.v1")
    )

    members = {("None" if m.name == "None_" else m.name): int(m) for m in schema.PlantFault}
    members["Diverged"] = 5
    members["Other"] = 4
    fault = enum.IntEnum("PlantFault", members)
    tables = [fault if t is schema.PlantFault else t for t in schema.CODE_TABLES]
    out["mutations"]["renumbered_code"] = layout_problems(layout, code_tables=tables)

    original = schema.CommandFlags
    schema.CommandFlags = enum.IntFlag("CommandFlags", {"ENABLE": 1, "HOLD": 8, "LOCKSTEP": 4})
    try:
        out["mutations"]["wrong_bit"] = layout_problems(layout)
    finally:
        schema.CommandFlags = original

    json.dump(out, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
