#!/usr/bin/env python3
"""gen-synthetic.py OUTDIR: write the two synthetic golden traces.

Unlike the captured traces (capture.sh: real candump on vcan0), these are
written frame by frame to reach every branch of the decoder, the formatters
and the analysis that a healthy bus never shows (odd NMT/heartbeat/EMCY/SDO
frames, PDO remapping and rerouting, error frames with controller details,
missing and late TPDOs, SYNC jitter beyond the histogram, a second bus):

  protocol.log  one of each kind of frame and each SDO transfer shape,
                decoded frame by frame (text and JSON) by golden.sh
  cyclic.log    two buses, SYNC at 1 ms with jitter and outliers, three
                drives (a lagging one, a silent/late one, one on every
                2nd SYNC), a fault and its reset, error frames; summarised
                with several option sets by golden.sh

Deterministic (no randomness, integer microseconds): re-running it gives
the checked-in files byte for byte.
"""
import os
import sys

T0 = 1700000000_000000  # microseconds


def line(t_us, iface, cid, data):
    if data == "R":
        payload = "R"
    else:
        payload = "".join(f"{b:02X}" for b in data)
    width = 8 if cid > 0x7FF else 3
    return f"({t_us // 1000000}.{t_us % 1000000:06d}) {iface} {cid:0{width}X}#{payload}\n"


def le(v, n):
    return [(v >> (8 * i)) & 0xFF for i in range(n)]


def sdo_w(node, index, sub, value, size):
    """Expedited download request and its response."""
    cs = 0x23 | ((4 - size) << 2)
    req = (0x600 + node, [cs] + le(index, 2) + [sub] + le(value, size) + [0] * (4 - size))
    rsp = (0x580 + node, [0x60] + le(index, 2) + [sub, 0, 0, 0, 0])
    return [req, rsp]


def protocol():
    f = []
    n1 = 1
    # NMT: reset all, a start of node 1, an unknown command, a short frame, RTR
    f += [(0x000, [0x81, 0x00]), (0x000, [0x01, 0x01]), (0x000, [0x07, 0x02]), (0x000, [0x01])]
    # boot-up, heartbeats (pre-op, bad state, long, toggled guard answer), guarding RTR, empty heartbeat
    f += [(0x701, [0x00]), (0x702, [0x00]), (0x701, [0x7F]), (0x703, [0x42]), (0x703, [0x7F, 0x00]),
          (0x701, "R"), (0x701, [0x85]), (0x704, [])]
    # TIME, LSS both ways, extended id, an id outside the connection set
    f += [(0x100, [1, 2, 3, 4, 5, 6]), (0x7E5, [0x04, 0, 0, 0, 0, 0, 0, 0]), (0x7E4, [0x44, 0, 0, 0, 0, 0, 0, 0]),
          (0x18FF0001, [0x11]), (0x050, [0x00])]
    # SYNC with a counter and a long one
    f += [(0x080, [0x05]), (0x080, [1, 2])]
    # EMCY: vendor bytes, short, not 8 bytes, reset (code 0)
    f += [(0x081, [0x10, 0x23, 0x03, 1, 2, 3, 4, 5]), (0x082, [0x10]), (0x082, [0x00, 0x50, 0x01, 0]),
          (0x081, [0, 0, 0, 0, 0, 0, 0, 0])]
    # expedited writes: mode, controlword (with halt), period 0x1006 (1000 us), EMCY COB-ID, SYNC COB-ID producer
    f += sdo_w(n1, 0x6060, 0, 8, 1)
    f += sdo_w(n1, 0x6040, 0, 0x010F, 2)
    f += sdo_w(n1, 0x1006, 0, 1000, 4)
    f += sdo_w(n1, 0x1014, 0, 0x80000081, 4)
    f += sdo_w(n1, 0x1005, 0, 0x40000080, 4)
    # remap TPDO2 of node 1 (statusword + velocity actual + mode display), type 1, moved to 0x3A1
    f += sdo_w(n1, 0x1A01, 0, 0, 1)
    f += sdo_w(n1, 0x1A01, 1, 0x60410010, 4)
    f += sdo_w(n1, 0x1A01, 2, 0x606C0020, 4)
    f += sdo_w(n1, 0x1A01, 3, 0x60610008, 4)
    f += sdo_w(n1, 0x1A01, 0, 3, 1)
    f += sdo_w(n1, 0x1801, 2, 1, 1)
    f += sdo_w(n1, 0x1801, 1, 0x000003A1, 4)
    # a dummy entry and a 0-entry mapping for RPDO2 of node 1
    f += sdo_w(n1, 0x1601, 0, 0, 1)
    f += sdo_w(n1, 0x1601, 1, 0x00050008, 4)
    f += sdo_w(n1, 0x1601, 2, 0x607A0020, 4)
    f += sdo_w(n1, 0x1601, 0, 2, 1)
    f += sdo_w(n1, 0x1602, 0, 0, 1)
    # uploads: statusword, position actual (negative), mode display, an unknown object, a signed 16-bit
    f += [(0x601, [0x40, 0x41, 0x60, 0, 0, 0, 0, 0]), (0x581, [0x4B, 0x41, 0x60, 0, 0x37, 0x0A, 0, 0])]
    f += [(0x601, [0x40, 0x64, 0x60, 0, 0, 0, 0, 0]), (0x581, [0x43, 0x64, 0x60, 0] + le(-12345 & 0xFFFFFFFF, 4))]
    f += [(0x601, [0x40, 0x61, 0x60, 0, 0, 0, 0, 0]), (0x581, [0x4F, 0x61, 0x60, 0, 0xFA, 0, 0, 0])]
    f += [(0x601, [0x40, 0x45, 0x23, 1, 0, 0, 0, 0]), (0x581, [0x43, 0x45, 0x23, 1, 0xDE, 0xAD, 0xBE, 0xEF])]
    f += [(0x601, [0x40, 0x71, 0x60, 0, 0, 0, 0, 0]), (0x581, [0x4B, 0x71, 0x60, 0, 0x18, 0xFC, 0, 0])]
    # a value shorter than its type (2 bytes for the 4-byte 0x1000)
    f += [(0x601, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]), (0x581, [0x4B, 0x00, 0x10, 0, 0x92, 0x01, 0, 0])]
    # segmented upload of 0x1008 (12 bytes, one non-printable), correct size
    f += [(0x601, [0x40, 0x08, 0x10, 0, 0, 0, 0, 0]), (0x581, [0x41, 0x08, 0x10, 0, 12, 0, 0, 0]),
          (0x601, [0x60, 0, 0, 0, 0, 0, 0, 0]), (0x581, [0x00] + list(b"Servo\"X")),
          (0x601, [0x70, 0, 0, 0, 0, 0, 0, 0]), (0x581, [0x10 | (2 << 1) | 1] + list(b"\x01 v1!") + [0, 0])]
    # segmented upload of 0x1009 announced 20, 3 delivered; a toggle mismatch on the way
    f += [(0x601, [0x40, 0x09, 0x10, 0, 0, 0, 0, 0]), (0x581, [0x41, 0x09, 0x10, 0, 20, 0, 0, 0]),
          (0x601, [0x60, 0, 0, 0, 0, 0, 0, 0]), (0x581, [0x10 | (4 << 1) | 1] + list(b"1.0") + [0] * 4)]
    # segmented upload without size indication
    f += [(0x601, [0x40, 0x0A, 0x10, 0, 0, 0, 0, 0]), (0x581, [0x40, 0x0A, 0x10, 0, 0, 0, 0, 0]),
          (0x601, [0x60, 0, 0, 0, 0, 0, 0, 0]), (0x581, [0x00 | (5 << 1) | 1] + list(b"ab") + [0] * 5)]
    # segmented download of 6 bytes to 0x2000:01 (an unknown object)
    f += [(0x601, [0x21, 0x00, 0x20, 0x01, 6, 0, 0, 0]), (0x581, [0x60, 0x00, 0x20, 0x01, 0, 0, 0, 0]),
          (0x601, [0x00 | (1 << 1) | 1, 1, 2, 3, 4, 5, 6, 0]), (0x581, [0x20, 0, 0, 0, 0, 0, 0, 0])]
    # segmented download of 4 bytes to 0x1006 (applied: 2000 us), response toggle wrong
    f += [(0x601, [0x21, 0x06, 0x10, 0x00, 4, 0, 0, 0]), (0x581, [0x60, 0x06, 0x10, 0x00, 0, 0, 0, 0]),
          (0x601, [0x00 | (3 << 1) | 1] + le(2000, 4) + [0, 0, 0]), (0x581, [0x30, 0, 0, 0, 0, 0, 0, 0])]
    # segmented download without size, in two segments (never confirmed as complete)
    f += [(0x601, [0x20, 0x00, 0x21, 0x00, 0, 0, 0, 0]), (0x581, [0x60, 0x00, 0x21, 0x00, 0, 0, 0, 0]),
          (0x601, [0x00, 1, 2, 3, 4, 5, 6, 7]), (0x581, [0x20, 0, 0, 0, 0, 0, 0, 0]),
          (0x601, [0x10 | (6 << 1) | 1, 8, 0, 0, 0, 0, 0, 0]), (0x581, [0x30, 0, 0, 0, 0, 0, 0, 0])]
    # orphan segments in both directions
    f += [(0x602, [0x00, 1, 2, 3, 4, 5, 6, 7]), (0x582, [0x20, 0, 0, 0, 0, 0, 0, 0]),
          (0x602, [0x60, 0, 0, 0, 0, 0, 0, 0]), (0x582, [0x00, 1, 2, 3, 4, 5, 6, 7])]
    # aborts by the server and by the client; an initiate-download response nobody asked for
    f += [(0x601, [0x2F, 0x60, 0x60, 0, 0x42, 0, 0, 0]), (0x581, [0x80, 0x60, 0x60, 0] + le(0x06090030, 4)),
          (0x601, [0x80, 0x08, 0x10, 0] + le(0x05040000, 4)), (0x581, [0x60, 0x40, 0x60, 0, 0, 0, 0, 0])]
    # block transfer, invalid command specifier, short SDO, RTR on an SDO id
    f += [(0x601, [0xC6, 0x00, 0x20, 0x01, 100, 0, 0, 0]), (0x581, [0xA4, 0x00, 0x20, 0x01, 0x7F, 0, 0, 0]),
          (0x601, [0xE0, 0, 0, 0, 0, 0, 0, 0]), (0x581, [0xE0, 0, 0, 0, 0, 0, 0, 0]), (0x601, [0x40, 0x41]),
          (0x601, "R")]
    # PDOs: default TPDO1/RPDO1, the remapped TPDO2 on its new id (and the old id now unused),
    # an unmapped TPDO3, a remote request, a short and a long TPDO1, the 2-entry RPDO2, the disabled RPDO3 mapping
    f += [(0x181, [0x37, 0x06, 0xA0, 0x86, 0x01, 0x00]), (0x201, [0x0F, 0x00, 0x10, 0x27, 0, 0]),
          (0x3A1, [0x37, 0x02, 0x18, 0xFC, 0xFF, 0xFF, 0xF7]), (0x281, [0x37, 0x06]),
          (0x381, [1, 2, 3]), (0x181, "R"), (0x181, [0x37, 0x06]), (0x181, [0x37, 0x06, 0, 0, 0, 0, 0, 0]),
          (0x301, [0x55, 0xE8, 0x03, 0, 0]), (0x401, [0x01]), (0x182, [0x18, 0x02, 0, 0, 0, 0])]
    # the TPDO2 COB-ID made invalid: 0x3A1 is node 33's TPDO3 again
    f += sdo_w(n1, 0x1801, 1, 0x800003A1, 4)
    f += [(0x3A1, [1, 2])]
    # error frames: controller problem with details, counters, bus-off, an unnamed class bit
    f += [(0x20000004, [0, 0x0C, 0, 0, 0, 0, 0, 0]), (0x20000004, [0, 0x04, 0, 0, 0, 0, 0x60, 0x7F]),
          (0x20000040, [0] * 8), (0x20000880, [0] * 8), (0x20000000, [0] * 8)]
    out = []
    t = T0
    for cid, data in f:
        out.append(line(t, "vcan0", cid, data))
        t += 137
    return out


def cyclic():
    frames = []  # (t_us, iface, id, data)

    def add(t, cid, data, iface="vcan0"):
        frames.append((t, iface, cid, data))

    t = T0
    # boot: NMT start all, boot-ups, configuration (TPDO transmission types, period), heartbeats
    add(t, 0x000, [0x82, 0x00]); t += 400
    for n in (1, 2, 3):
        add(t, 0x700 + n, [0x00]); t += 300
    for n, tt in ((1, 1), (2, 1), (3, 2)):
        for cid, data in sdo_w(n, 0x1800, 2, tt, 1):
            add(t, cid, data); t += 250
    for cid, data in sdo_w(1, 0x1006, 0, 1000, 4):
        add(t, cid, data); t += 250
    # a client abort the summary lists "by master"
    add(t, 0x602, [0x80, 0x64, 0x60, 0] + le(0x08000020, 4)); t += 250
    add(t, 0x000, [0x01, 0x00]); t += 300
    for n in (1, 2, 3):
        add(t, 0x700 + n, [0x05]); t += 300
    # cyclic part: 220 SYNCs at a nominal 1 ms
    sync0 = t + 1000
    target = {1: 0, 2: 0, 3: 0}
    applied = {1: [], 2: [], 3: []}
    sw = {1: 0x0250, 2: 0x0250, 3: 0x0250}
    pos = {1: 1000, 2: -500, 3: 0}
    t_sync = sync0
    for k in range(220):
        jitter = ((k * 37) % 23) - 11  # -11 .. +11 us
        if k == 60:
            jitter = 900   # far beyond the histogram
        if k == 61:
            jitter = -700
        if k == 120:
            jitter = 2100  # a lost SYNC
        t_sync += 1000 + jitter if k else 0
        add(t_sync, 0x080, [])
        tk = t_sync + 40
        # controlword sequence for node 1 and 2: shutdown, switch on, enable; fault reset later
        cw = 0x06 if k < 5 else 0x07 if k < 10 else 0x0F
        if 150 <= k < 152:
            cw = 0x80
        if k >= 15:
            target[1] += 20 * min(k - 14, 50)
            target[2] += 7
            target[3] += 3
        for n in (1, 2, 3):
            applied[n].append(target[n])
        # RPDOs of this cycle (applied at the next SYNC)
        for n in (1, 2, 3):
            add(tk, 0x200 + n, [cw & 0xFF, cw >> 8] + le(target[n] & 0xFFFFFFFF, 4)); tk += 130
        # state machine as the drives answer
        for n in (1, 2, 3):
            s = sw[n]
            if cw == 0x06:
                s = 0x0231
            elif cw == 0x07:
                s = 0x0233
            elif cw == 0x0F and s in (0x0233, 0x0237, 0x0A37):
                s = 0x0237
            elif cw == 0x80 and s == 0x0218:
                s = 0x0250
            if n == 1 and k == 140:
                s = 0x0218  # fault
            if n == 1 and 140 <= k < 150:
                s = 0x0218
            if n == 1 and k in (152, 153, 154):
                s = (0x0231, 0x0233, 0x0237)[k - 152]
            if n == 2 and k == 100:
                s = 0x0A37  # warning bit
            sw[n] = s
        # positions: node 1 lags one SYNC (actual = target applied one SYNC earlier - 3),
        # node 2 follows with a small error, node 3 exact
        if len(applied[1]) >= 3:
            pos[1] = applied[1][-3] - 3
        if len(applied[2]) >= 2:
            pos[2] = applied[2][-2] + (k % 5) - 2
        if len(applied[3]) >= 2:
            pos[3] = applied[3][-2]
        # TPDOs
        if not (90 <= k < 104):  # node 1 silent for 14 cycles
            add(tk, 0x181, le(sw[1], 2) + le(pos[1] & 0xFFFFFFFF, 4)); tk += 130
        if k not in (30, 31, 170):  # node 2: two missed, one of them made up late; one more miss
            add(tk, 0x182, le(sw[2], 2) + le(pos[2] & 0xFFFFFFFF, 4)); tk += 130
            if k in (32, 171):
                add(tk, 0x182, le(sw[2], 2) + le(pos[2] & 0xFFFFFFFF, 4)); tk += 130
        if k % 2 == 0 and not (k in (80, 82)):  # node 3: every 2nd SYNC, two misses
            add(tk, 0x183, le(sw[3], 2) + le(pos[3] & 0xFFFFFFFF, 4)); tk += 130
        # events
        if k == 140:
            add(tk, 0x081, [0x10, 0x23, 0x03, 0, 0, 0, 0, 0]); tk += 130
        if k == 151:
            add(tk, 0x081, [0, 0, 0, 0, 0, 0, 0, 0]); tk += 130
        if k == 70:
            add(tk, 0x20000004, [0, 0x08, 0, 0, 0, 0, 0x80, 0]); tk += 130
        if k == 71:
            add(tk, 0x20000040, [0] * 8); tk += 130
        if k == 72:
            add(tk, 0x20000100, [0] * 8); tk += 130
        if k == 180:
            add(tk, 0x000, [0x02, 0x03]); tk += 130  # stop node 3: no more TPDOs expected
        if k == 190:
            for cid, data in sdo_w(3, 0x1800, 2, 254, 1):
                add(tk, cid, data); tk += 130
            add(tk, 0x000, [0x01, 0x03]); tk += 130
        if k % 50 == 0:
            for n in (1, 2, 3):
                add(tk, 0x700 + n, [0x05 if not (n == 3 and k >= 180) else 0x04]); tk += 130
    # the second bus: a few SYNCs and one drive
    t2 = sync0 + 500
    for k in range(12):
        add(t2, 0x080, [], "vcan1")
        if k != 5:
            add(t2 + 60, 0x181, le(0x0237, 2) + le(k * 10, 4), "vcan1")
        t2 += 2000
    add(t2, 0x20000004, [0, 0x10, 0, 0, 0, 0, 0, 0], "vcan1")
    frames.sort(key=lambda x: (x[0], x[1]))
    return [line(t, iface, cid, data) for t, iface, cid, data in frames]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    with open(os.path.join(out, "protocol.log"), "w") as fh:
        fh.writelines(protocol())
    with open(os.path.join(out, "cyclic.log"), "w") as fh:
        fh.writelines(cyclic())


if __name__ == "__main__":
    main()
