#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""python-can (Debian's python3-can) reads a candump -l log written by
CandumpLogWriter: every frame with its time, identifier, length and bytes, and
each HRG message with the DLC the DBC gives it.

usage: check_python_can.py LOG DBC
"""
import re
import sys

import can


def main():
    log, dbc = sys.argv[1], sys.argv[2]
    dlc = {int(m.group(1)): int(m.group(2))
           for m in re.finditer(r"^BO_ (\d+) \w+: (\d+)", open(dbc).read(), re.M)}
    lines = [l.split() for l in open(log) if l.strip()]
    msgs = list(can.CanutilsLogReader(log))
    if len(msgs) != len(lines) or not msgs:
        sys.exit(f"python-can read {len(msgs)} frames, the log has {len(lines)}")
    for n, (msg, (ts, chan, frame)) in enumerate(zip(msgs, lines), 1):
        ident, data = frame.split("#")
        want = bytes.fromhex(data)
        if (abs(msg.timestamp - float(ts.strip("()"))) > 1e-7 or msg.channel != chan
                or msg.arbitration_id != int(ident, 16) or bytes(msg.data) != want
                or msg.dlc != len(want) or msg.is_extended_id != (len(ident) == 8)):
            sys.exit(f"line {n}: python-can read {msg}, the log says {ts} {chan} {frame}")
        if msg.arbitration_id in dlc and msg.dlc != dlc[msg.arbitration_id]:
            sys.exit(f"line {n}: DLC {msg.dlc}, the DBC says {dlc[msg.arbitration_id]}")
    print(f"python-can {can.__version__}: {len(msgs)} frames read as written")


if __name__ == "__main__":
    main()
