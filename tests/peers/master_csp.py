#!/usr/bin/python3
"""master_csp.py: an independent CiA 402 master for one CSP drive, written
from the CiA 301 / CiA 402 tables on python-can (with link.py and
spec_checks.py of tests/peers; nothing of canmotion's fieldbus/).

It does what a new user's master does with a drive described by an EDS
(issue 26 item 3), one step after the other, each reported PASS or FAIL:

  boot      NMT reset node, the boot-up (700h+node, 00h), transition 1
  mode      0x6502 has CSP (bit 7); 0x6060 = 8 over SDO in pre-operational,
            before any SYNC, and 0x6061 read back = 8 (as python-canopen's
            op_mode does); a mode outside 0x6502 (CSV) is refused with
            0609 0030h and 0x6061 still shows 8
  pdos      RPDO1 = 0x6040 + 0x607A, TPDO1 = 0x6041 + 0x6064, transmission
            type 1, by the CiA 301 re-mapping procedure; 0x60C2 = the period
  start     0x1017 heartbeat, NMT start, a heartbeat showing 05h
  enable    transitions 2, 3, 4 by RPDO1 + SYNC: Operation enabled, bit 12
  move      a cosine move of --distance counts over --move-cycles SYNCs, then
            --hold-cycles at rest: every TPDO1's position within
            --tolerance of the target, the end reached to 1 count
  end       0x6061 still 8, no EMCY from the drive during the whole run

Cycles, not seconds, are what the checks count: each cycle sends RPDO1 and
a SYNC and waits for the TPDO1 of that SYNC (lock-step: a slow, emulated
host only makes a cycle longer). Times are only limits on waiting.

--check-trace FILE reads a candump -L trace of such a run and checks from
the wire alone: the boot-up after NMT reset node, 0x6060 = 8 written and
0x6061 = 8 read before the first SYNC, NMT start before the first RPDO1, one
TPDO1 per SYNC, the move's distance between the first and last TPDO1, and
no EMCY.

Exit status: 0 when every step passed, 1 otherwise, 2 on bad arguments.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import spec_checks  # noqa: E402
from link import SdoAbort  # noqa: E402

# CiA 301 identifiers (function code + node-ID) and NMT commands.
NMT, SYNC, EMCY, TPDO1, RPDO1, SDO_TX, SDO_RX, HEARTBEAT = 0x000, 0x080, 0x080, 0x180, 0x200, 0x580, 0x600, 0x700
NMT_START, NMT_RESET_NODE = 0x01, 0x81
HB_OPERATIONAL = 0x05
# CiA 402: modes (0x6060), their bits in 0x6502, controlword commands, statusword bits.
MODE_CSP, MODE_CSV = 8, 9
SUPPORTS_CSP, SUPPORTS_CSV = 1 << 7, 1 << 8
CW_SHUTDOWN, CW_SWITCH_ON, CW_ENABLE_OPERATION = 0x0006, 0x0007, 0x000F
SW_FOLLOWS_COMMAND = 1 << 12
ABORT_INVALID_VALUE, ABORT_READ_ONLY = 0x06090030, 0x06010002


class StepFailed(Exception):
    pass


def expect(cond, why):
    if not cond:
        raise StepFailed(why)


class CspMaster:
    """The master's steps over a link.Link to one drive (node)."""

    def __init__(self, link, node: int, period: float = 0.01, patience: float = 2.0, mode_reads: int = 10):
        self.ctx = spec_checks.Ctx(link, node, period, patience)
        self.link, self.node, self.period, self.patience = link, node, period, patience
        self.mode_reads = mode_reads      # SDO reads of 0x6061 before "not shown" (no SYNC in between)
        self.sdo = self.ctx.sdo
        self.cycles = 0                   # SYNCs sent
        self.statusword, self.position = 0, None

    # ---- one cycle -------------------------------------------------------------------------
    def cycle(self, cw: int, target: int):
        """RPDO1 (controlword, target), SYNC, and that SYNC's TPDO1."""
        self.link.send(RPDO1 + self.node, struct.pack('<Hi', cw, target))
        self.link.send(SYNC)
        self.cycles += 1
        f = self.link.wait_for(lambda i, d: i == TPDO1 + self.node, self.patience)
        expect(f is not None, f'no TPDO1 within {self.patience} s of SYNC {self.cycles}')
        expect(len(f[2]) == 6, f'TPDO1 of {len(f[2])} bytes after SYNC {self.cycles}, want 6 (0x6041 + 0x6064)')
        self.statusword, self.position = struct.unpack('<Hi', f[2])
        self.link.advance(self.period)

    def state(self) -> str:
        return spec_checks.state_of(self.statusword)

    def emcys(self):
        return [f for f in self.link.log if f[1] == EMCY + self.node]

    # ---- the steps ---------------------------------------------------------------------------
    def step_boot(self):
        self.ctx.reset()      # NMT reset node, boot-up 00h, then transition 1 (Switch on disabled)
        dt = self.sdo.read(0x1000)
        expect(dt & 0xFFFF == 402, f'0x1000 = 0x{dt:08X}: not a CiA 402 device')
        return f'boot-up after NMT reset node, switch on disabled, device type 0x{dt:08X}'

    def step_mode(self):
        modes = self.sdo.read(0x6502)
        expect(modes & SUPPORTS_CSP, f'0x6502 = 0x{modes:08X}: CSP (bit 7) not supported')
        before = self.sdo.read(0x6061, 0, '<b')
        self.sdo.write(0x6060, 0, MODE_CSP, '<b')
        shown, reads = None, 0
        while shown != MODE_CSP and reads < self.mode_reads:
            shown, reads = self.sdo.read(0x6061, 0, '<b'), reads + 1
        expect(shown == MODE_CSP, f'0x6060 = 8 written in pre-operational, 0x6061 still shows {shown} after '
                                  f'{reads} reads (no SYNC sent yet; it showed {before} before)')
        note = f'0x6061 {before} -> 8 after {reads} read(s), no SYNC'
        if not modes & SUPPORTS_CSV:
            code = self.sdo.abort_code(self.sdo.write, 0x6060, 0, MODE_CSV, '<b')
            expect(code == ABORT_INVALID_VALUE, f'0x6060 = 9 (CSV, not in 0x6502 = 0x{modes:08X}): '
                                                f'{"accepted" if code is None else f"abort 0x{code:08X}"}, '
                                                f'want abort 0x{ABORT_INVALID_VALUE:08X}')
            shown = self.sdo.read(0x6061, 0, '<b')
            expect(shown == MODE_CSP, f'0x6061 = {shown} after the refused 0x6060 = 9, want 8')
            note += f'; 0x6060 = 9 refused (0x6502 = 0x{modes:08X})'
        return note

    def step_pdos(self):
        self.ctx.csp_pdos()   # CiA 301 re-mapping, steps 1..5, transmission type 1
        ms = max(1, round(self.period * 1000))
        self.sdo.write(0x60C2, 1, min(ms, 255), '<B')
        code = self.sdo.abort_code(self.sdo.write, 0x60C2, 2, -3, '<b')
        expect(code in (None, ABORT_READ_ONLY), f'0x60C2:2 = -3: abort 0x{code or 0:08X}')
        index = self.sdo.read(0x60C2, 2, '<b')
        expect(index == -3, f'0x60C2:2 is {index}: the period in ms cannot be written')
        return f'RPDO1 = 0x6040 + 0x607A, TPDO1 = 0x6041 + 0x6064, type 1; 0x60C2 = {min(ms, 255)} ms'

    def step_start(self):
        self.sdo.write(0x1017, 0, 100, '<H')
        self.link.clear()
        self.ctx.nmt(NMT_START)
        f = self.link.wait_for(lambda i, d: i == HEARTBEAT + self.node and d == bytes([HB_OPERATIONAL]),
                               3 * self.patience)
        expect(f is not None, f'no heartbeat 05h (operational) within {3 * self.patience} s of NMT start')
        return 'heartbeat 05h after NMT start'

    def step_enable(self, limit: int = 20):
        self.position = self.sdo.read(0x6064, 0, '<i')
        hold = self.position          # the target stays at the actual position: no jump at enable
        for cw, want, transition in ((CW_SHUTDOWN, 'ready to switch on', 2),
                                     (CW_SWITCH_ON, 'switched on', 3),
                                     (CW_ENABLE_OPERATION, 'operation enabled', 4)):
            for _ in range(limit):
                self.cycle(cw, hold)
                if self.state() == want:
                    break
            expect(self.state() == want, f'controlword 0x{cw:04X} for {limit} cycles: {self.state()} '
                                         f'(statusword 0x{self.statusword:04X}), want {want} (transition {transition})')
        expect(self.statusword & SW_FOLLOWS_COMMAND, f'statusword 0x{self.statusword:04X}: bit 12 (CSP: drive '
                                                     f'follows the command value) not set')
        expect(self.position == hold, f'position {self.position} after enable, was {hold}: the drive jumped')
        return f'operation enabled after {self.cycles} cycles at position {hold}'

    def step_move(self, distance: int, move_cycles: int, hold_cycles: int, tolerance: int):
        start = self.position
        worst, worst_at = 0, 0
        for k in range(1, move_cycles + hold_cycles + 1):
            s = min(k, move_cycles) / move_cycles
            target = start + round(distance * (1 - math.cos(math.pi * s)) / 2)
            self.cycle(CW_ENABLE_OPERATION, target)
            expect(self.state() == 'operation enabled' and self.statusword & SW_FOLLOWS_COMMAND,
                   f'cycle {k} of the move: statusword 0x{self.statusword:04X} ({self.state()})')
            err = abs(target - self.position)
            if err > worst:
                worst, worst_at = err, k
            expect(err <= tolerance, f'cycle {k} of the move: position {self.position}, target {target}: '
                                     f'following error {err} > {tolerance} counts')
        end = start + distance
        expect(abs(self.position - end) <= 1, f'after {hold_cycles} cycles at rest: position {self.position}, '
                                              f'want {end}')
        return (f'{distance} counts in {move_cycles} cycles + {hold_cycles} at rest: ended at {self.position}; '
                f'largest following error {worst} counts (cycle {worst_at})')

    def step_end(self):
        shown = self.sdo.read(0x6061, 0, '<b')
        expect(shown == MODE_CSP, f'0x6061 = {shown} at the end, want 8')
        self.link.poll()
        emcy = self.emcys()
        expect(not emcy, f'{len(emcy)} EMCY from node {self.node}: ' + ', '.join(f[2].hex() for f in emcy[:5]))
        for _ in range(5):
            self.cycle(CW_SHUTDOWN, self.position)
            if self.state() == 'ready to switch on':
                break
        expect(self.state() == 'ready to switch on', f'shutdown: {self.state()}')
        return f'0x6061 = 8, no EMCY in {self.cycles} cycles; shut down (transition 8)'

    def run(self, distance=20000, move_cycles=200, hold_cycles=20, tolerance=2000, out=print) -> bool:
        """Every step in order, until one fails; True if none did."""
        steps = (('boot', self.step_boot), ('mode', self.step_mode), ('pdos', self.step_pdos),
                 ('start', self.step_start), ('enable', self.step_enable),
                 ('move', lambda: self.step_move(distance, move_cycles, hold_cycles, tolerance)),
                 ('end', self.step_end))
        for name, fn in steps:
            try:
                out(f'PASS {name}: {fn()}')
            except (StepFailed, AssertionError, SdoAbort, TimeoutError) as e:
                out(f'FAIL {name}: {e}')
                return False
        return True


# ---- the trace --------------------------------------------------------------------------------

LINE = re.compile(r'^\((\d+\.\d+)\)\s+\S+\s+([0-9A-Fa-f]{3})#([0-9A-Fa-f]*)\s*$')


def read_trace(path):
    """(can_id, bytes) of every standard frame of a candump -L log, in order."""
    frames = []
    with open(path) as f:
        for line in f:
            m = LINE.match(line.strip())
            if m:
                frames.append((int(m.group(2), 16), bytes.fromhex(m.group(3))))
    return frames


def check_trace(frames, node: int, distance: int):
    """From the wire alone; a list of (ok, text)."""
    results = []

    def first(pred, start=0):
        return next((k for k in range(start, len(frames)) if pred(*frames[k])), None)

    def item(ok, text):
        results.append((bool(ok), text))

    reset = first(lambda i, d: i == NMT and d == bytes([NMT_RESET_NODE, node]))
    boot = first(lambda i, d: i == HEARTBEAT + node and d == b'\x00', reset or 0)
    item(reset is not None and boot is not None, f'boot-up {HEARTBEAT + node:03X}#00 after NMT reset node')
    first_sync = first(lambda i, d: i == SYNC)
    item(first_sync is not None, 'SYNCs on the bus')
    end = first_sync if first_sync is not None else len(frames)
    # SDO download 0x6060:00 = 8 (1 byte, expedited) and its confirmation, then an
    # expedited upload of 0x6061:00 answered with 8, all before the first SYNC.
    wr = first(lambda i, d: i == SDO_RX + node and d[:5] == bytes([0x2F, 0x60, 0x60, 0x00, MODE_CSP]))
    confirmed = shown = None
    if wr is not None:
        confirmed = first(lambda i, d: i == SDO_TX + node and d[:4] == bytes([0x60, 0x60, 0x60, 0x00]), wr)
        shown = first(lambda i, d: i == SDO_TX + node and len(d) >= 5 and d[0] & 0xE3 == 0x43 and
                      d[1:4] == bytes([0x61, 0x60, 0x00]) and d[4] == MODE_CSP, wr)
    item(confirmed is not None and confirmed < end, '0x6060 = 8 written (confirmed) before the first SYNC')
    item(shown is not None and shown < end, '0x6061 read as 8 after that write, before the first SYNC')
    start = first(lambda i, d: i == NMT and d == bytes([NMT_START, node]))
    rpdo = first(lambda i, d: i == RPDO1 + node)
    item(start is not None and rpdo is not None and start < rpdo, 'NMT start before the first RPDO1')
    syncs = sum(1 for i, _ in frames if i == SYNC)
    tpdos = [d for i, d in frames if i == TPDO1 + node and len(d) == 6]
    item(syncs == len(tpdos) and syncs > 0, f'one TPDO1 per SYNC ({len(tpdos)} TPDO1, {syncs} SYNC)')
    if tpdos:
        moved = struct.unpack('<i', tpdos[-1][2:6])[0] - struct.unpack('<i', tpdos[0][2:6])[0]
        item(abs(moved - distance) <= 1, f'moved {moved} counts between the first and the last TPDO1, want {distance}')
    emcy = [d.hex() for i, d in frames if i == EMCY + node]
    item(not emcy, f'no EMCY {EMCY + node:03X}# ({len(emcy)} seen{": " + ", ".join(emcy[:5]) if emcy else ""})')
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog='master_csp.py', description='An independent CiA 402 CSP master for one drive on SocketCAN.',
        epilog='Examples:\n'
               '  build/tools/cia402-emu/cia402-emu -i vcan0 -n 5 --eds tests/peers/csp-drive.eds &\n'
               '  /usr/bin/python3 tests/peers/master_csp.py -i vcan0 -n 5\n'
               '  /usr/bin/python3 tests/peers/master_csp.py --check-trace candump.log -n 5',
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('-i', '--interface', help='SocketCAN interface (vcan0)')
    ap.add_argument('-n', '--node', type=int, required=True, help='node-ID of the drive, 1..127')
    ap.add_argument('--period-ms', type=float, default=10.0, help='pause after each cycle, ms (default 10)')
    ap.add_argument('--patience', type=float, default=2.0, help='longest wait for one answer, s (default 2)')
    ap.add_argument('--distance', type=int, default=20000, help='move distance, counts (default 20000)')
    ap.add_argument('--move-cycles', type=int, default=200, help='cycles of the move (default 200)')
    ap.add_argument('--hold-cycles', type=int, default=20, help='cycles at rest after it (default 20)')
    ap.add_argument('--tolerance', type=int, default=2000, help='largest following error, counts (default 2000)')
    ap.add_argument('--check-trace', metavar='FILE',
                    help='check a candump -L trace of a run instead (-: $CANMOTION_TRACE, as run-vcan-test sets it)')
    a = ap.parse_args(argv)
    if not 1 <= a.node <= 127:
        ap.error('--node is 1..127')
    if a.move_cycles < 1 or a.hold_cycles < 0:
        ap.error('--move-cycles must be at least 1, --hold-cycles at least 0')
    if a.check_trace:
        path = os.environ.get('CANMOTION_TRACE', '') if a.check_trace == '-' else a.check_trace
        if not path:
            ap.error('--check-trace -: CANMOTION_TRACE is not set (run-vcan-test sets it)')
        results = check_trace(read_trace(path), a.node, a.distance)
        for ok, text in results:
            print(f'{"PASS" if ok else "FAIL"} trace: {text}')
        return 0 if all(ok for ok, _ in results) else 1
    if not a.interface:
        ap.error('--interface is required (or --check-trace FILE)')
    from link import SocketLink
    link = SocketLink(a.interface)
    try:
        ok = CspMaster(link, a.node, a.period_ms / 1000.0, a.patience).run(
            a.distance, a.move_cycles, a.hold_cycles, a.tolerance, out=lambda s: print(s, flush=True))
    finally:
        link.close()
    print(f'master_csp: node {a.node} on {a.interface}: {"PASS" if ok else "FAIL"}')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
