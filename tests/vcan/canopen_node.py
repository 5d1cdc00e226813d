#!/usr/bin/env python3
"""An independent CANopen device for tests/vcan_master.rs: python-canopen's LocalNode.

Serves SDO and NMT on a SocketCAN interface with the objects the dnurbs master configures
(CiA-301 communication and mapping parameters, CiA-402 0x6060/0x6061/0x6064/0x607A/0x60C2,
and what a drive guards by itself: 0x605A/0x605E/0x6065/0x6066/0x607D).
python-canopen leaves the device application to its user; this script adds the parts a
drive has and LocalNode does not: a boot-up message and pre-operational after an NMT reset,
and 0x6061 (modes of operation display) following 0x6060.

When the node is put in Operational (NMT start), the values the master wrote are saved as
JSON to --out and the script exits.

    canopen_node.py IFACE --node 7 --position 12345 --out node.json
"""
import argparse
import json
import struct
import sys
import threading

import canopen
from canopen import objectdictionary as od


def variable(name, index, sub, data_type, access, default):
    v = od.ODVariable(name, index, sub)
    v.data_type = data_type
    v.access_type = access
    v.default = default
    return v


def dictionary(node_id, position):
    d = od.ObjectDictionary()
    d.add_object(variable("Device type", 0x1000, 0, od.UNSIGNED32, "ro", 0x00020192))
    d.add_object(variable("Heartbeat producer", 0x1017, 0, od.UNSIGNED16, "rw", 0))
    for index, name, entries in [
        (0x1400, "RPDO1 communication", [(1, od.UNSIGNED32, 0x200 + node_id), (2, od.UNSIGNED8, 0xFF)]),
        (0x1800, "TPDO1 communication", [(1, od.UNSIGNED32, 0x180 + node_id), (2, od.UNSIGNED8, 0xFF)]),
        (0x1600, "RPDO1 mapping", [(s, od.UNSIGNED32, 0) for s in range(1, 9)]),
        (0x1A00, "TPDO1 mapping", [(s, od.UNSIGNED32, 0) for s in range(1, 9)]),
        (0x60C2, "Interpolation time period", [(1, od.UNSIGNED8, 1), (2, od.INTEGER8, -3)]),
        (0x607D, "Software position limit", [(1, od.INTEGER32, -(2**31)), (2, od.INTEGER32, 2**31 - 1)]),
    ]:
        record = od.ODRecord(name, index)
        count = 0 if index in (0x1600, 0x1A00) else len(entries)
        record.add_member(variable("count", index, 0, od.UNSIGNED8, "rw" if count == 0 else "ro", count))
        for sub, data_type, default in entries:
            record.add_member(variable(f"sub{sub}", index, sub, data_type, "rw", default))
        d.add_object(record)
    d.add_object(variable("Controlword", 0x6040, 0, od.UNSIGNED16, "rw", 0))
    d.add_object(variable("Statusword", 0x6041, 0, od.UNSIGNED16, "ro", 0x0250))
    d.add_object(variable("Quick stop option code", 0x605A, 0, od.INTEGER16, "rw", 2))
    d.add_object(variable("Fault reaction option code", 0x605E, 0, od.INTEGER16, "rw", 2))
    d.add_object(variable("Modes of operation", 0x6060, 0, od.INTEGER8, "rw", 0))
    d.add_object(variable("Modes of operation display", 0x6061, 0, od.INTEGER8, "ro", 0))
    d.add_object(variable("Position actual value", 0x6064, 0, od.INTEGER32, "ro", position))
    d.add_object(variable("Following error window", 0x6065, 0, od.UNSIGNED32, "rw", 0xFFFFFFFF))
    d.add_object(variable("Following error time out", 0x6066, 0, od.UNSIGNED16, "rw", 0))
    d.add_object(variable("Target position", 0x607A, 0, od.INTEGER32, "rw", position))
    return d


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("iface")
    p.add_argument("--node", type=int, default=7)
    p.add_argument("--position", type=int, default=12345)
    p.add_argument("--out", required=True)
    p.add_argument("--timeout", type=float, default=60.0)
    a = p.parse_args()

    network = canopen.Network()
    node = canopen.LocalNode(a.node, dictionary(a.node, a.position))
    network.add_node(node)
    started = threading.Event()

    def on_write(index, subindex, od, data):
        if index == 0x6060:
            node.data_store.setdefault(0x6061, {})[0] = bytes(data)

    def on_nmt(can_id, data, timestamp):
        cmd, target = struct.unpack_from("BB", data)
        if target not in (0, a.node):
            return
        if cmd in (0x81, 0x82):
            node.nmt.send_command(cmd)  # INITIALISING: sends the boot-up message
            node.nmt.send_command(0x80)  # then pre-operational, as a device does by itself
        elif cmd == 0x01:
            started.set()

    node.add_write_callback(on_write)
    network.connect(interface="socketcan", channel=a.iface)
    network.subscribe(0, on_nmt)
    node.nmt.send_command(0x82)
    node.nmt.send_command(0x80)
    print("ready", flush=True)
    ok = started.wait(a.timeout)
    values = {f"{i:04X}:{s:02X}": int.from_bytes(v, "little", signed=(i in (0x605A, 0x605E, 0x6060, 0x6061, 0x6064, 0x607A, 0x607D) or (i, s) == (0x60C2, 2)))
              for i, subs in node.data_store.items() for s, v in subs.items()}
    with open(a.out, "w") as f:
        json.dump({"started": ok, "nmt_state": node.nmt.state, "values": values}, f, indent=1, sort_keys=True)
    network.disconnect()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
