#!/usr/bin/python3
"""cia402_peer: a minimal CiA 402 servo drive (a CANopen slave) on python-can.

An independent peer for canmotion's tests: written from the CiA 301 and
CiA 402 tables (shared/reference/cia402.md and the specifications), sharing
no code and no constants with canmotion's fieldbus/ (the master and its
emulator share theirs). What it implements, with the clause each rule comes
from, is in tests/peers/README.md.

The drive logic (class Drive) is sans-IO: it takes frames and a monotonic
time and returns the frames to send, so the unit tests step it on a virtual
clock over python-can's in-process `virtual` interface. class Runner does
the I/O on a python-can bus (SocketCAN on vcan/can in the integration
tests). Every time the drive compares is time.monotonic(); kernel receive
timestamps (CLOCK_REALTIME) are never used.

Run it with the system interpreter (Debian's python3-can): /usr/bin/python3.
"""

from __future__ import annotations

import argparse
import errno
import math
import os
import select
import signal
import struct
import sys
import time

# ============================================================================
# CiA 301 numbers, written from the specification (not from fieldbus/)
# ============================================================================

# Pre-defined connection set (CiA 301 7.3.5): base COB-IDs, + node-ID.
NMT_ID = 0x000
SYNC_ID = 0x080
EMCY_BASE = 0x080
TPDO_BASE = (0x180, 0x280, 0x380, 0x480)
RPDO_BASE = (0x200, 0x300, 0x400, 0x500)
SDO_TX_BASE = 0x580  # server -> client
SDO_RX_BASE = 0x600  # client -> server
HEARTBEAT_BASE = 0x700

COB_INVALID = 1 << 31      # PDO/EMCY COB-ID bit 31: not valid
COB_NO_RTR = 1 << 30       # TPDO COB-ID bit 30; SYNC COB-ID bit 30 = producer
COB_EXTENDED = 1 << 29     # 29-bit CAN-ID

# NMT command specifiers (CiA 301 7.2.8.3.1) and states in the heartbeat.
NMT_START, NMT_STOP, NMT_ENTER_PREOP, NMT_RESET_NODE, NMT_RESET_COMM = 0x01, 0x02, 0x80, 0x81, 0x82
BOOTUP, STOPPED, OPERATIONAL, PREOPERATIONAL = 0x00, 0x04, 0x05, 0x7F
NMT_NAMES = {BOOTUP: 'boot-up', STOPPED: 'stopped', OPERATIONAL: 'operational', PREOPERATIONAL: 'pre-operational'}

# SDO abort codes (CiA 301 7.2.4.3.17).
ABORT_TOGGLE = 0x05030000
ABORT_TIMEOUT = 0x05040000
ABORT_COMMAND = 0x05040001
ABORT_BLOCK_SIZE = 0x05040002
ABORT_CRC = 0x05040004
ABORT_WRITE_ONLY = 0x06010001
ABORT_READ_ONLY = 0x06010002
ABORT_NO_OBJECT = 0x06020000
ABORT_NOT_MAPPABLE = 0x06040041
ABORT_PDO_LENGTH = 0x06040042
ABORT_PARAM_INCOMPATIBLE = 0x06040043
ABORT_LENGTH = 0x06070010
ABORT_LENGTH_HIGH = 0x06070012
ABORT_NO_SUB = 0x06090011
ABORT_VALUE = 0x06090030
ABORT_DEVICE_STATE = 0x08000022
ABORT_TEXT = {
    ABORT_TOGGLE: 'toggle bit not alternated',
    ABORT_TIMEOUT: 'SDO protocol timed out',
    ABORT_COMMAND: 'command specifier not valid or unknown',
    ABORT_WRITE_ONLY: 'attempt to read a write only object',
    ABORT_READ_ONLY: 'attempt to write a read only object',
    ABORT_NO_OBJECT: 'object does not exist in the object dictionary',
    ABORT_NOT_MAPPABLE: 'object cannot be mapped to the PDO',
    ABORT_PDO_LENGTH: 'number and length of the objects to be mapped would exceed PDO length',
    ABORT_PARAM_INCOMPATIBLE: 'general parameter incompatibility',
    ABORT_LENGTH: 'data type does not match, length of service parameter does not match',
    ABORT_LENGTH_HIGH: 'data type does not match, length of service parameter too high',
    ABORT_NO_SUB: 'sub-index does not exist',
    ABORT_VALUE: 'invalid value for parameter',
    ABORT_DEVICE_STATE: 'data cannot be transferred or stored because of the present device state',
}

# Error register (0x1001) bits (CiA 301 7.5.2.2).
ERR_GENERIC, ERR_CURRENT, ERR_VOLTAGE, ERR_TEMPERATURE = 0x01, 0x02, 0x04, 0x08
ERR_COMMUNICATION, ERR_PROFILE, ERR_MANUFACTURER = 0x10, 0x20, 0x80

# EMCY error codes used here (CiA 301 table 21, CiA 402).
EMCY_RESET = 0x0000            # error reset / no error
EMCY_HEARTBEAT = 0x8130        # life guard / heartbeat error
EMCY_PDO_LENGTH = 0x8210       # PDO not processed due to length error


def error_register_bits(code: int) -> int:
    """The error register class bits for an EMCY code (CiA 301 table 21)."""
    hi = code >> 8
    bits = ERR_GENERIC
    if 0x20 <= hi <= 0x2F:
        bits |= ERR_CURRENT
    elif 0x30 <= hi <= 0x3F:
        bits |= ERR_VOLTAGE
    elif 0x40 <= hi <= 0x4F:
        bits |= ERR_TEMPERATURE
    elif hi in (0x81, 0x82):
        bits |= ERR_COMMUNICATION
    elif hi == 0xFF:
        bits |= ERR_MANUFACTURER
    return bits


# Restricted CAN-IDs a PDO must not use (CiA 301 7.3.5).
RESTRICTED_IDS = ((0x000, 0x07F), (0x101, 0x180), (0x581, 0x5FF), (0x601, 0x67F), (0x6E0, 0x6FF), (0x701, 0x7FF))


def restricted(can_id: int) -> bool:
    return any(lo <= can_id <= hi for lo, hi in RESTRICTED_IDS)


# ============================================================================
# CiA 402 numbers (IEC 61800-7-201), written from the specification
# ============================================================================

NOT_READY, SWITCH_ON_DISABLED, READY_TO_SWITCH_ON, SWITCHED_ON = 0, 1, 2, 3
OPERATION_ENABLED, QUICK_STOP_ACTIVE, FAULT_REACTION_ACTIVE, FAULT = 4, 5, 6, 7
STATE_NAMES = ('Not ready to switch on', 'Switch on disabled', 'Ready to switch on', 'Switched on',
               'Operation enabled', 'Quick stop active', 'Fault reaction active', 'Fault')
# Statusword bits 0..6 per state (CiA 402 statusword table): rtso, so, oe, f, (ve), qs, sod.
STATE_BITS = {NOT_READY: 0x0000, SWITCH_ON_DISABLED: 0x0040, READY_TO_SWITCH_ON: 0x0021, SWITCHED_ON: 0x0023,
              OPERATION_ENABLED: 0x0027, QUICK_STOP_ACTIVE: 0x0007, FAULT_REACTION_ACTIVE: 0x000F, FAULT: 0x0008}
SW_VOLTAGE_ENABLED = 1 << 4
SW_REMOTE = 1 << 9
SW_CSP_FOLLOWING = 1 << 12     # CSP: drive follows the command value
CW_FAULT_RESET = 1 << 7

MODE_NONE, MODE_CSP = 0, 8
MODE_HOMING, MODE_CSV = 6, 9
SW_TARGET_REACHED = 1 << 10
CW_HOMING_START = 1 << 4        # homing mode: bit 4 starts the homing
# Interpolated position mode (CiA 402 / DSP 402 v2 clause 11): mode 7; the
# set point is 0x60C1:1, taken only while controlword bit 4 "enable ip mode"
# is 1 in Operation enabled; statusword bit 12 "ip mode active" says so.
MODE_IP = 7
CW_ENABLE_IP = 1 << 4
SW_IP_ACTIVE = 1 << 12
# 0x6502 supported drive modes bits: 5 homing, 6 ip, 7 csp, 8 csv.
MODE_BITS = {MODE_HOMING: 1 << 5, MODE_IP: 1 << 6, MODE_CSP: 1 << 7, MODE_CSV: 1 << 8}
QUICK_STOP_OPTION_DEFAULT = 2  # 0x605A: quick-stop ramp, then Switch on disabled


# The device control transitions (CiA 402 state machine): (state, command)
# -> the transitions taken, in order. 13/14 (fault), 15 (fault reset edge)
# and 12 (quick stop completed) happen outside this table.
TRANSITIONS = {
    (SWITCH_ON_DISABLED, 'shutdown'): ((2, READY_TO_SWITCH_ON),),
    (READY_TO_SWITCH_ON, 'switch on'): ((3, SWITCHED_ON),),
    (READY_TO_SWITCH_ON, 'enable operation'): ((3, SWITCHED_ON), (4, OPERATION_ENABLED)),
    (READY_TO_SWITCH_ON, 'disable voltage'): ((7, SWITCH_ON_DISABLED),),
    (READY_TO_SWITCH_ON, 'quick stop'): ((7, SWITCH_ON_DISABLED),),
    (SWITCHED_ON, 'enable operation'): ((4, OPERATION_ENABLED),),
    (SWITCHED_ON, 'shutdown'): ((6, READY_TO_SWITCH_ON),),
    (SWITCHED_ON, 'disable voltage'): ((10, SWITCH_ON_DISABLED),),
    (SWITCHED_ON, 'quick stop'): ((10, SWITCH_ON_DISABLED),),
    (OPERATION_ENABLED, 'switch on'): ((5, SWITCHED_ON),),        # = disable operation
    (OPERATION_ENABLED, 'shutdown'): ((8, READY_TO_SWITCH_ON),),
    (OPERATION_ENABLED, 'disable voltage'): ((9, SWITCH_ON_DISABLED),),
    (OPERATION_ENABLED, 'quick stop'): ((11, QUICK_STOP_ACTIVE),),
    (QUICK_STOP_ACTIVE, 'disable voltage'): ((12, SWITCH_ON_DISABLED),),
    (QUICK_STOP_ACTIVE, 'enable operation'): ((16, OPERATION_ENABLED),),   # 0x605A = 5..8 only
}


def decode_command(cw: int):
    """The device control command in a controlword (CiA 402 command table)."""
    if cw & 0x0082 == 0x0000:
        return 'disable voltage'
    if cw & 0x0086 == 0x0002:
        return 'quick stop'
    if cw & 0x0087 == 0x0006:
        return 'shutdown'
    if cw & 0x008F == 0x0007:
        return 'switch on'          # also "disable operation"
    if cw & 0x008F == 0x000F:
        return 'enable operation'
    return None                     # bit 7 set: only the fault reset edge counts


# ============================================================================
# Object dictionary
# ============================================================================

NUMERIC = {'u8': '<B', 'i8': '<b', 'u16': '<H', 'i16': '<h', 'u32': '<I', 'i32': '<i'}


class Var:
    """One object dictionary entry. `get`/`set` make it a view of drive
    state; `check(value)` returns an abort code that refuses a write."""

    def __init__(self, name, dtype, access, value=0, pdo='', get=None, set=None, check=None, max_len=0):
        self.name, self.dtype, self.access, self.pdo = name, dtype, access, pdo
        self.value, self._get, self._set, self.check, self.max_len = value, get, set, check, max_len

    @property
    def size(self) -> int:
        if self.dtype in NUMERIC:
            return struct.calcsize(NUMERIC[self.dtype])
        return len(self.read())

    def read(self):
        return self._get() if self._get else self.value

    def encode(self) -> bytes:
        v = self.read()
        if self.dtype in NUMERIC:
            return struct.pack(NUMERIC[self.dtype], v)
        return bytes(v)

    def decode(self, data: bytes):
        if self.dtype in NUMERIC:
            return struct.unpack(NUMERIC[self.dtype], data)[0]
        return bytes(data)

    def store(self, v):
        if self._set:
            self._set(v)
        else:
            self.value = v


class ObjectDictionary:
    def __init__(self):
        self.entries: dict[tuple[int, int], Var] = {}
        self.indices: set[int] = set()

    def add(self, index: int, sub: int, var: Var) -> Var:
        self.entries[(index, sub)] = var
        self.indices.add(index)
        return var

    def remove_index(self, index: int):
        for key in [k for k in self.entries if k[0] == index]:
            del self.entries[key]
        self.indices.discard(index)

    def find(self, index: int, sub: int):
        var = self.entries.get((index, sub))
        if var is not None:
            return var, 0
        return None, (ABORT_NO_SUB if index in self.indices else ABORT_NO_OBJECT)

    def upload(self, index: int, sub: int):
        var, abort = self.find(index, sub)
        if abort:
            return None, abort
        if var.access == 'wo':
            return None, ABORT_WRITE_ONLY
        return var.encode(), 0

    def download(self, index: int, sub: int, data: bytes) -> int:
        """SDO write: access, length and value checks, then store. 0 or an abort code."""
        var, abort = self.find(index, sub)
        if abort:
            return abort
        if var.access in ('ro', 'const'):
            return ABORT_READ_ONLY
        if var.dtype in NUMERIC:
            if len(data) != var.size:
                return ABORT_LENGTH
        elif len(data) > var.max_len:
            return ABORT_LENGTH_HIGH
        value = var.decode(data)
        if var.check:
            abort = var.check(value)
            if abort:
                return abort
        var.store(value)
        return 0


# ============================================================================
# PDOs
# ============================================================================

class Pdo:
    MAX_ENTRIES = 8   # classical CAN: at most 8 one-byte objects

    def __init__(self, rx: bool, num: int, node: int):
        self.rx, self.num, self.node = rx, num, node
        self.reset()

    def reset(self):
        """Power-on / reset-communication defaults: PDO 1 valid and mapped to
        the controlword / statusword, event-driven; the others invalid."""
        base = (RPDO_BASE if self.rx else TPDO_BASE)
        default_id = base[self.num - 1] + self.node if self.num <= 4 else 0
        self.cob = default_id | (0 if self.num == 1 else COB_INVALID)
        if not self.rx:
            self.cob |= COB_NO_RTR
        self.ttype = 255
        self.inhibit = 0      # TPDO sub 3, 100 us units
        self.event_ms = 0     # TPDO sub 5
        self.entries = [0] * self.MAX_ENTRIES
        self.count = 0
        if self.num == 1:
            self.entries[0] = (0x6040 if self.rx else 0x6041) << 16 | 16
            self.count = 1
        self.restart()

    def restart(self):
        """Runtime state, cleared when the PDO or the NMT state changes."""
        self.sync_count = 0
        self.pending = None       # synchronous RPDO data waiting for SYNC
        self.last_sent = None     # TPDO payload last sent
        self.last_time = None     # TPDO time last sent
        self.length_error = False

    @property
    def valid(self) -> bool:
        return not self.cob & COB_INVALID

    @property
    def can_id(self) -> int:
        return self.cob & 0x7FF

    @property
    def comm_index(self) -> int:
        return (0x1400 if self.rx else 0x1800) + self.num - 1

    @property
    def map_index(self) -> int:
        return (0x1600 if self.rx else 0x1A00) + self.num - 1

    def mapped(self):
        """(index, sub, bits) of the active entries."""
        return [(e >> 16, (e >> 8) & 0xFF, e & 0xFF) for e in self.entries[:self.count]]

    @property
    def name(self) -> str:
        return f"{'RPDO' if self.rx else 'TPDO'}{self.num}"


# ============================================================================
# The drive
# ============================================================================

class Drive:
    """A CiA 402 servo drive in cyclic synchronous position mode, as a CANopen
    slave. Methods take the monotonic time `now` (s) and return the frames to
    send as (can_id, bytes) tuples."""

    def __init__(self, node: int, rpdos: int = 2, tpdos: int = 2, position: int = 0, heartbeat_ms: int = 0,
                 consumer_heartbeat: int = 0, fault_code: int = 0xFF00, sdo_timeout: float = 1.0, log=None,
                 velocity_unit: str = None, encoder_increments: int = 0, modes: str = 'csp'):
        if not 1 <= node <= 127:
            raise ValueError(f'node-ID {node} is not 1..127')
        if not 1 <= rpdos <= 8 or not 1 <= tpdos <= 8:
            raise ValueError('the number of RPDOs and TPDOs must be 1..8')
        if not 0 <= consumer_heartbeat <= 127:
            raise ValueError('the number of consumer heartbeat entries must be 0..127')
        if velocity_unit not in (None, 'inc/s', 'rpm'):
            raise ValueError(f"velocity unit '{velocity_unit}' is not inc/s or rpm")
        if velocity_unit == 'rpm' and encoder_increments <= 0:
            raise ValueError('rpm needs --encoder-increments (0x608F:1, increments per motor revolution) > 0')
        # Drive units (CiA 402 factor group): with a velocity unit the drive
        # also has CSV (mode 9) and homing (mode 6); 0x60FF, 0x6099 and 0x606C
        # are in that unit: inc/s (0x60A9 = 0x00B50300) or rpm (0x00B44700,
        # 0x608F:1 increments per 0x608F:2 = 1 motor revolution).
        self.velocity_unit = velocity_unit
        self.encoder_increments = encoder_increments
        # The position modes it has: 'csp', 'ip' or 'csp,ip' (--modes).
        self.position_modes = set()
        for m in modes.split(','):
            if m.strip() not in ('csp', 'ip'):
                raise ValueError(f"mode '{m}' is not csp or ip")
            self.position_modes.add(MODE_CSP if m.strip() == 'csp' else MODE_IP)
        self.node = node
        self.default_heartbeat_ms = heartbeat_ms
        self.consumer_entries = consumer_heartbeat
        self.fault_code = fault_code
        self.sdo_timeout = sdo_timeout
        self.log = log or (lambda msg: None)
        self.rpdos = [Pdo(True, n, node) for n in range(1, rpdos + 1)]
        self.tpdos = [Pdo(False, n, node) for n in range(1, tpdos + 1)]
        self.actual = position            # position actual value (counts): kept across resets
        self.transitions = []             # CiA 402 transition numbers taken, in order (tests read it)
        self.sync_count = 0               # SYNCs received, and their intervals (s)
        self.sync_interval = [0.0, None, None]   # sum, min, max
        self._pending_out = []            # frames raised inside an object write (EMCY)
        self.pending_enable_log = False
        self.max_step = 0                 # largest set-point step while following (counts)
        self.enable_log = []              # (actual, first set-point) at each entry into Operation enabled
        self.booted = False
        self._power_on()

    # ---- initialisation ------------------------------------------------------
    def _power_on(self):
        self.nmt = BOOTUP
        self.errors = {}                  # active EMCY codes -> error register bits
        self.fault_codes = set()          # codes that a fault reset clears
        self.fault_held = False           # an injected fault that persists until `clear`
        self._reset_application()
        self._reset_communication()

    def _reset_application(self):
        self.state = SWITCH_ON_DISABLED   # transitions 0 and 1 are automatic
        self.controlword = 0
        self.cw_applied = 0
        self.target = self.actual
        self.demand = self.actual
        self.prev_actual = self.actual
        self.velocity = 0
        self.target_velocity = 0          # 0x60FF, in the velocity unit
        self.target_torque = 0            # 0x6071
        self.ip_target = self.actual      # 0x60C1:1, the IP set point
        self.ip_sub_mode = 0              # 0x60C0: 0 = linear interpolation (the only one)
        self.homing_method = 0
        self.homing_speeds = [0, 0]       # 0x6099:1/2, in the velocity unit
        self.homing_accel = 0             # 0x609A
        self.home_offset = 0              # 0x607C
        self.homing = None                # None, 'active', 'attained'
        self.frac = 0.0                   # CSV/homing: sub-count position
        self.following = False
        self.mode = MODE_NONE
        self.quick_stop_option = QUICK_STOP_OPTION_DEFAULT
        self.error_code = 0
        self.ip_value, self.ip_index = 1, -3   # 0x60C2: 1 ms until the master writes it
        self.note = b''
        self.block = b''
        self.reaction_deadline = None
        self.fault_held = False
        for code in list(self.fault_codes):
            self.errors.pop(code, None)
        self.fault_codes.clear()

    def _reset_communication(self):
        self.sync_cob = SYNC_ID
        self.emcy_cob = EMCY_BASE + self.node
        self.heartbeat_ms = self.default_heartbeat_ms
        self.next_heartbeat = None
        self.consumers = [0] * self.consumer_entries
        self.consumer_seen = [None] * self.consumer_entries
        self.consumer_lost = [False] * self.consumer_entries
        for p in self.rpdos + self.tpdos:
            p.reset()
        self.sdo = None
        self.last_sync = None
        if not hasattr(self, 'block_transfer'):
            self.block_transfer = True    # serve SDO block transfer (False: abort 0504 0001h, as a drive without it)
            self.block_log = []           # finished block transfers: (direction, index, sub, bytes, CRC)
        self._build_od()

    def _build_od(self):
        od = ObjectDictionary()
        self.od = od
        d = self
        # --- CiA 301 communication area
        od.add(0x1000, 0, Var('Device type', 'u32', 'ro', 0x00020192))   # profile 402, servo drive
        od.add(0x1001, 0, Var('Error register', 'u8', 'ro', pdo='T', get=self.error_register))
        od.add(0x1005, 0, Var('COB-ID SYNC', 'u32', 'rw', get=lambda: d.sync_cob, set=self._set_sync_cob,
                              check=self._check_sync_cob))
        od.add(0x1008, 0, Var('Manufacturer device name', 'str', 'const', b'canmotion cia402_peer'))
        od.add(0x100A, 0, Var('Manufacturer software version', 'str', 'const', b'tests/peers 1'))
        od.add(0x1014, 0, Var('COB-ID EMCY', 'u32', 'rw', get=lambda: d.emcy_cob, set=self._set_emcy_cob,
                              check=self._check_emcy_cob))
        if self.consumer_entries:
            od.add(0x1016, 0, Var('Consumer heartbeat time', 'u8', 'ro', self.consumer_entries))
            for i in range(self.consumer_entries):
                od.add(0x1016, i + 1, Var('Consumer heartbeat time', 'u32', 'rw',
                                          get=lambda i=i: d.consumers[i],
                                          set=lambda v, i=i: d._set_consumer(i, v),
                                          check=lambda v, i=i: d._check_consumer(i, v)))
        od.add(0x1017, 0, Var('Producer heartbeat time', 'u16', 'rw', get=lambda: d.heartbeat_ms,
                              set=self._set_heartbeat))
        od.add(0x1018, 0, Var('Identity object', 'u8', 'ro', 4))
        for sub, value in ((1, 0), (2, 0x402), (3, 1), (4, self.node)):
            od.add(0x1018, sub, Var('Identity object', 'u32', 'ro', value))
        od.add(0x1200, 0, Var('SDO server parameter', 'u8', 'ro', 2))
        od.add(0x1200, 1, Var('COB-ID client to server', 'u32', 'ro', SDO_RX_BASE + self.node))
        od.add(0x1200, 2, Var('COB-ID server to client', 'u32', 'ro', SDO_TX_BASE + self.node))
        for p in self.rpdos + self.tpdos:
            self._add_pdo_objects(p)
        # --- CiA 402 device profile area
        od.add(0x603F, 0, Var('Error code', 'u16', 'ro', pdo='T', get=lambda: d.error_code))
        od.add(0x6040, 0, Var('Controlword', 'u16', 'rw', pdo='R', get=lambda: d.controlword,
                              set=self._set_controlword))
        od.add(0x6041, 0, Var('Statusword', 'u16', 'ro', pdo='T', get=self.statusword))
        od.add(0x605A, 0, Var('Quick stop option code', 'i16', 'rw', get=lambda: d.quick_stop_option,
                              set=lambda v: setattr(d, 'quick_stop_option', v),
                              check=lambda v: 0 if 0 <= v <= 8 else ABORT_VALUE))
        od.add(0x6060, 0, Var('Modes of operation', 'i8', 'rw', pdo='R', get=lambda: d.mode, set=self._set_mode,
                              check=lambda v: 0 if v == MODE_NONE or v in self.position_modes or (
                                  self.velocity_unit and v in (MODE_CSV, MODE_HOMING)) else ABORT_VALUE))
        od.add(0x6061, 0, Var('Modes of operation display', 'i8', 'ro', pdo='T', get=lambda: d.mode))
        od.add(0x6062, 0, Var('Position demand value', 'i32', 'ro', pdo='T', get=lambda: d.demand))
        od.add(0x6064, 0, Var('Position actual value', 'i32', 'ro', pdo='T', get=lambda: d.actual))
        od.add(0x606C, 0, Var('Velocity actual value', 'i32', 'ro', pdo='T', get=lambda: d.velocity))
        od.add(0x607A, 0, Var('Target position', 'i32', 'rw', pdo='R', get=lambda: d.target,
                              set=lambda v: setattr(d, 'target', v)))
        if MODE_IP in self.position_modes:
            od.add(0x60C0, 0, Var('Interpolation sub mode select', 'i16', 'rw', get=lambda: d.ip_sub_mode,
                                  set=lambda v: setattr(d, 'ip_sub_mode', v),
                                  check=lambda v: 0 if v == 0 else ABORT_VALUE))   # linear only
            od.add(0x60C1, 0, Var('Interpolation data record', 'u8', 'ro', 1))
            od.add(0x60C1, 1, Var('Interpolation data record 1', 'i32', 'rw', pdo='R', get=lambda: d.ip_target,
                                  set=lambda v: setattr(d, 'ip_target', v)))
        od.add(0x60C2, 0, Var('Interpolation time period', 'u8', 'ro', 2))
        od.add(0x60C2, 1, Var('Interpolation time period value', 'u8', 'rw', get=lambda: d.ip_value,
                              set=lambda v: setattr(d, 'ip_value', v)))
        od.add(0x60C2, 2, Var('Interpolation time index', 'i8', 'rw', get=lambda: d.ip_index,
                              set=lambda v: setattr(d, 'ip_index', v),
                              check=lambda v: 0 if -128 <= v <= 63 else ABORT_VALUE))
        supported = sum(MODE_BITS[m] for m in self.position_modes)   # CSP and/or IP
        if self.velocity_unit:
            supported |= MODE_BITS[MODE_CSV] | MODE_BITS[MODE_HOMING]
        od.add(0x6502, 0, Var('Supported drive modes', 'u32', 'ro', supported))
        if self.velocity_unit:
            self._add_unit_objects()
        # --- manufacturer-specific area: a writable string (segmented downloads)
        od.add(0x2000, 0, Var('Application note', 'str', 'rw', get=lambda: d.note,
                              set=lambda v: setattr(d, 'note', v), max_len=64))
        # a DOMAIN of up to 1 KiB (parameter blocks: SDO block transfer)
        od.add(0x2F00, 0, Var('Parameter block', 'domain', 'rw', get=lambda: d.block,
                              set=lambda v: setattr(d, 'block', v), max_len=1024))

    def _add_unit_objects(self):
        od, d = self.od, self
        rpm = self.velocity_unit == 'rpm'
        od.add(0x60A9, 0, Var('SI unit velocity', 'u32', 'ro', 0x00B44700 if rpm else 0x00B50300))
        od.add(0x608F, 0, Var('Position encoder resolution', 'u8', 'ro', 2))
        od.add(0x608F, 1, Var('Encoder increments', 'u32', 'ro', self.encoder_increments or 1))
        od.add(0x608F, 2, Var('Motor revolutions', 'u32', 'ro', 1))
        od.add(0x60FF, 0, Var('Target velocity', 'i32', 'rw', pdo='R', get=lambda: d.target_velocity,
                              set=lambda v: setattr(d, 'target_velocity', v)))
        od.add(0x6071, 0, Var('Target torque', 'i16', 'rw', pdo='R', get=lambda: d.target_torque,
                              set=lambda v: setattr(d, 'target_torque', v)))
        od.add(0x6077, 0, Var('Torque actual value', 'i16', 'ro', pdo='T', get=lambda: 0))
        od.add(0x6098, 0, Var('Homing method', 'i8', 'rw', get=lambda: d.homing_method,
                              set=lambda v: setattr(d, 'homing_method', v)))
        od.add(0x6099, 0, Var('Homing speeds', 'u8', 'ro', 2))
        for i in range(2):
            od.add(0x6099, i + 1, Var('Homing speeds', 'u32', 'rw', get=lambda i=i: d.homing_speeds[i],
                                      set=lambda v, i=i: d.homing_speeds.__setitem__(i, v)))
        od.add(0x609A, 0, Var('Homing acceleration', 'u32', 'rw', get=lambda: d.homing_accel,
                              set=lambda v: setattr(d, 'homing_accel', v)))
        od.add(0x607C, 0, Var('Home offset', 'i32', 'rw', get=lambda: d.home_offset,
                              set=lambda v: setattr(d, 'home_offset', v)))

    def _add_pdo_objects(self, p: Pdo):
        od = self.od
        ci, mi = p.comm_index, p.map_index
        od.add(ci, 0, Var('highest sub-index supported', 'u8', 'ro', 2 if p.rx else 5))
        od.add(ci, 1, Var('COB-ID', 'u32', 'rw', get=lambda: p.cob, set=lambda v: self._set_pdo_cob(p, v),
                          check=lambda v: self._check_pdo_cob(p, v)))
        od.add(ci, 2, Var('transmission type', 'u8', 'rw', get=lambda: p.ttype, set=lambda v: setattr(p, 'ttype', v),
                          check=lambda v: 0 if v <= 240 or v >= 254 else ABORT_VALUE))
        if not p.rx:
            od.add(ci, 3, Var('inhibit time', 'u16', 'rw', get=lambda: p.inhibit,
                              set=lambda v: setattr(p, 'inhibit', v),
                              check=lambda v: ABORT_VALUE if p.valid else 0))
            od.add(ci, 5, Var('event timer', 'u16', 'rw', get=lambda: p.event_ms,
                              set=lambda v: setattr(p, 'event_ms', v)))
        od.add(mi, 0, Var('number of mapped objects', 'u8', 'rw', get=lambda: p.count,
                          set=lambda v: self._set_map_count(p, v), check=lambda v: self._check_map_count(p, v)))
        for i in range(Pdo.MAX_ENTRIES):
            od.add(mi, i + 1, Var('mapped object', 'u32', 'rw', get=lambda i=i: p.entries[i],
                                  set=lambda v, i=i: p.entries.__setitem__(i, v),
                                  check=lambda v: self._check_map_entry(p, v)))

    # ---- object write rules ------------------------------------------------------
    def _check_pdo_cob(self, p: Pdo, v: int) -> int:
        # CiA 301 PDO communication parameter: bits 0..29 may not change while
        # the PDO exists (bit 31 = 0); this drive has 11-bit CAN-IDs only, and a
        # valid PDO must not use a restricted CAN-ID.
        if v & COB_EXTENDED or v & 0x1FFFF800:
            return ABORT_VALUE
        if self.nmt == OPERATIONAL:
            return ABORT_DEVICE_STATE     # this drive changes PDOs in pre-operational only
        valid = not v & COB_INVALID
        if valid and p.valid and (v & 0x7FF) != p.can_id:
            return ABORT_VALUE
        if valid and restricted(v & 0x7FF):
            return ABORT_VALUE
        return 0

    def _set_pdo_cob(self, p: Pdo, v: int):
        was = p.valid
        p.cob = v
        if p.valid != was:
            p.restart()
            self.log(f"{p.name} {'valid' if p.valid else 'invalid'}, COB-ID 0x{p.can_id:03X}, "
                     f"transmission type {p.ttype}, mapping {self._mapping_text(p)}")

    def _mapping_problem(self, p: Pdo, v: int) -> int:
        """Abort code for mapping entry `v` in PDO `p` (0 when it maps)."""
        index, sub, bits = v >> 16, (v >> 8) & 0xFF, v & 0xFF
        var = self.od.entries.get((index, sub))
        if var is None:
            return ABORT_NO_OBJECT        # CiA 301: mapped object does not exist: 0602 0000h
        direction = 'R' if p.rx else 'T'
        if direction not in var.pdo or var.dtype not in NUMERIC or bits != 8 * var.size:
            return ABORT_NOT_MAPPABLE
        return 0

    def _check_map_entry(self, p: Pdo, v: int) -> int:
        # CiA 301 PDO mapping: the entries change only while the PDO is not
        # valid and sub-index 0 is 0 (step 1 and 2 of the re-mapping procedure).
        if p.valid or p.count != 0:
            return ABORT_VALUE
        if self.nmt == OPERATIONAL:
            return ABORT_DEVICE_STATE
        return self._mapping_problem(p, v) if v else 0

    def _check_map_count(self, p: Pdo, n: int) -> int:
        if p.valid:
            return ABORT_VALUE
        if self.nmt == OPERATIONAL:
            return ABORT_DEVICE_STATE
        if n == 0:
            return 0
        if p.count != 0:
            return ABORT_VALUE            # sub-index 0 goes through 0 before a new count
        if n > Pdo.MAX_ENTRIES:
            return ABORT_PDO_LENGTH
        total = 0
        for e in p.entries[:n]:
            if e == 0:
                return ABORT_PARAM_INCOMPATIBLE   # an unset entry among 1..n
            problem = self._mapping_problem(p, e)
            if problem:
                return problem
            total += e & 0xFF
        return ABORT_PDO_LENGTH if total > 64 else 0

    def _set_map_count(self, p: Pdo, n: int):
        p.count = n
        p.restart()

    def _check_sync_cob(self, v: int) -> int:
        if v & COB_NO_RTR:
            return ABORT_VALUE            # bit 30: this drive cannot produce SYNC
        if v & (COB_EXTENDED | 0x1FFFF800):
            return ABORT_VALUE
        return 0

    def _set_sync_cob(self, v: int):
        self.sync_cob = v

    def _check_emcy_cob(self, v: int) -> int:
        if v & (COB_EXTENDED | 0x1FFFF800):
            return ABORT_VALUE
        if not v & COB_INVALID and not self.emcy_cob & COB_INVALID and (v & 0x7FF) != (self.emcy_cob & 0x7FF):
            return ABORT_VALUE            # the CAN-ID may not change while the EMCY is valid
        return 0

    def _set_emcy_cob(self, v: int):
        self.emcy_cob = v

    def _check_consumer(self, i: int, v: int) -> int:
        if v & 0xFF000000:
            return ABORT_VALUE            # bits 24..31 reserved (0)
        node, ms = (v >> 16) & 0xFF, v & 0xFFFF
        if node and ms:
            # CiA 301 0x1016: one node-ID monitored twice -> 0604 0043h
            for j, other in enumerate(self.consumers):
                if j != i and (other >> 16) & 0xFF == node and other & 0xFFFF:
                    return ABORT_PARAM_INCOMPATIBLE
        return 0

    def _set_consumer(self, i: int, v: int):
        self.consumers[i] = v
        self.consumer_seen[i] = None      # monitoring starts at the next heartbeat received
        if self.consumer_lost[i]:
            self.consumer_lost[i] = False

    def _set_heartbeat(self, ms: int):
        self.heartbeat_ms = ms
        self.next_heartbeat = (self._now + ms / 1000.0) if ms else None

    def _set_mode(self, m: int):
        if m != self.mode:
            self.log(f'mode {self.mode} -> {m}')
        self.mode = m

    def _set_controlword(self, cw: int):
        if (self.mode == MODE_HOMING and self.state == OPERATION_ENABLED and cw & CW_HOMING_START
                and not self.controlword & CW_HOMING_START):
            self.homing = 'active'
            self.log(f'homing started: method {self.homing_method}, speeds 0x6099:1 = {self.homing_speeds[0]} '
                     f'0x6099:2 = {self.homing_speeds[1]} {self.velocity_unit}, 0x609A = {self.homing_accel}')
        self.controlword = cw
        self._apply_controlword(cw)

    # ---- EMCY and the error register ---------------------------------------------
    def error_register(self) -> int:
        reg = 0
        for bits in self.errors.values():
            reg |= bits
        return reg

    def _emcy(self, code: int, out: list):
        if self.emcy_cob & COB_INVALID or self.nmt not in (PREOPERATIONAL, OPERATIONAL):
            return
        out.append((self.emcy_cob & 0x7FF, struct.pack('<HB5s', code, self.error_register(), bytes(5))))
        self.log(f'EMCY 0x{code:04X}, error register 0x{self.error_register():02X}')

    def _raise_error(self, code: int, out: list):
        self.errors[code] = error_register_bits(code)
        self._emcy(code, out)

    def _clear_error(self, code: int, out: list):
        if self.errors.pop(code, None) is not None:
            self._emcy(EMCY_RESET, out)

    # ---- CiA 402 state machine ------------------------------------------------------
    def statusword(self) -> int:
        sw = STATE_BITS[self.state] | SW_REMOTE
        if self.state != NOT_READY:
            sw |= SW_VOLTAGE_ENABLED
        if self.state == OPERATION_ENABLED and self.mode in (MODE_CSP, MODE_CSV):
            sw |= SW_CSP_FOLLOWING        # bit 12: drive follows the command value
        if self.ip_active():
            sw |= SW_IP_ACTIVE            # bit 12 in IP: ip mode active
        if self.mode == MODE_HOMING and self.homing == 'attained':
            sw |= SW_CSP_FOLLOWING | SW_TARGET_REACHED   # bit 12 homing attained, bit 10 target reached
        return sw

    def ip_active(self) -> bool:
        """IP: Operation enabled, mode 7 and controlword bit 4 (enable ip mode)."""
        return self.state == OPERATION_ENABLED and self.mode == MODE_IP and bool(self.controlword & CW_ENABLE_IP)

    def counts_per_unit(self) -> float:
        """Increments per second of one unit of 0x60FF/0x6099/0x606C."""
        return self.encoder_increments / 60.0 if self.velocity_unit == 'rpm' else 1.0

    def _go(self, transition: int, to: int):
        self.log(f'transition {transition}: {STATE_NAMES[self.state]} -> {STATE_NAMES[to]}')
        self.transitions.append(transition)
        self.state = to
        if to == OPERATION_ENABLED:
            self.demand = self.actual     # hold here until the next set-point
            self.pending_enable_log = True

    def _apply_controlword(self, cw: int):
        prev, self.cw_applied = self.cw_applied, cw
        s = self.state
        if s == FAULT:
            if cw & CW_FAULT_RESET and not prev & CW_FAULT_RESET and not self.fault_held:
                out = []
                for code in sorted(self.fault_codes):
                    self._clear_error(code, out)
                self.fault_codes.clear()
                self.error_code = 0
                self._pending_out.extend(out)
                self._go(15, SWITCH_ON_DISABLED)
            return
        if s == FAULT_REACTION_ACTIVE:
            return
        steps = TRANSITIONS.get((s, decode_command(cw)), ())
        if steps and steps[0][0] == 16 and not 5 <= self.quick_stop_option <= 8:
            return                        # 16 only when the quick stop option stays in Quick stop active
        for number, to in steps:
            self._go(number, to)

    def _fault(self, code: int, out: list, hold: bool = False):
        """A fault detected (transition 13): EMCY, 0x603F, fault reaction."""
        self.error_code = code
        self.fault_codes.add(code)
        self.fault_held = self.fault_held or hold
        self._raise_error(code, out)
        if self.state not in (FAULT_REACTION_ACTIVE, FAULT):
            self._go(13, FAULT_REACTION_ACTIVE)
            self.reaction_deadline = self._now + 0.5   # without SYNC; with SYNC it ends at the next one
        self.following = False
        self.demand = self.actual

    # ---- frames in -------------------------------------------------------------------
    _now = 0.0

    def start(self, now: float) -> list:
        """Power on: the boot-up message, then pre-operational."""
        self._now = now
        return self._boot(now)

    def power_on(self, now: float) -> list:
        """Power on again after a power-off: every default (as at
        construction; the position is kept), then the boot-up."""
        self._power_on()
        return self.start(now)

    def _boot(self, now: float) -> list:
        self.nmt = PREOPERATIONAL
        self.booted = True
        self.log('boot-up, NMT pre-operational')
        self.next_heartbeat = now + self.heartbeat_ms / 1000.0 if self.heartbeat_ms else None
        return [(HEARTBEAT_BASE + self.node, bytes([BOOTUP]))]

    def on_frame(self, can_id: int, data: bytes, now: float) -> list:
        self._now = now
        self._pending_out = out = []
        data = bytes(data)
        if can_id == NMT_ID:
            out += self._on_nmt(data, now)
        elif HEARTBEAT_BASE < can_id <= HEARTBEAT_BASE + 127 and can_id != HEARTBEAT_BASE + self.node:
            self._on_heartbeat(can_id - HEARTBEAT_BASE, data, now)
        elif self.nmt == STOPPED:
            pass                          # stopped: NMT and error control only
        elif can_id == self.sync_cob & 0x7FF:
            out += self._on_sync(now)
        elif can_id == SDO_RX_BASE + self.node:
            out += self._on_sdo(data, now)
        elif self.nmt == OPERATIONAL:
            for p in self.rpdos:
                if p.valid and p.can_id == can_id:
                    out += self._on_rpdo(p, data)
                    break
        out += self._event_tpdos(now)
        self._pending_out = []
        return out

    def _on_nmt(self, data: bytes, now: float) -> list:
        if len(data) != 2 or data[1] not in (0, self.node):
            return []
        cs = data[0]
        if cs == NMT_START:
            self._set_nmt(OPERATIONAL)
        elif cs == NMT_STOP:
            self._set_nmt(STOPPED)
        elif cs == NMT_ENTER_PREOP:
            self._set_nmt(PREOPERATIONAL)
        elif cs == NMT_RESET_NODE:
            self.log('NMT reset node')
            self.errors.clear()
            self._reset_application()
            self._reset_communication()
            return self._boot(now)
        elif cs == NMT_RESET_COMM:
            self.log('NMT reset communication')
            self._reset_communication()
            return self._boot(now)
        return []

    def _set_nmt(self, state: int):
        if state == self.nmt or self.nmt == BOOTUP:
            return
        self.log(f'NMT {NMT_NAMES[self.nmt]} -> {NMT_NAMES[state]}')
        self.nmt = state
        for p in self.rpdos + self.tpdos:
            p.restart()
        if state == STOPPED:
            self.sdo = None

    def _on_heartbeat(self, node: int, data: bytes, now: float):
        for i, entry in enumerate(self.consumers):
            if (entry >> 16) & 0xFF == node and entry & 0xFFFF:
                self.consumer_seen[i] = now
                if self.consumer_lost[i]:
                    self.consumer_lost[i] = False
                    self.log(f'heartbeat of node {node} back')
                    if EMCY_HEARTBEAT not in self.fault_codes:   # else the fault reset clears it
                        self._clear_error(EMCY_HEARTBEAT, self._pending_out)

    # ---- SYNC and PDOs --------------------------------------------------------------
    def interpolation_period(self) -> float:
        return self.ip_value * 10.0 ** self.ip_index

    def _on_sync(self, now: float) -> list:
        out = []
        if self.last_sync is not None:
            dt = now - self.last_sync
            st = self.sync_interval
            st[0] += dt
            st[1] = dt if st[1] is None else min(st[1], dt)
            st[2] = dt if st[2] is None else max(st[2], dt)
        self.sync_count += 1
        self.last_sync = now
        # 1. The set-point taken at the last SYNC has been reached (the drive
        #    interpolates to it over the interpolation period, 0x60C2).
        self.prev_actual = self.actual
        was_at = self.actual + self.frac
        if self.following:
            self.actual = self.demand
        period = self.interpolation_period()
        enabled = self.state == OPERATION_ENABLED
        if enabled and self.mode == MODE_CSV:           # 0x60FF in the velocity unit
            self._advance(self.target_velocity * self.counts_per_unit() * period)
        elif enabled and self.mode == MODE_HOMING and self.homing == 'active':
            # to position 0 at 0x6099:1 (search), the last count at 0x6099:2 (zero)
            step = self.homing_speeds[0] * self.counts_per_unit() * period
            if abs(self.actual) <= step or step <= 0:
                self.actual, self.frac, self.homing = -self.home_offset, 0.0, 'attained'
                self.log(f'homing attained at {self.actual}')
            else:
                self._advance(-step if self.actual > 0 else step)
        vel = (self.actual + self.frac - was_at) / period if period > 0 else 0
        # 0x606C: counts/s, or in the velocity unit when the drive has one.
        self.velocity = int(round(vel / self.counts_per_unit()))
        # 2. Synchronous TPDOs, sampled now.
        if self.nmt == OPERATIONAL:
            for p in self.tpdos:
                if not p.valid or p.ttype > 240:
                    continue
                payload = self._tpdo_payload(p)
                if p.ttype == 0:
                    send = payload != p.last_sent
                else:
                    p.sync_count += 1
                    send = p.sync_count >= p.ttype
                if send:
                    p.sync_count = 0
                    out.append(self._send_tpdo(p, payload, now))
        # 3. Drive-internal completions: the fault reaction and a quick stop
        #    with option 0..4 end here (their state was shown once).
        if self.state == FAULT_REACTION_ACTIVE:
            self._go(14, FAULT)
            self.reaction_deadline = None
        elif self.state == QUICK_STOP_ACTIVE and 0 <= self.quick_stop_option <= 4:
            self._go(12, SWITCH_ON_DISABLED)
        # 4. Synchronous RPDOs received since the last SYNC take effect.
        self._pending_out = out
        for p in self.rpdos:
            if p.pending is not None:
                data, p.pending = p.pending, None
                self._write_rpdo(p, data)
        # 5. The new set-point (CSP): the drive follows 0x607A while enabled.
        was = self.demand
        if not enabled or (self.mode != MODE_HOMING and self.homing == 'active'):
            self.homing = None            # a homing ends with the enable or its mode
        # IP (sub-mode 0, linear): the same, with 0x60C1:1 while bit 4 is set.
        ip = self.ip_active()
        self.following = (self.state == OPERATION_ENABLED and self.mode == MODE_CSP) or ip
        if self.following:
            self.demand = self.ip_target if ip else self.target
            if getattr(self, 'pending_enable_log', False):
                self.pending_enable_log = False
                self.enable_log.append((self.actual, self.demand))
                self.log(f'operation enabled at position {self.actual}, first set-point {self.demand} '
                         f'(step {self.demand - self.actual})')
            self.max_step = max(self.max_step, abs(self.demand - was))
        else:
            self.demand = self.actual
        return out

    def _advance(self, counts: float):
        x = self.actual + self.frac + counts
        self.actual = int(math.floor(x))
        self.frac = x - self.actual

    def _tpdo_payload(self, p: Pdo) -> bytes:
        return b''.join(self.od.entries[(i, s)].encode() for i, s, _ in p.mapped())

    def _send_tpdo(self, p: Pdo, payload: bytes, now: float):
        p.last_sent, p.last_time = payload, now
        return (p.can_id, payload)

    def _event_tpdos(self, now: float) -> list:
        """Event-driven TPDOs (254/255): on a change of their data (not before
        the inhibit time) and when the event timer expires."""
        out = []
        if self.nmt != OPERATIONAL:
            return out
        for p in self.tpdos:
            if not p.valid or p.ttype < 254:
                continue
            payload = self._tpdo_payload(p)
            since = None if p.last_time is None else now - p.last_time + 1e-9
            if since is not None and since < p.inhibit / 10000.0:
                continue
            timer = p.event_ms and since is not None and since >= p.event_ms / 1000.0
            if payload != p.last_sent or timer:
                out.append(self._send_tpdo(p, payload, now))
        return out

    def _on_rpdo(self, p: Pdo, data: bytes) -> list:
        out = []
        need = sum(bits for _, _, bits in p.mapped()) // 8
        if len(data) < need:
            # CiA 301: PDO not processed due to length error (EMCY once per episode).
            if not p.length_error:
                p.length_error = True
                self._raise_error(EMCY_PDO_LENGTH, out)
            return out
        if p.length_error:
            p.length_error = False
            if not any(q.length_error for q in self.rpdos):
                self._clear_error(EMCY_PDO_LENGTH, out)
        if p.ttype <= 240:
            p.pending = data              # synchronous: applied at the next SYNC
        else:
            self._pending_out = out
            self._write_rpdo(p, data)
        return out

    def _write_rpdo(self, p: Pdo, data: bytes):
        pos = 0
        for index, sub, bits in p.mapped():
            n = bits // 8
            var = self.od.entries[(index, sub)]
            var.store(var.decode(data[pos:pos + n]))
            pos += n

    # ---- SDO server ------------------------------------------------------------------
    def _abort(self, index: int, sub: int, code: int) -> list:
        self.sdo = None
        self.log(f'SDO abort 0x{index:04X}:{sub:02X}: 0x{code:08X} {ABORT_TEXT.get(code, "")}')
        return [(SDO_TX_BASE + self.node, struct.pack('<BHBI', 0x80, index, sub, code))]

    def _reply(self, data: bytes) -> list:
        return [(SDO_TX_BASE + self.node, data.ljust(8, b'\x00'))]

    def _segment(self, direction: str, toggle: int, now: float):
        """The transfer a segment request continues, and None; or None and
        the abort (no such transfer: 0504 0001h; toggle not alternated: 0503 0000h)."""
        t = self.sdo
        if not t or t['dir'] != direction:
            return None, self._abort(t['index'] if t else 0, t['sub'] if t else 0, ABORT_COMMAND)
        if toggle != t['toggle']:
            return None, self._abort(t['index'], t['sub'], ABORT_TOGGLE)
        t['toggle'] ^= 1
        t['deadline'] = now + self.sdo_timeout
        return t, None

    # ---- SDO block transfer (CiA 301 7.2.4.3.9 .. 7.2.4.3.16) ------------------------
    BLOCK_SIZE = 127                      # segments per sub-block this server asks for

    @staticmethod
    def crc16(data: bytes) -> int:
        """CiA 301 7.2.4.3.16: CRC-CCITT, polynomial x^16 + x^12 + x^5 + 1, initial 0."""
        crc = 0
        for b in data:
            crc ^= b << 8
            for _ in range(8):
                crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
        return crc

    def _sub_block(self, t) -> list:
        """The next sub-block of a block upload: up to blksize segments of 7 bytes."""
        out, t['start'] = [], t['pos']
        pos = t['pos']
        for seq in range(1, t['blksize'] + 1):
            if pos >= len(t['buf']):
                break
            chunk = t['buf'][pos:pos + 7]
            pos += len(chunk)
            last = pos >= len(t['buf'])
            out += self._reply(bytes([0x80 * last | seq]) + chunk)
        return out

    def _on_block(self, data: bytes, now: float) -> list:
        cmd = data[0]
        index, sub = struct.unpack_from('<HB', data, 1)
        t = self.sdo
        if t and t['dir'] == 'bdown' and not t['end'] and cmd != 0x80:      # a sub-block segment
            seq, c = cmd & 0x7F, cmd & 0x80
            if seq == t['seq'] + 1 and not t['last']:                       # in order: kept
                t['buf'] += data[1:8]
                t['seq'], t['last'] = seq, bool(c)
            t['deadline'] = now + self.sdo_timeout
            if not c and seq < self.BLOCK_SIZE:
                return []
            ack = bytes([0xA2, t['seq'], self.BLOCK_SIZE])                  # last in-order segment
            t['seq'] = 0
            t['end'] = t['last']
            return self._reply(ack)
        if cmd >> 5 == 6 and cmd & 0x01 == 0:                               # block download initiate
            self.sdo = None
            if not self.block_transfer:
                return self._abort(index, sub, ABORT_COMMAND)
            var, abort = self.od.find(index, sub)
            if abort:
                return self._abort(index, sub, abort)
            if var.access in ('ro', 'const'):
                return self._abort(index, sub, ABORT_READ_ONLY)
            size = struct.unpack_from('<I', data, 4)[0] if cmd & 0x02 else None
            if size is not None and var.dtype not in NUMERIC and size > var.max_len:
                return self._abort(index, sub, ABORT_LENGTH_HIGH)
            self.sdo = {'dir': 'bdown', 'index': index, 'sub': sub, 'buf': b'', 'size': size, 'seq': 0,
                        'last': False, 'end': False, 'crc': bool(cmd & 0x04), 'deadline': now + self.sdo_timeout}
            return self._reply(struct.pack('<BHBB', 0xA4, index, sub, self.BLOCK_SIZE))
        if cmd >> 5 == 6:                                                    # block download end
            if not t or t['dir'] != 'bdown' or not t['end']:
                return self._abort(t['index'] if t else 0, t['sub'] if t else 0, ABORT_COMMAND)
            self.sdo = None
            buf = t['buf'][:len(t['buf']) - ((cmd >> 2) & 0x07)]
            if t['size'] is not None and len(buf) != t['size']:
                return self._abort(t['index'], t['sub'], ABORT_LENGTH)
            crc = struct.unpack_from('<H', data, 1)[0]
            if t['crc'] and crc != self.crc16(buf):
                return self._abort(t['index'], t['sub'], ABORT_CRC)
            abort = self.od.download(t['index'], t['sub'], buf)
            if abort:
                return self._abort(t['index'], t['sub'], abort)
            self.block_log.append(('download', t['index'], t['sub'], buf, crc))
            self.log(f"SDO block download 0x{t['index']:04X}:{t['sub']:02X}: {len(buf)} bytes, "
                     f"CRC 0x{crc:04X} {'checked' if t['crc'] else '(not used)'}")
            return self._reply(bytes([0xA1]))
        cs = cmd & 0x03                                                      # ccs 5: block upload
        if cs == 0:
            self.sdo = None
            if not self.block_transfer:
                return self._abort(index, sub, ABORT_COMMAND)
            if not 1 <= data[4] <= 127:
                return self._abort(index, sub, ABORT_BLOCK_SIZE)
            value, abort = self.od.upload(index, sub)
            if abort:
                return self._abort(index, sub, abort)
            self.sdo = {'dir': 'bup', 'index': index, 'sub': sub, 'buf': value, 'pos': 0, 'start': 0,
                        'blksize': data[4], 'crc': bool(cmd & 0x04), 'started': False,
                        'deadline': now + self.sdo_timeout}
            return self._reply(struct.pack('<BHBI', 0xC6, index, sub, len(value)))
        if not t or t['dir'] != 'bup':
            return self._abort(index, sub, ABORT_COMMAND)
        t['deadline'] = now + self.sdo_timeout
        if cs == 3 and not t['started']:                                     # start
            t['started'] = True
            return self._sub_block(t)
        if cs == 2 and t['started']:                                         # ack of a sub-block
            ackseq, t['blksize'] = data[1], data[2]
            if not 1 <= t['blksize'] <= 127:
                return self._abort(t['index'], t['sub'], ABORT_BLOCK_SIZE)
            t['pos'] = min(len(t['buf']), t['start'] + 7 * ackseq)
            if t['pos'] < len(t['buf']):
                return self._sub_block(t)
            n = 7 - (len(t['buf']) - 7 * ((len(t['buf']) - 1) // 7)) if t['buf'] else 7
            crc = self.crc16(t['buf']) if t['crc'] else 0
            t['ended'] = True
            return self._reply(struct.pack('<BH', 0xC1 | n << 2, crc))
        if cs == 1 and t.get('ended'):                                       # the client's end response
            self.sdo = None
            self.block_log.append(('upload', t['index'], t['sub'], t['buf'], self.crc16(t['buf'])))
            return []
        return self._abort(t['index'], t['sub'], ABORT_COMMAND)

    def _on_sdo(self, data: bytes, now: float) -> list:
        if len(data) != 8:
            return []                     # not an SDO request (CiA 301: DLC 8)
        cmd = data[0]
        ccs = cmd >> 5
        if (self.sdo and self.sdo['dir'] in ('bdown', 'bup') and cmd != 0x80) or ccs in (5, 6):  # (0x81..0xFF: segments)
            return self._on_block(data, now)
        index, sub = struct.unpack_from('<HB', data, 1)
        if ccs == 4:                      # abort from the client
            self.sdo = None
            return []
        if ccs == 1:                      # initiate download
            self.sdo = None
            expedited, sized = cmd & 0x02, cmd & 0x01
            var, abort = self.od.find(index, sub)
            if abort:
                return self._abort(index, sub, abort)
            if var.access in ('ro', 'const'):
                return self._abort(index, sub, ABORT_READ_ONLY)
            if expedited:
                n = (cmd >> 2) & 0x03 if sized else 0
                payload = data[4:8 - n]
                if not sized and var.dtype in NUMERIC:
                    payload = payload[:var.size]
                abort = self.od.download(index, sub, payload)
                if abort:
                    return self._abort(index, sub, abort)
                return self._reply(struct.pack('<BHB', 0x60, index, sub))
            size = struct.unpack_from('<I', data, 4)[0] if sized else None
            if size is not None:
                if var.dtype in NUMERIC and size != var.size:
                    return self._abort(index, sub, ABORT_LENGTH)
                if var.dtype not in NUMERIC and size > var.max_len:
                    return self._abort(index, sub, ABORT_LENGTH_HIGH)
            self.sdo = {'dir': 'down', 'index': index, 'sub': sub, 'toggle': 0, 'buf': b'', 'size': size,
                        'deadline': now + self.sdo_timeout}
            return self._reply(struct.pack('<BHB', 0x60, index, sub))
        toggle = (cmd >> 4) & 1
        if ccs == 0:                      # download segment
            t, refused = self._segment('down', toggle, now)
            if refused:
                return refused
            n, last = (cmd >> 1) & 0x07, cmd & 0x01
            t['buf'] += data[1:8 - n]
            if t['size'] is not None and len(t['buf']) > t['size']:
                return self._abort(t['index'], t['sub'], ABORT_LENGTH)
            if last:
                self.sdo = None
                if t['size'] is not None and len(t['buf']) != t['size']:
                    return self._abort(t['index'], t['sub'], ABORT_LENGTH)
                abort = self.od.download(t['index'], t['sub'], t['buf'])
                if abort:
                    return self._abort(t['index'], t['sub'], abort)
            return self._reply(bytes([0x20 | toggle << 4]))
        if ccs == 2:                      # initiate upload
            self.sdo = None
            value, abort = self.od.upload(index, sub)
            if abort:
                return self._abort(index, sub, abort)
            if 1 <= len(value) <= 4:
                return self._reply(struct.pack('<BHB', 0x43 | (4 - len(value)) << 2, index, sub) + value)
            self.sdo = {'dir': 'up', 'index': index, 'sub': sub, 'toggle': 0, 'buf': value, 'pos': 0,
                        'deadline': now + self.sdo_timeout}
            return self._reply(struct.pack('<BHBI', 0x41, index, sub, len(value)))
        if ccs == 3:                      # upload segment
            t, refused = self._segment('up', toggle, now)
            if refused:
                return refused
            chunk = t['buf'][t['pos']:t['pos'] + 7]
            t['pos'] += len(chunk)
            last = t['pos'] >= len(t['buf'])
            if last:
                self.sdo = None
            return self._reply(bytes([toggle << 4 | (7 - len(chunk)) << 1 | int(last)]) + chunk)
        return self._abort(index, sub, ABORT_COMMAND)     # 7: no such command

    # ---- time ------------------------------------------------------------------------
    def tick(self, now: float) -> list:
        """Timers: heartbeat producer and consumer, SDO timeout, fault
        reaction without SYNC, TPDO event timers."""
        self._now = now
        self._pending_out = out = []
        if self.next_heartbeat is not None and now >= self.next_heartbeat and self.nmt != BOOTUP:
            out.append((HEARTBEAT_BASE + self.node, bytes([self.nmt])))
            period = self.heartbeat_ms / 1000.0
            self.next_heartbeat += period
            if self.next_heartbeat <= now:
                self.next_heartbeat = now + period
        if self.sdo and now >= self.sdo['deadline']:
            out += self._abort(self.sdo['index'], self.sdo['sub'], ABORT_TIMEOUT)
        for i, entry in enumerate(self.consumers):
            seen = self.consumer_seen[i]
            ms = entry & 0xFFFF
            if ms and seen is not None and not self.consumer_lost[i] and now >= seen + ms / 1000.0:
                self.consumer_lost[i] = True
                node = (entry >> 16) & 0xFF
                self.log(f'heartbeat of node {node} lost (consumer time {ms} ms)')
                if self.state in (OPERATION_ENABLED, QUICK_STOP_ACTIVE):
                    self._fault(EMCY_HEARTBEAT, out)      # EMCY, and a fault the reset clears
                else:
                    self._raise_error(EMCY_HEARTBEAT, out)
                if self.nmt == OPERATIONAL:   # 0x1029 default: pre-operational
                    self._set_nmt(PREOPERATIONAL)
        if self.reaction_deadline is not None and now >= self.reaction_deadline and self.state == FAULT_REACTION_ACTIVE:
            self._go(14, FAULT)           # no SYNC: the reaction completes on its own
            self.reaction_deadline = None
        out += self._event_tpdos(now)
        self._pending_out = []
        return out

    def next_deadline(self):
        """The next time tick() has something to do (None: nothing pending)."""
        times = [self.next_heartbeat]
        if self.sdo:
            times.append(self.sdo['deadline'])
        if self.reaction_deadline is not None:
            times.append(self.reaction_deadline)
        for i, entry in enumerate(self.consumers):
            if entry & 0xFFFF and self.consumer_seen[i] is not None and not self.consumer_lost[i]:
                times.append(self.consumer_seen[i] + (entry & 0xFFFF) / 1000.0)
        if self.nmt == OPERATIONAL:
            for p in self.tpdos:
                if p.valid and p.ttype >= 254 and p.last_time is not None:
                    if p.event_ms:
                        times.append(p.last_time + p.event_ms / 1000.0)
                    if p.inhibit and self._tpdo_payload(p) != p.last_sent:   # a change held back
                        times.append(p.last_time + p.inhibit / 10000.0)
        times = [t for t in times if t is not None]
        return min(times) if times else None

    # ---- fault injection and local commands ---------------------------------------
    def inject_fault(self, now: float, code: int = None, hold: bool = False) -> list:
        self._now = now
        out = []
        self._fault(self.fault_code if code is None else code, out, hold)
        return out

    def clear_held_fault(self):
        self.fault_held = False

    def local_nmt(self, state: int):
        """A local NMT transition (as a drive does on a communication error, 0x1029)."""
        self._set_nmt(state)

    def summary(self) -> str:
        total, lo, hi = self.sync_interval
        s = f'{self.sync_count} SYNC'
        if self.sync_count > 1:
            s += (f', interval mean {1e3 * total / (self.sync_count - 1):.3f} ms min {1e3 * lo:.3f} ms '
                  f'max {1e3 * hi:.3f} ms')
        s += (f'; 0x60C2 = {self.ip_value} x 10^{self.ip_index} s; position {self.actual}; '
              f'largest set-point step {self.max_step}; state {STATE_NAMES[self.state]}; NMT {NMT_NAMES[self.nmt]}')
        return s

    @staticmethod
    def _mapping_text(p: Pdo) -> str:
        return '[' + ', '.join(f'0x{i:04X}:{s:02X}/{b}' for i, s, b in p.mapped()) + ']'


# ============================================================================
# I/O: a python-can bus, a control channel, signals
# ============================================================================

COMMANDS_HELP = """Control commands (one per line on --control FIFO or stdin):
  fault [CODE] [hold]   inject a drive fault: EMCY CODE (default --fault-code),
                        0x603F = CODE, CiA 402 transition 13 (Fault reaction
                        active), then Fault at the next SYNC. With `hold` the
                        fault persists (fault reset refused) until `clear`.
  clear                 the held fault condition is gone
  silence               stop sending and receiving (a drive that vanishes
                        without its process dying); `resume` undoes it
  nmt preop|stop|op     a local NMT transition (as on a communication error)
  reset                 power cycle: NMT reset node (boot-up sent)
  power off|on          power off: no frames in or out, no timers (the
                        drive has no supply); power on: every default, the
                        boot-up, pre-operational (see --powered-off)
  status                print the CiA 402 and NMT state
  quit                  exit (status 0)
Signals: SIGUSR1 = `fault`, SIGUSR2 = `reset`, SIGINT/SIGTERM = exit 0."""


class Runner:
    """Moves frames between a python-can bus and a Drive."""

    def __init__(self, drive: Drive, bus, clock=time.monotonic, out=sys.stdout, powered=True):
        self.drive, self.bus, self.clock, self.out = drive, bus, clock, out
        self.silent = False
        self.powered = powered            # False: no supply, nothing in or out until `power on`
        self.stop = False
        self.sent = 0
        self.bus_error = None             # the errno of the last failed recv/send, while it lasts (logged once)

    def send(self, frames):
        import can   # here, not at the top: the trace checks import this module without python-can
        if self.silent or not self.powered:
            return
        for can_id, data in frames:
            msg = can.Message(arbitration_id=can_id, data=data, is_extended_id=False)
            for attempt in range(50):
                try:
                    self.bus.send(msg)
                    self.sent += 1
                    self.bus_ok()
                    break
                except can.CanError as e:     # ENOBUFS: the queue is full, retry shortly
                    if getattr(e, 'error_code', None) == errno.ENETDOWN:
                        self.bus_failed('send', e)   # the interface is down: the frame is lost, as on a cut cable
                        break
                    if attempt == 49:
                        print(f'cia402_peer: send 0x{can_id:03X} failed: {e}', file=sys.stderr)
                    time.sleep(0.001)

    def bus_failed(self, what, e):
        """A recv or send the interface refused (ENETDOWN: `ip link set
        vcan0 down`): logged once until the bus works again; the drive runs
        on, as a drive whose cable is cut."""
        code = getattr(e, 'error_code', None)
        if self.bus_error != code:
            self.bus_error = code
            self.drive.log(f'bus: {what} failed: {e}')
            print(f'cia402_peer: bus: {what} failed: {e}', file=sys.stderr, flush=True)

    def bus_ok(self):
        """A frame went out: the interface is up (again)."""
        if self.bus_error is not None:
            self.bus_error = None
            self.drive.log('bus: frames flow again')

    def recv(self, timeout=0):
        """One frame from the bus, or None; a failed recv (ENETDOWN after
        the interface went down) is logged, not raised."""
        import can
        try:
            msg = self.bus.recv(timeout=timeout)
        except can.CanError as e:
            self.bus_failed('recv', e)
            return None
        return msg    # a frame read is no sign that the interface is up: it may have waited since before it went down

    def start(self, now=None):
        if not self.powered:
            self.drive.log('powered off: no frames in or out until `power on`')
            return
        self.send(self.drive.start(self.clock() if now is None else now))

    def tick(self, now: float):
        if self.powered:
            self.send(self.drive.tick(now))

    def next_deadline(self):
        """The drive's next timer; None while powered off (no timers run)."""
        return self.drive.next_deadline() if self.powered else None

    def handle(self, msg, now: float):
        if self.silent or not self.powered or msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id:
            return
        self.send(self.drive.on_frame(msg.arbitration_id, bytes(msg.data), now))

    def pump(self, now=None):
        """Process every frame waiting on the bus, then the timers (which run
        on while silenced: only the frames are dropped)."""
        while True:
            msg = self.recv(timeout=0)
            if msg is None:
                break
            self.handle(msg, self.clock() if now is None else now)
        self.tick(self.clock() if now is None else now)

    def command(self, line: str):
        words = line.split()
        if not words:
            return
        d, now = self.drive, self.clock()
        try:
            if words[0] == 'fault':
                code = int(words[1], 0) if len(words) > 1 and words[1] != 'hold' else None
                self.send(d.inject_fault(now, code, hold='hold' in words[1:]))
            elif words[0] == 'clear':
                d.clear_held_fault()
            elif words[0] == 'silence':
                self.silent = True
                d.log('silenced: no frames in or out')
            elif words[0] == 'resume':
                self.silent = False
                d.log('resumed')
            elif words[0] == 'nmt' and len(words) == 2 and words[1] in ('preop', 'stop', 'op'):
                d.local_nmt({'preop': PREOPERATIONAL, 'stop': STOPPED, 'op': OPERATIONAL}[words[1]])
            elif words[0] == 'reset':
                self.send(d.on_frame(NMT_ID, bytes([NMT_RESET_NODE, d.node]), now))
            elif words[0] == 'power' and len(words) == 2 and words[1] in ('on', 'off'):
                if words[1] == 'off':
                    self.powered = False
                    d.log('power off: no frames in or out')
                elif not self.powered:
                    self.powered = True
                    d.log('power on')
                    self.send(d.power_on(now))
            elif words[0] == 'status':
                print(f'cia402_peer node {d.node}: {d.summary()}', file=self.out, flush=True)
            elif words[0] == 'quit':
                self.stop = True
            else:
                raise ValueError('unknown command')
        except (ValueError, IndexError) as e:
            print(f"cia402_peer: control: '{line.strip()}': {e} (commands: fault, clear, silence, resume, "
                  f"nmt, reset, power, status, quit)", file=sys.stderr, flush=True)

    def run(self, control_fd=None, duration=None):
        """Serve until quit, a signal (self.stop) or `duration` seconds."""
        self.start()
        t_end = None if duration is None else self.clock() + duration
        try:
            bus_fd = self.bus.fileno()
        except (NotImplementedError, AttributeError):
            bus_fd = None
        pending = b''
        while not self.stop:
            now = self.clock()
            if t_end is not None and now >= t_end:
                break
            deadline = self.next_deadline()
            wait = 0.1 if deadline is None else max(0.0, min(0.1, deadline - now))
            if t_end is not None:
                wait = min(wait, max(0.0, t_end - now))
            fds = [f for f in (bus_fd, control_fd) if f is not None]
            if bus_fd is None:
                ready = []
                msg = self.recv(timeout=min(wait, 0.01))
                if msg is not None:
                    self.handle(msg, self.clock())
                if control_fd is not None:
                    ready = select.select([control_fd], [], [], 0)[0]
            else:
                try:
                    ready = select.select(fds, [], [], wait)[0]
                except InterruptedError:
                    ready = []
            if bus_fd is not None and bus_fd in ready:
                # A bounded batch, so that the timers (heartbeat) run even
                # when frames come faster than this process handles them.
                t_batch = self.clock() + 0.005
                while self.clock() < t_batch:
                    msg = self.recv(timeout=0)
                    if msg is None:
                        break
                    self.handle(msg, self.clock())
            if control_fd is not None and control_fd in ready:
                try:
                    chunk = os.read(control_fd, 4096)
                except BlockingIOError:
                    chunk = b''
                pending += chunk
                while b'\n' in pending:
                    line, pending = pending.split(b'\n', 1)
                    self.command(line.decode(errors='replace'))
                if not chunk and control_fd == 0:
                    control_fd = None     # stdin closed
            self.tick(self.clock())


def open_control(path: str):
    """The control channel: '-' = stdin, else a FIFO (created if missing),
    opened read-write so that writers may come and go."""
    if path == '-':
        os.set_blocking(0, False)
        return 0
    if not os.path.exists(path):
        os.mkfifo(path)
    return os.open(path, os.O_RDWR | os.O_NONBLOCK)


def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog='cia402_peer.py',
        description='A minimal CiA 402 servo drive (CANopen slave, CSP) on python-can, written from the '
                    'CiA 301/402 tables; an independent peer for canmotion tests.',
        epilog=COMMANDS_HELP + """

Examples:
  /usr/bin/python3 tests/peers/cia402_peer.py -i vcan0 -n 5 --position 123456 -v
  mkfifo /tmp/peer.ctl; /usr/bin/python3 tests/peers/cia402_peer.py -i vcan0 -n 5 --control /tmp/peer.ctl &
  echo 'fault 0xFF00' > /tmp/peer.ctl

Exit status: 0 after quit, SIGINT/SIGTERM or --duration; 1 on errors (bus, arguments).""",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('-i', '--interface', required=True, help='CAN channel (vcan0, can0)')
    ap.add_argument('--bus-type', default='socketcan', help='python-can interface type (default socketcan)')
    ap.add_argument('-n', '--node', type=int, required=True, help='node-ID 1..127')
    ap.add_argument('--rpdos', type=int, default=2, help='number of RPDOs, 1..8 (default 2)')
    ap.add_argument('--tpdos', type=int, default=2, help='number of TPDOs, 1..8 (default 2)')
    ap.add_argument('--position', type=int, default=0, help='position actual value at power-on, counts (default 0)')
    ap.add_argument('--heartbeat-ms', type=int, default=0, help='default of 0x1017 (default 0 = off)')
    ap.add_argument('--consumer-heartbeat', type=int, default=0, metavar='N',
                    help='give the drive 0x1016 with N entries (default 0: the object is absent)')
    ap.add_argument('--fault-code', type=lambda s: int(s, 0), default=0xFF00,
                    help='EMCY code of `fault` and SIGUSR1 (default 0xFF00)')
    ap.add_argument('--sdo-timeout-ms', type=int, default=1000, help='segmented transfer timeout (default 1000)')
    ap.add_argument('--velocity-unit', choices=('inc/s', 'rpm'),
                    help='drive units: 0x60A9 = inc/s or rpm, and CSV (mode 9) and homing (mode 6): 0x60FF, '
                         '0x6099 and 0x606C in that unit (default: CSP only, no 0x60A9)')
    ap.add_argument('--encoder-increments', type=int, default=0, metavar='N',
                    help='0x608F:1, increments per motor revolution (needed by rpm)')
    ap.add_argument('--modes', default='csp', metavar='LIST',
                    help="position modes: csp (default), ip (interpolated position, mode 7: 0x60C0, 0x60C1:1, "
                         "controlword bit 4; an IP-only drive) or csp,ip")
    ap.add_argument('--control', metavar='PATH', help="control channel: a FIFO path, or '-' for stdin")
    ap.add_argument('--powered-off', action='store_true',
                    help='start without power: silent (no boot-up, nothing answered) until the control command '
                         '`power on` (a drive switched on after the master)')
    ap.add_argument('--duration', type=float, help='exit after this many seconds')
    ap.add_argument('-v', '--verbose', action='store_true', help='print NMT, CiA 402, PDO, SDO-abort and EMCY events')
    a = ap.parse_args(argv)
    if not 1 <= a.node <= 127:
        ap.error(f'--node {a.node}: a node-ID is 1..127')
    if not 1 <= a.rpdos <= 8 or not 1 <= a.tpdos <= 8:
        ap.error('--rpdos and --tpdos are 1..8')
    if not 0 <= a.heartbeat_ms <= 0xFFFF:
        ap.error('--heartbeat-ms is 0..65535')
    if not 0 <= a.consumer_heartbeat <= 127:
        ap.error('--consumer-heartbeat is 0..127')
    if not 0 <= a.fault_code <= 0xFFFF:
        ap.error('--fault-code is a 16-bit EMCY code')
    return a


def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    t0 = time.monotonic()

    def log(msg):
        if a.verbose:
            print(f'cia402_peer node {a.node} +{time.monotonic() - t0:.6f}: {msg}', flush=True)

    try:
        import can
        bus = can.Bus(interface=a.bus_type, channel=a.interface)
    except Exception as e:   # python-can raises several types for a missing interface
        print(f'cia402_peer: cannot open {a.bus_type} bus {a.interface}: {e}', file=sys.stderr)
        return 1
    try:
        drive = Drive(a.node, a.rpdos, a.tpdos, a.position, a.heartbeat_ms, a.consumer_heartbeat, a.fault_code,
                      a.sdo_timeout_ms / 1000.0, log, a.velocity_unit, a.encoder_increments, a.modes)
    except ValueError as e:
        print(f'cia402_peer: {e}', file=sys.stderr)
        return 2
    runner = Runner(drive, bus, powered=not a.powered_off)

    def on_stop(signum, frame):
        runner.stop = True

    signal.signal(signal.SIGINT, on_stop)
    signal.signal(signal.SIGTERM, on_stop)
    signal.signal(signal.SIGUSR1, lambda s, f: runner.command('fault'))
    signal.signal(signal.SIGUSR2, lambda s, f: runner.command('reset'))
    control = open_control(a.control) if a.control else None
    print(f'cia402_peer: node {a.node} on {a.interface}: {a.rpdos} RPDO, {a.tpdos} TPDO, position {a.position}, '
          f"0x1016 {'with %d entries' % a.consumer_heartbeat if a.consumer_heartbeat else 'absent'}"
          f"{', control ' + a.control if a.control else ''}{', powered off' if a.powered_off else ''}", flush=True)
    try:
        runner.run(control, a.duration)
    finally:
        print(f'cia402_peer: node {a.node}: {drive.summary()}', flush=True)
        bus.shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
