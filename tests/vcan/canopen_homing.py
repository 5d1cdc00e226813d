#!/usr/bin/env python3
"""An independent CiA-402 master for tests/vcan_master.rs: python-canopen's BaseNode402.

Homes and enables one node of a `dnurbs sim-drives` process on a SocketCAN interface, the
way python-canopen's CiA-402 profile does it: its PDOs configured over SDO (RPDO1 the
controlword, applied on receipt; TPDO1 the statusword and the position actual value, every
SYNC), the network's SYNC producer running, NMT start, homing mode and method by SDO, then
`BaseNode402.homing()` (Operation enabled, controlword bit 4, the statusword's homing bits
until attained), then the drive at rest (target reached), then `state = 'OPERATION
ENABLED'` again to check the drive stays there.
Prints one JSON line: whether it homed, the state, the mode, the position actual value.

    canopen_homing.py IFACE --node 1 --method 3 --offset 1000
"""
import argparse
import json
import sys
import time

import canopen
from canopen import objectdictionary as od
from canopen.profiles.p402 import BaseNode402


def variable(name, index, sub, data_type, access):
    v = od.ODVariable(name, index, sub)
    v.data_type = data_type
    v.access_type = access
    return v


def dictionary():
    """The simulated drive's objects this master uses (the drive's own table is in
    drives/src/sim/tables.rs)."""
    d = od.ObjectDictionary()
    for index, name, entries in [
        (0x1400, "RPDO1 communication", [(1, od.UNSIGNED32), (2, od.UNSIGNED8)]),
        (0x1800, "TPDO1 communication", [(1, od.UNSIGNED32), (2, od.UNSIGNED8)]),
        (0x1600, "RPDO1 mapping", [(s, od.UNSIGNED32) for s in range(1, 9)]),
        (0x1A00, "TPDO1 mapping", [(s, od.UNSIGNED32) for s in range(1, 9)]),
        (0x6099, "Homing speeds", [(1, od.UNSIGNED32), (2, od.UNSIGNED32)]),
    ]:
        record = od.ODRecord(name, index)
        record.add_member(variable("count", index, 0, od.UNSIGNED8, "rw"))
        for sub, data_type in entries:
            record.add_member(variable(f"sub{sub}", index, sub, data_type, "rw"))
        d.add_object(record)
    for index, name, data_type, access in [
        (0x6040, "Controlword", od.UNSIGNED16, "rw"),
        (0x6041, "Statusword", od.UNSIGNED16, "ro"),
        (0x6060, "Modes of operation", od.INTEGER8, "rw"),
        (0x6061, "Modes of operation display", od.INTEGER8, "ro"),
        (0x6064, "Position actual value", od.INTEGER32, "ro"),
        (0x607C, "Home offset", od.INTEGER32, "rw"),
        (0x6098, "Homing method", od.INTEGER8, "rw"),
        (0x609A, "Homing acceleration", od.UNSIGNED32, "rw"),
        (0x6502, "Supported drive modes", od.UNSIGNED32, "ro"),
    ]:
        d.add_object(variable(name, index, 0, data_type, access))
    return d


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("iface")
    p.add_argument("--node", type=int, default=1)
    p.add_argument("--method", type=int, default=3)
    p.add_argument("--offset", type=int, default=0)
    p.add_argument("--period", type=float, default=0.01)
    a = p.parse_args()

    network = canopen.Network()
    network.connect(interface="socketcan", channel=a.iface)
    node = BaseNode402(a.node, dictionary())
    network.add_node(node)
    result = {"node": a.node, "method": a.method}
    try:
        node.nmt.state = "PRE-OPERATIONAL"
        node.tpdo.read()
        node.rpdo.read()
        node.rpdo[1].clear()
        node.rpdo[1].add_variable(0x6040)
        node.rpdo[1].trans_type = 255
        node.rpdo[1].enabled = True
        node.tpdo[1].clear()
        node.tpdo[1].add_variable(0x6041)
        node.tpdo[1].add_variable(0x6064)
        node.tpdo[1].trans_type = 1
        node.tpdo[1].enabled = True
        node.rpdo.save()
        node.tpdo.save()
        node.setup_402_state_machine(read_pdos=False)
        network.sync.start(a.period)
        node.nmt.state = "OPERATIONAL"
        node.tpdo[1].wait_for_reception(timeout=5.0)
        node.sdo[0x6098].raw = a.method
        node.sdo[0x607C].raw = a.offset
        result["homed"] = node.homing(timeout=60)
        # homing() returns once attained, the motor perhaps still stopping: wait for rest.
        status = node._homing_status()
        deadline = time.monotonic() + 10.0
        while status == "ATTAINED" and time.monotonic() < deadline:
            status = node._homing_status()
        result["homing_status"] = status
        node.state = "OPERATION ENABLED"
        result["state"] = node.state
        result["op_mode"] = node.op_mode
        result["position"] = node.sdo[0x6064].raw
        result["statusword"] = node.statusword
        node.state = "SWITCH ON DISABLED"
    except Exception as e:  # reported to the test, which fails with it
        result["error"] = f"{type(e).__name__}: {e}"
    finally:
        network.sync.stop()
        network.disconnect()
    print(json.dumps(result), flush=True)
    return 0 if "error" not in result else 1


if __name__ == "__main__":
    sys.exit(main())
