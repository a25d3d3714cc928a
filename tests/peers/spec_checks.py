"""CiA 301 / CiA 402 conformance checks for one CSP servo drive.

Each check is written from the specification (its clause is named) and
talks to the device only over the bus, through a link.Link: the unit tests
run them against the peer on python-can's virtual bus, conformance.py runs
them against any device on SocketCAN (the peer, cia402-emu, a real drive).
Where the specification allows several answers (e.g. 0602 0000h or
0604 0041h for a mapping entry of a missing object), a check accepts all of
them and reports the one it got.

A check gets a Ctx whose device was just reset (NMT reset node, boot-up
seen) and returns a short note, raises Skip, or fails with AssertionError.
"""

from __future__ import annotations

import struct

from link import SdoAbort, SdoClient

NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET_NODE, NMT_RESET_COMM = 0x01, 0x02, 0x80, 0x81, 0x82
HB_STOPPED, HB_OPERATIONAL, HB_PREOP = 0x04, 0x05, 0x7F

# Statusword decoding (CiA 402 statusword table): (mask, value, state).
STATES = ((0x004F, 0x0000, 'not ready to switch on'), (0x004F, 0x0040, 'switch on disabled'),
          (0x006F, 0x0021, 'ready to switch on'), (0x006F, 0x0023, 'switched on'),
          (0x006F, 0x0027, 'operation enabled'), (0x006F, 0x0007, 'quick stop active'),
          (0x004F, 0x000F, 'fault reaction active'), (0x004F, 0x0008, 'fault'))


def state_of(sw: int) -> str:
    for mask, value, name in STATES:
        if sw & mask == value:
            return name
    return f'unknown (0x{sw:04X})'


class Skip(Exception):
    pass


class Ctx:
    def __init__(self, link, node: int, period: float = 0.01, patience: float = 2.0):
        self.link, self.node, self.period = link, node, period
        self.patience = patience      # how long to wait for an answer (VM: the device may stall)
        self.sdo = SdoClient(link, node, timeout=patience)

    def barrier(self):
        """An SDO round trip: the device has handled every frame sent before it
        and sent what they caused (one device answers in order)."""
        self.sdo.read(0x1000)

    def nmt(self, cs: int):
        self.link.send(0x000, bytes([cs, self.node]))
        self.link.advance(self.period)

    def reset(self):
        """NMT reset node; the boot-up must follow (CiA 301 NMT). Then wait
        for CiA 402 transition 1: a drive may send its boot-up while still
        initialising (Not ready to switch on, e.g. its DC bus charging) and
        leave that state by itself; the checks start from Switch on disabled."""
        self.link.clear()
        self.link.send(0x000, bytes([NMT_RESET_NODE, self.node]))
        boot = self.link.wait_for(lambda i, d: i == 0x700 + self.node, 2.0)
        assert boot is not None, 'no boot-up within 2 s of NMT reset node'
        assert boot[2] == b'\x00', f'boot-up must be one byte 0x00, got {boot[2].hex()}'
        self.link.advance(self.period)
        t_end = self.link.now() + 5.0
        while (st := self.state()) == 'not ready to switch on' and self.link.now() < t_end:
            self.link.advance(self.period)
        assert st == 'switch on disabled', f'after the boot-up: {st}, want switch on disabled (transition 1) within 5 s'
        self.link.clear()

    def sync(self, n: int = 1):
        for _ in range(n):
            self.link.send(0x080)
            self.link.advance(self.period)

    def state(self) -> str:
        return state_of(self.sdo.read(0x6041, 0, '<H'))

    def control(self, cw: int, syncs: int = 2) -> str:
        """Controlword by SDO, then SYNCs (a CSP drive may act on SYNC); the state."""
        self.sdo.write(0x6040, 0, cw, '<H')
        self.sync(syncs)
        return self.state()

    def expect_abort(self, allowed, fn, *args, what=''):
        allowed = (allowed,) if isinstance(allowed, int) else tuple(allowed)
        code = self.sdo.abort_code(fn, *args)
        assert code is not None, f'{what}: accepted, want abort {" or ".join(f"0x{c:08X}" for c in allowed)}'
        assert code in allowed, (f'{what}: abort 0x{code:08X}, want {" or ".join(f"0x{c:08X}" for c in allowed)}')
        return code

    def remap(self, rx: bool, num: int, entries, ttype: int = 1):
        """The CiA 301 re-mapping procedure, steps 1..5, for PDO `num`."""
        comm = (0x1400 if rx else 0x1800) + num - 1
        cob = (0x200 if rx else 0x180) + 0x100 * (num - 1) + self.node
        self.sdo.write(comm, 1, cob | 1 << 31)               # 1. PDO not valid
        self.sdo.write(comm + 0x200, 0, 0, '<B')             # 2. mapping disabled
        for i, e in enumerate(entries):                      # 3. entries
            self.sdo.write(comm + 0x200, i + 1, e)
        self.sdo.write(comm + 0x200, 0, len(entries), '<B')  # 4. count
        self.sdo.write(comm, 2, ttype, '<B')
        self.sdo.write(comm, 1, cob)                         # 5. PDO valid
        return cob

    def tpdo1_on_syncs(self, n: int) -> int:
        """How many TPDO1 the device sends for n SYNCs (after what it owed before)."""
        self.barrier()
        self.link.clear()
        self.sync(n)
        self.barrier()
        return sum(1 for f in self.link.queue if f[1] == 0x180 + self.node)

    def csp_pdos(self):
        """RPDO1 = controlword + target position, TPDO1 = statusword + position actual, SYNC every cycle."""
        r = self.remap(True, 1, [0x60400010, 0x607A0020])
        t = self.remap(False, 1, [0x60410010, 0x60640020])
        return r, t


CHECKS = []


def check(clause):
    def register(fn):
        CHECKS.append((fn.__name__, clause, fn))
        return fn
    return register


# ---- NMT, boot-up, heartbeat ---------------------------------------------------------

@check('CiA 301 7.2.8.3.2 NMT boot-up: after reset node, one byte 0x00 on 700h+node; SDO in pre-operational')
def boot_up_after_reset(c: Ctx):
    c.reset()     # the boot-up itself is checked in reset()
    dt = c.sdo.read(0x1000)
    assert dt & 0xFFFF == 402, f'0x1000 device type 0x{dt:08X}: profile {dt & 0xFFFF}, want 402'
    return f'device type 0x{dt:08X}'


@check('CiA 301 7.2.8.3.2.2 NMT states: heartbeat byte 7Fh/05h/04h; SDO answered in pre-operational and '
       'operational only')
def nmt_states_in_heartbeat(c: Ctx):
    c.sdo.write(0x1017, 0, 20, '<H')
    node_hb = 0x700 + c.node

    def state_seen():
        c.link.clear()
        f = c.link.wait_for(lambda i, d: i == node_hb, c.patience)
        assert f is not None, f'no heartbeat within {c.patience} s with 0x1017 = 20 ms'
        assert len(f[2]) == 1, f'heartbeat must have 1 byte, got {f[2].hex()}'
        return f[2][0]

    assert state_seen() == HB_PREOP, 'heartbeat after boot: want 7Fh (pre-operational)'
    c.nmt(NMT_START)
    assert state_seen() == HB_OPERATIONAL, 'after NMT start: want 05h (operational)'
    c.nmt(NMT_STOP)
    assert state_seen() == HB_STOPPED, 'after NMT stop: want 04h (stopped)'
    c.link.clear()
    c.link.send(0x600 + c.node, struct.pack('<BHB4x', 0x40, 0x1000, 0))
    got = c.link.wait_for(lambda i, d: i == 0x580 + c.node, 0.2)
    assert got is None, 'an SDO request was answered in NMT stopped'
    c.nmt(NMT_PREOP)
    assert state_seen() == HB_PREOP, 'after NMT enter pre-operational: want 7Fh'
    c.sdo.read(0x1000)
    c.nmt(NMT_RESET_COMM)
    boot = c.link.wait_for(lambda i, d: i == node_hb and d == b'\x00', c.patience)
    assert boot is not None, 'no boot-up after NMT reset communication'
    return 'pre-operational, operational, stopped (SDO silent), pre-operational, reset communication'


@check('CiA 301 7.2.8.3.2.2 / 0x1017: heartbeat every producer time')
def heartbeat_period(c: Ctx):
    c.sdo.write(0x1017, 0, 50, '<H')
    assert c.sdo.read(0x1017, 0, '<H') == 50
    c.link.clear()
    times = []
    while len(times) < 11:
        f = c.link.wait_for(lambda i, d: i == 0x700 + c.node, c.patience)
        assert f is not None, f'heartbeat {len(times)} missing (0x1017 = 50 ms)'
        times.append(f[0])
    ints = sorted(b - a for a, b in zip(times, times[1:]))
    median = ints[len(ints) // 2]     # the median: one scheduling stall does not move it
    assert abs(median - 0.050) <= 0.005, (f'median heartbeat interval {1e3 * median:.2f} ms, want 50 ms '
                                          f'(intervals {", ".join(f"{1e3 * x:.1f}" for x in ints)} ms)')
    c.sdo.write(0x1017, 0, 0, '<H')
    c.barrier()
    c.link.clear()
    assert c.link.wait_for(lambda i, d: i == 0x700 + c.node, 0.2) is None, 'heartbeat after 0x1017 = 0'
    return f'median interval {1e3 * median:.2f} ms of {len(ints)}'


# ---- SDO --------------------------------------------------------------------------------

def _mode_shown(c: Ctx, mode: int) -> bool:
    """0x6061 shows `mode` within 10 SYNCs (a drive may switch at a SYNC)."""
    for _ in range(10):
        if c.sdo.read(0x6061, 0, '<b') == mode:
            return True
        c.sync()
    return False


@check('CiA 301 7.2.4.3.3/7.2.4.3.6 SDO expedited download and upload; CiA 402 0x6061 follows 0x6060 '
       '(in NMT pre-operational too: the drive application does not depend on the NMT state)')
def sdo_expedited(c: Ctx):
    modes = []
    if c.sdo.abort_code(c.sdo.write, 0x6060, 0, 0, '<b') is None:     # mode 0 (no mode) is optional
        assert _mode_shown(c, 0), '0x6061 does not show mode 0 within 10 SYNCs of 0x6060 = 0'
        modes.append(0)
    c.sdo.write(0x6060, 0, 8, '<b')
    assert c.sdo.read(0x6060, 0, '<b') == 8, '0x6060 read back'
    assert _mode_shown(c, 8), '0x6061 does not show mode 8 within 10 SYNCs of 0x6060 = 8'
    modes.append(8)
    c.sdo.write(0x607A, 0, -123456, '<i')
    assert c.sdo.read(0x607A, 0, '<i') == -123456, '0x607A (INTEGER32) read back'
    return f'0x6060 = 0x6061 = {" then ".join(map(str, modes))}; 0x607A = -123456'


@check('CiA 301 7.2.4.3.9 SDO segmented upload (toggle from 0, c bit, size indicated)')
def sdo_segmented_upload(c: Ctx):
    try:
        name = c.sdo.upload(0x1008, 0)
    except SdoAbort as e:
        if e.code == 0x06020000:
            raise Skip('0x1008 absent')
        raise
    if len(name) <= 4:
        raise Skip(f'0x1008 is {len(name)} bytes: expedited')
    return f'0x1008 = {name.decode(errors="replace")!r} ({len(name)} bytes)'


@check('CiA 301 7.2.4.3.4 SDO segmented download (a 2-byte object sent segmented)')
def sdo_segmented_download(c: Ctx):
    c.sdo.write(0x1017, 0, 123, '<H', segmented=True)
    got = c.sdo.read(0x1017, 0, '<H')
    assert got == 123, f'0x1017 read back {got}, want 123'
    c.sdo.write(0x1017, 0, 0, '<H')
    return '0x1017 = 123 by segmented download'


@check('CiA 301 SDO abort 0602 0000h: object does not exist')
def abort_no_object(c: Ctx):
    c.expect_abort(0x06020000, c.sdo.upload, 0x5FFF, 0, what='upload 0x5FFF')
    c.expect_abort(0x06020000, c.sdo.write, 0x5FFF, 0, 1, what='download 0x5FFF')
    return '0x5FFF up and down'


@check('CiA 301 SDO abort 0609 0011h: sub-index does not exist')
def abort_no_sub(c: Ctx):
    c.expect_abort(0x06090011, c.sdo.upload, 0x1018, 0xFE, what='upload 0x1018:FE')
    return '0x1018:FE'


@check('CiA 301 SDO abort 0601 0002h: write to a read-only object')
def abort_read_only(c: Ctx):
    c.expect_abort(0x06010002, c.sdo.write, 0x6041, 0, 0, '<H', what='download 0x6041 (statusword)')
    c.expect_abort(0x06010002, c.sdo.write, 0x1000, 0, 0, what='download 0x1000 (device type)')
    return '0x6041, 0x1000'


@check('CiA 301 SDO abort 0607 0010h (or 0012h/0013h): length of service parameter does not match')
def abort_length(c: Ctx):
    a = c.expect_abort((0x06070010, 0x06070012), c.sdo.write, 0x6040, 0, 0x000F, '<I',
                       what='4 bytes to 0x6040 (UNSIGNED16)')
    b = c.expect_abort((0x06070010, 0x06070013), c.sdo.write, 0x6040, 0, 0x0F, '<B',
                       what='1 byte to 0x6040 (UNSIGNED16)')
    return f'too long 0x{a:08X}, too short 0x{b:08X}'


@check('CiA 301 SDO abort 0503 0000h: toggle bit not alternated')
def abort_toggle(c: Ctx):
    r = c.sdo.request(struct.pack('<BHBI', 0x21, 0x1017, 0, 2))
    assert r[0] == 0x60, f'initiate segmented download 0x1017: {r.hex()}'
    r = c.sdo.request(bytes([0x10 | 5 << 1 | 1, 7, 0]))     # toggle 1 in the first segment
    assert r[0] == 0x80, f'first segment with toggle 1 accepted: {r.hex()}'
    code = struct.unpack_from('<I', r, 4)[0]
    assert code == 0x05030000, f'abort 0x{code:08X}, want 0x05030000'
    return 'first download segment with toggle 1'


@check('CiA 301 SDO abort 0504 0001h: command specifier not valid or unknown')
def abort_command(c: Ctx):
    r = c.sdo.request(struct.pack('<BHB', 0xE0, 0x1000, 0))
    assert r[0] == 0x80, f'ccs 7 answered {r.hex()}'
    code = struct.unpack_from('<I', r, 4)[0]
    assert code == 0x05040001, f'abort 0x{code:08X}, want 0x05040001'
    r = c.sdo.request(bytes([0x60]))                        # upload segment, no transfer
    assert r[0] == 0x80, f'upload segment without a transfer answered {r.hex()}'
    return 'ccs 7; upload segment outside a transfer'


# ---- PDO mapping ----------------------------------------------------------------------

@check('CiA 301 7.5.2.36/38 PDO re-mapping procedure (steps 1..5) accepted and read back')
def pdo_remap_procedure(c: Ctx):
    c.csp_pdos()
    assert c.sdo.read(0x1600, 0, '<B') == 2 and c.sdo.read(0x1A00, 0, '<B') == 2
    assert [c.sdo.read(0x1600, s) for s in (1, 2)] == [0x60400010, 0x607A0020]
    assert [c.sdo.read(0x1A00, s) for s in (1, 2)] == [0x60410010, 0x60640020]
    assert c.sdo.read(0x1800, 1) & 0x800007FF == 0x180 + c.node, 'TPDO1 COB-ID valid'
    return 'RPDO1 = 0x6040 + 0x607A, TPDO1 = 0x6041 + 0x6064'


@check('CiA 301 PDO mapping: no change while the PDO is valid (COB-ID bit 31 = 0)')
def pdo_mapping_refused_while_valid(c: Ctx):
    c.csp_pdos()
    codes = {c.expect_abort((0x06090030, 0x08000022, 0x06010000, 0x06040043), c.sdo.write, 0x1A00, 0, 0, '<B',
                            what='0x1A00:0 = 0 while TPDO1 valid'),
             c.expect_abort((0x06090030, 0x08000022, 0x06010000, 0x06040043), c.sdo.write, 0x1600, 1, 0x60400010,
                            what='0x1600:1 while RPDO1 valid')}
    assert c.sdo.read(0x1A00, 0, '<B') == 2, 'mapping count changed by a refused write'
    return 'aborts ' + ', '.join(f'0x{x:08X}' for x in sorted(codes))


@check('CiA 301 PDO mapping: entries change only while sub-index 0 is 0')
def pdo_mapping_refused_while_count_nonzero(c: Ctx):
    c.csp_pdos()
    c.sdo.write(0x1800, 1, (0x180 + c.node) | 1 << 31)
    code = c.expect_abort((0x06090030, 0x08000022, 0x06010000, 0x06040043), c.sdo.write, 0x1A00, 1, 0x60610008,
                          what='0x1A00:1 while 0x1A00:0 = 2')
    c.sdo.write(0x1A00, 0, 0, '<B')
    c.sdo.write(0x1A00, 1, 0x60610008)
    c.sdo.write(0x1A00, 0, 1, '<B')
    assert c.sdo.read(0x1A00, 1) == 0x60610008
    return f'abort 0x{code:08X}; accepted after 0x1A00:0 = 0'


@check('CiA 301 PDO mapping step 3: 0604 0041h not mappable / 0602 0000h missing object')
def pdo_mapping_not_mappable(c: Ctx):
    c.sdo.write(0x1400, 1, (0x200 + c.node) | 1 << 31)
    c.sdo.write(0x1600, 0, 0, '<B')
    c.sdo.write(0x1800, 1, (0x180 + c.node) | 1 << 31)
    c.sdo.write(0x1A00, 0, 0, '<B')
    a = c.expect_abort(0x06040041, c.sdo.write, 0x1600, 1, 0x60410010, what='statusword (ro) into RPDO1')
    b = c.expect_abort((0x06020000, 0x06040041), c.sdo.write, 0x1A00, 1, 0x5FFF0010, what='missing 0x5FFF into TPDO1')
    d = c.expect_abort((0x06040041, 0x06040043), c.sdo.write, 0x1A00, 1, 0x60410020,
                       what='0x6041 with length 32 (it is 16 bit)')
    return f'0x{a:08X}, 0x{b:08X}, 0x{d:08X}'


@check('CiA 301 PDO mapping step 4: 0604 0042h when the mapped objects exceed 8 bytes')
def pdo_mapping_length_exceeded(c: Ctx):
    c.sdo.write(0x1800, 1, (0x180 + c.node) | 1 << 31)
    c.sdo.write(0x1A00, 0, 0, '<B')
    for s in (1, 2, 3):
        c.sdo.write(0x1A00, s, 0x60640020)
    c.expect_abort(0x06040042, c.sdo.write, 0x1A00, 0, 3, '<B', what='0x1A00:0 = 3 x 32 bit')
    return '3 x 32 bit refused'


@check('CiA 301 PDO COB-ID: the CAN-ID may not change while the PDO is valid (0609 0030h)')
def pdo_cob_id_change_refused_while_valid(c: Ctx):
    c.csp_pdos()
    c.expect_abort(0x06090030, c.sdo.write, 0x1800, 1, 0x190 + c.node, what='TPDO1 CAN-ID changed while valid')
    return 'TPDO1 180h+node -> 190h+node refused'


@check('CiA 301 PDO transmission type: 241..251 reserved (0609 0030h)')
def pdo_reserved_transmission_type(c: Ctx):
    c.expect_abort(0x06090030, c.sdo.write, 0x1800, 2, 245, '<B', what='TPDO1 transmission type 245')
    return 'type 245 refused'


# ---- CiA 402 ------------------------------------------------------------------------------

def _prepare_enable(c: Ctx):
    c.sdo.write(0x6060, 0, 8, '<b')
    c.sdo.write(0x607A, 0, c.sdo.read(0x6064, 0, '<i'), '<i')   # no jump when enabled


@check('CiA 402 state machine: transitions 2..12 by controlword (SDO), one step each')
def state_machine_transitions(c: Ctx):
    _prepare_enable(c)
    steps = [  # (controlword, expected state, transition)
        (0x000F, 'switch on disabled', 'none from SOD'),
        (0x0006, 'ready to switch on', '2'), (0x0007, 'switched on', '3'), (0x000F, 'operation enabled', '4'),
        (0x0007, 'switched on', '5'), (0x0006, 'ready to switch on', '6'), (0x0000, 'switch on disabled', '7'),
        (0x0006, 'ready to switch on', '2'), (0x000F, 'operation enabled', '3+4'),
        (0x0006, 'ready to switch on', '8'), (0x0007, 'switched on', '3'), (0x0000, 'switch on disabled', '10'),
        (0x0006, 'ready to switch on', '2'), (0x0002, 'switch on disabled', '7 (quick stop)'),
        (0x0006, 'ready to switch on', '2'), (0x0007, 'switched on', '3'),
        (0x0002, 'switch on disabled', '10 (quick stop)'),
        (0x0006, 'ready to switch on', '2'), (0x000F, 'operation enabled', '3+4'),
        (0x0000, 'switch on disabled', '9'),
        (0x0006, 'ready to switch on', '2'), (0x000F, 'operation enabled', '3+4'),
        (0x0002, 'switch on disabled', '11 then 12 (0x605A default)'),
    ]
    for cw, want, tr in steps:
        got = c.control(cw, syncs=3)
        assert got == want, f'controlword 0x{cw:04X} (transition {tr}): {got}, want {want}'
    return f'{len(steps)} steps'


@check('CiA 402 quick stop option 5..8: stays in Quick stop active; transition 16 by enable operation')
def quick_stop_transition_16(c: Ctx):
    try:
        c.sdo.write(0x605A, 0, 6, '<h')
    except SdoAbort as e:
        raise Skip(f'0x605A = 6 refused (0x{e.code:08X})')
    _prepare_enable(c)
    for cw in (0x0006, 0x000F):
        c.control(cw)
    assert c.control(0x0002, syncs=4) == 'quick stop active', 'quick stop with 0x605A = 6'
    assert c.control(0x000F) == 'operation enabled', 'transition 16'
    assert c.control(0x0002) == 'quick stop active'
    assert c.control(0x0000) == 'switch on disabled', 'transition 12 by disable voltage'
    return '11, 16, 11, 12'


@check('CiA 402 CSP: target applied at SYNC, not on reception; TPDO1 after each SYNC')
def csp_target_at_sync(c: Ctx):
    c.csp_pdos()
    c.sdo.write(0x6060, 0, 8, '<b')
    pos = c.sdo.read(0x6064, 0, '<i')
    rpdo, tpdo = 0x200 + c.node, 0x180 + c.node
    c.nmt(NMT_START)
    for cw in (0x0006, 0x0007, 0x000F, 0x000F):
        c.link.send(rpdo, struct.pack('<Hi', cw, pos))
        c.sync(2)
    assert c.state() == 'operation enabled', f'not enabled by RPDO1: {c.state()}'
    step = 10        # small: a drive may limit velocity and acceleration
    c.link.clear()
    c.link.send(rpdo, struct.pack('<Hi', 0x000F, pos + step))
    c.link.advance(c.period)
    assert c.sdo.read(0x6064, 0, '<i') == pos, 'position moved before a SYNC'
    seen, syncs = [], 0
    for _ in range(20):
        c.link.send(0x080)
        syncs += 1
        f = c.link.wait_for(lambda i, d: i == tpdo, c.patience)
        assert f is not None, f'no TPDO1 after SYNC {syncs}'
        sw, p = struct.unpack('<Hi', f[2][:6])
        seen.append(p)
        assert sw & 0x1000, f'statusword 0x{sw:04X}: bit 12 (CSP: drive follows the command) not set'
        c.link.send(rpdo, struct.pack('<Hi', 0x000F, pos + step))
        c.link.advance(c.period)
    assert seen[-1] == pos + step, f'TPDO1 positions {seen}: never reached {pos + step}'
    lag = seen.index(pos + step) + 1
    return f'target +{step} reached in TPDO1 after {lag} SYNC(s)'


@check('CiA 301 7.2.2.5 TPDO transmission type 0 (synchronous acyclic): after a SYNC only when its data changed')
def tpdo_type_0_on_change(c: Ctx):
    c.remap(False, 1, [0x60410010], ttype=0)
    c.nmt(NMT_START)
    c.sync(2)
    n = c.tpdo1_on_syncs(4)
    assert n == 0, f'{n} TPDO1 in 4 SYNCs with unchanged data (type 0 sends only on a change)'
    c.sdo.write(0x6040, 0, 0x0006, '<H')
    n = c.tpdo1_on_syncs(3)
    assert n == 1, f'{n} TPDO1 in 3 SYNCs after the statusword changed, want 1'
    return 'silent while unchanged, one TPDO at the SYNC after a change'


@check('CiA 301 7.2.2.5 TPDO transmission type 254/255 (event-driven): on a change, not on SYNC')
def tpdo_event_driven(c: Ctx):
    c.remap(False, 1, [0x60410010], ttype=255)
    c.nmt(NMT_START)
    n = c.tpdo1_on_syncs(4)
    assert n == 0, f'{n} event-driven TPDO1 sent on 4 SYNCs with unchanged data'
    c.link.clear()
    c.sdo.write(0x6040, 0, 0x0006, '<H')
    f = c.link.wait_for(lambda i, d: i == 0x180 + c.node, c.patience)
    assert f is not None, f'no event-driven TPDO1 within {c.patience} s of a statusword change (no SYNC sent)'
    return 'sent on the change without SYNC'


@check('CiA 301 7.2.2.5 RPDO transmission type 254/255: the data takes effect on reception, without SYNC')
def rpdo_event_driven(c: Ctx):
    c.remap(True, 1, [0x60400010, 0x607A0020], ttype=255)
    c.sdo.write(0x6060, 0, 8, '<b')
    c.nmt(NMT_START)
    c.link.send(0x200 + c.node, struct.pack('<Hi', 0x0006, c.sdo.read(0x6064, 0, '<i')))
    c.link.advance(c.period)
    got = c.state()
    assert got == 'ready to switch on', f'controlword 0x0006 by an event-driven RPDO, no SYNC: {got}'
    return 'shutdown applied without SYNC'


@check('CiA 301 7.2.7 EMCY 8210h on a short RPDO: once per error event, error register bits 0 and 4; '
       '0000h when it is gone')
def rpdo_length_error_emcy(c: Ctx):
    c.remap(True, 1, [0x60400010, 0x607A0020])
    c.nmt(NMT_START)
    c.link.clear()
    for _ in range(3):
        c.link.send(0x200 + c.node, b'\x06\x00')
        c.link.advance(c.period)
    c.barrier()
    emcy = [f[2] for f in c.link.queue if f[1] == 0x080 + c.node]
    assert emcy, 'no EMCY for RPDO1 with 2 of 6 bytes'
    problems = []
    code, reg = struct.unpack_from('<HB', emcy[0])
    if code != 0x8210:
        problems.append(f'EMCY 0x{code:04X}, want 0x8210')
    if reg & 0x11 != 0x11:
        problems.append(f'error register 0x{reg:02X}: bits 0 (generic) and 4 (communication) not set')
    if len(emcy) != 1:
        problems.append(f'{len(emcy)} EMCY for one error event (3 short RPDOs)')
    c.link.clear()
    c.link.send(0x200 + c.node, struct.pack('<Hi', 0x0000, 0))
    c.barrier()
    emcy = [f[2] for f in c.link.queue if f[1] == 0x080 + c.node]
    if not emcy or emcy[0][:2] != b'\x00\x00':
        problems.append(f'no EMCY 0000h after a correct RPDO1 ({[e.hex() for e in emcy]})')
    assert not problems, '; '.join(problems)
    return 'one 8210h, register 0x11; 0000h after'


@check('CiA 402 0x60C2 interpolation time period: value (UNSIGNED8) and index (INTEGER8); a drive may fix the '
       'index (sub 2 read-only, 0601 0002h)')
def interpolation_period(c: Ctx):
    c.sdo.write(0x60C2, 1, 4, '<B')
    code = c.sdo.abort_code(c.sdo.write, 0x60C2, 2, -3, '<b')
    assert code in (None, 0x06010002), f'0x60C2:2 = -3: abort 0x{code:08X}, want accepted or 0x06010002 (read-only)'
    index = c.sdo.read(0x60C2, 2, '<b')
    assert c.sdo.read(0x60C2, 1, '<B') == 4, '0x60C2:1 read back'
    assert c.sdo.read(0x60C2, 0, '<B') >= 2
    if code is None:
        assert index == -3, f'0x60C2:2 read back {index}, want -3'
        return '4 x 10^-3 s'
    return f'4 x 10^{index} s (index read-only)'


def run(ctx_factory, names=None, out=print):
    """Run the checks (all, or those named); each on a freshly reset device.
    Returns the list of (name, clause, result, note)."""
    results = []
    for name, clause, fn in CHECKS:
        if names and name not in names:
            continue
        c = ctx_factory()
        try:
            c.reset()
            note, result = fn(c) or '', 'PASS'
        except Skip as e:
            note, result = str(e), 'SKIP'
        except (AssertionError, SdoAbort, TimeoutError) as e:
            note, result = str(e), 'FAIL'
        results.append((name, clause, result, note))
        out(f'{result} {name}: {note}\n     [{clause}]')
    return results
