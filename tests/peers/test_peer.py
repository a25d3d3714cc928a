"""Unit tests of the independent CiA 402 peer (tests/peers/cia402_peer.py).

Run: /usr/bin/python3 -m unittest discover -s tests/peers -p 'test_*.py'
(ctest label `unit`). Everything runs on python-can's in-process `virtual`
bus and a virtual clock (link.VirtualLink): no AF_CAN, no sleeping.
Each expectation is written from the CiA 301 / CiA 402 tables, not from
canmotion's fieldbus/ code: spec_checks.py's conformance checks (each
names its clause) plus the peer's own options and fault injection below.
"""

import os
import struct
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import cia402_peer as peer  # noqa: E402
import spec_checks  # noqa: E402
from link import SdoClient, VirtualLink  # noqa: E402

NODE = 5
SYNC, EMCY, TPDO1, TPDO2, RPDO1, HB = 0x080, 0x080 + NODE, 0x180 + NODE, 0x280 + NODE, 0x200 + NODE, 0x700 + NODE
PERIOD = 0.004


class PeerCase(unittest.TestCase):
    def make(self, **kw):
        self.link = VirtualLink(peer.Drive(NODE, **kw))
        self.drive = self.link.drive
        self.sdo = SdoClient(self.link, NODE)
        self.addCleanup(self.link.close)
        return self.link

    def frames(self, can_id):
        """Queued frames with this id (consumed), oldest first."""
        self.link.poll()
        got = [f for f in self.link.queue if f[1] == can_id]
        self.link.queue = [f for f in self.link.queue if f[1] != can_id]
        return got

    def nmt(self, cs, node=NODE):
        self.link.send(0x000, bytes([cs, node]))

    def sync(self, n=1):
        out = []
        for _ in range(n):
            self.link.send(SYNC)
            out += self.frames(TPDO1)
            self.link.advance(PERIOD)
        return out

    def csp(self, position=None):
        """The CSP set-up a master does: PDOs remapped, 0x6060 = 8, NMT start."""
        c = spec_checks.Ctx(self.link, NODE, PERIOD)
        c.csp_pdos()
        self.sdo.write(0x6060, 0, 8, '<b')
        self.nmt(0x01)
        return c

    def rpdo(self, cw, target):
        self.link.send(RPDO1, struct.pack('<Hi', cw, target))

    def enable(self, target):
        for cw in (0x0006, 0x0007, 0x000F):
            self.rpdo(cw, target)
            self.sync()
        self.assertEqual(self.drive.state, peer.OPERATION_ENABLED)


class SpecConformance(unittest.TestCase):
    """spec_checks.CHECKS against the peer: every one must pass (none may skip)."""


def _add_spec_test(name, clause, fn):
    def test(self):
        link = VirtualLink(peer.Drive(NODE))
        self.addCleanup(link.close)
        c = spec_checks.Ctx(link, NODE, PERIOD)
        c.reset()
        fn(c)
    test.__doc__ = clause
    setattr(SpecConformance, 'test_' + name, test)


for _name, _clause, _fn in spec_checks.CHECKS:
    _add_spec_test(_name, _clause, _fn)


class Sdo(PeerCase):
    def test_multi_segment_download_and_upload(self):
        self.make()
        for n in (5, 7, 14, 20, 64):        # 7 and 14: the last segment is full (n = 0)
            text = bytes(range(0x41, 0x41 + n))
            self.sdo.download(0x2000, 0, text)
            self.assertEqual(self.sdo.upload(0x2000, 0), text, f'{n} bytes')

    def test_expedited_upload_frames(self):
        # 4/2/1 bytes: 43h/4Bh/4Fh (n = unused bytes, e = s = 1), index and sub echoed.
        self.make()
        for (index, sub), want in (((0x1000, 0), '4300100092010200'), ((0x6041, 0), '4b41600050020000'),
                                   ((0x1018, 0), '4f18100004000000')):
            self.link.send(0x600 + NODE, struct.pack('<BHB4x', 0x40, index, sub))
            self.assertEqual(self.frames(0x580 + NODE)[0][2].hex(), want)

    def test_segmented_upload_frames(self):
        # 0x1008 = 21 bytes: 41h + size 21, then 3 segments: 00h, 10h, then
        # 0x0B = toggle 0, n = 0 (7 bytes), c = 1 (CiA 301 upload segment).
        self.make()
        self.link.send(0x600 + NODE, struct.pack('<BHB4x', 0x40, 0x1008, 0))
        self.assertEqual(self.frames(0x580 + NODE)[0][2], struct.pack('<BHBI', 0x41, 0x1008, 0, 21))
        cmds = []
        for toggle in (0, 1, 0):
            self.link.send(0x600 + NODE, bytes([0x60 | toggle << 4]) + bytes(7))
            cmds.append(self.frames(0x580 + NODE)[0][2][0])
        self.assertEqual(cmds, [0x00, 0x10, 0x01])

    def test_expedited_download_without_size(self):
        # e = 1, s = 0 (22h): the server takes the object's size from 4 data bytes.
        self.make()
        self.link.send(0x600 + NODE, struct.pack('<BHBI', 0x22, 0x607A, 0, 0xFFFFFF85))
        self.assertEqual(self.frames(0x580 + NODE)[0][2][0], 0x60)
        self.assertEqual(self.sdo.read(0x607A, 0, '<i'), -123)

    def test_segmented_download_size_mismatch_at_initiate(self):
        self.make()
        self.assertEqual(self.sdo.abort_code(self.sdo.download, 0x6040, 0, b'\x0f\x00\x00\x00', segmented=True),
                         peer.ABORT_LENGTH)

    def test_segmented_download_unsized_too_long(self):
        self.make()
        r = self.sdo.request(struct.pack('<BHB', 0x20, 0x6040, 0))     # no size indicated
        self.assertEqual(r[0], 0x60)
        r = self.sdo.request(bytes([0x00 | 3 << 1 | 1, 1, 2, 3, 4]))    # 4 bytes, last
        self.assertEqual(struct.unpack_from('<BHBI', r), (0x80, 0x6040, 0, peer.ABORT_LENGTH))

    def test_string_too_long(self):
        self.make()
        self.assertEqual(self.sdo.abort_code(self.sdo.download, 0x2000, 0, bytes(65)), peer.ABORT_LENGTH_HIGH)

    def test_server_timeout(self):
        self.make()
        r = self.sdo.request(struct.pack('<BHB', 0x40, 0x1008, 0))
        self.assertEqual(r[0], 0x41)
        self.link.advance(0.9)
        self.assertEqual(self.frames(0x580 + NODE), [])
        self.link.advance(0.2)
        (t, _, data), = self.frames(0x580 + NODE)
        self.assertEqual(struct.unpack_from('<BHBI', data), (0x80, 0x1008, 0, peer.ABORT_TIMEOUT))

    def test_client_abort_ends_transfer(self):
        self.make()
        self.sdo.request(struct.pack('<BHB', 0x40, 0x1008, 0))
        self.link.send(0x600 + NODE, struct.pack('<BHBI', 0x80, 0x1008, 0, 0x05040000))
        self.assertEqual(self.frames(0x580 + NODE), [])
        r = self.sdo.request(bytes([0x60]))
        self.assertEqual(struct.unpack_from('<I', r, 4)[0], peer.ABORT_COMMAND)

    def test_block_transfer_refused(self):
        self.make()
        self.drive.block_transfer = False                                # a drive without block transfer
        r = self.sdo.request(struct.pack('<BHBB', 0xA4, 0x1008, 0, 127))  # block upload initiate
        self.assertEqual(struct.unpack_from('<BHBI', r), (0x80, 0x1008, 0, peer.ABORT_COMMAND))

    def test_crc16_check_value(self):
        # CRC-16/XMODEM (CiA 301: CCITT 0x1021, initial 0): "123456789" -> 0x31C3
        self.assertEqual(peer.Drive.crc16(b'123456789'), 0x31C3)

    def block_download(self, data: bytes, lose=None, crc=None):
        """Block download of `data` to 0x2000 with segment number `lose` of
        the first sub-block left out (then resent); the server's answers."""
        r = self.sdo.request(struct.pack('<BHBI', 0xC6, 0x2000, 0, len(data)))
        self.assertEqual(r[:4], struct.pack('<BHB', 0xA4, 0x2000, 0))
        blksize = r[4]
        self.assertEqual(blksize, 127)
        segs = [data[i:i + 7] for i in range(0, len(data), 7)]
        first = 0
        while True:
            for seq, chunk in enumerate(segs[first:first + blksize], 1):
                last = first + seq == len(segs)
                if seq == lose:
                    lose = None
                    continue
                self.link.send(0x600 + NODE, (bytes([0x80 * last | seq]) + chunk).ljust(8, b'\x00'))
            (_, _, ack), = self.frames(0x580 + NODE)
            self.assertEqual(ack[0], 0xA2)
            first += ack[1]
            if first == len(segs):
                break
        n = 7 - (len(data) - 7 * (len(segs) - 1))
        crc = peer.Drive.crc16(data) if crc is None else crc
        return self.sdo.request(struct.pack('<BH', 0xC1 | n << 2, crc))

    def test_block_download_with_crc_and_a_lost_segment(self):
        self.make()
        data = bytes(range(0x41, 0x41 + 40))
        r = self.block_download(data, lose=3)
        self.assertEqual(r[0], 0xA1)
        self.assertEqual(self.sdo.upload(0x2000, 0), data)
        self.assertEqual(self.drive.block_log[-1][3], data)

    def test_block_download_with_a_wrong_crc(self):
        self.make()
        data = bytes(range(0x41, 0x41 + 20))
        r = self.block_download(data, crc=peer.Drive.crc16(data) ^ 1)
        self.assertEqual(struct.unpack_from('<BHBI', r), (0x80, 0x2000, 0, peer.ABORT_CRC))

    def test_block_upload_with_crc_and_a_resend(self):
        self.make()
        name = self.sdo.upload(0x1008, 0)
        r = self.sdo.request(struct.pack('<BHBBB', 0xA4, 0x1008, 0, 127, 0))
        self.assertEqual(struct.unpack_from('<BHBI', r), (0xC6, 0x1008, 0, len(name)))
        self.link.send(0x600 + NODE, bytes([0xA3]).ljust(8, b'\x00'))
        segs = [f[2] for f in self.frames(0x580 + NODE)]
        self.assertEqual(len(segs), (len(name) + 6) // 7)
        self.assertEqual([s[0] & 0x7F for s in segs], list(range(1, len(segs) + 1)))
        self.assertEqual(segs[-1][0] & 0x80, 0x80)
        # Segment 2 "lost": ack 1, the server resends from the 2nd segment, numbered from 1.
        self.link.send(0x600 + NODE, bytes([0xA2, 1, 127]).ljust(8, b'\x00'))
        again = [f[2] for f in self.frames(0x580 + NODE)]
        self.assertEqual(again[0], bytes([1]) + name[7:14])
        got = segs[0][1:] + b''.join(s[1:] for s in again)
        self.link.send(0x600 + NODE, bytes([0xA2, len(again), 127]).ljust(8, b'\x00'))
        (_, _, end), = self.frames(0x580 + NODE)
        n = (end[0] >> 2) & 7
        self.assertEqual(end[0] & 0xE3, 0xC1)
        self.assertEqual(got[:len(got) - n], name)
        self.assertEqual(struct.unpack_from('<H', end, 1)[0], peer.Drive.crc16(name))
        self.link.send(0x600 + NODE, bytes([0xA1]).ljust(8, b'\x00'))
        self.assertEqual(self.drive.block_log[-1][:4], ('upload', 0x1008, 0, name))

    def test_value_range(self):
        self.make()
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x6060, 0, 1, '<b'), peer.ABORT_VALUE)   # PP: not supported
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x605A, 0, 9, '<h'), peer.ABORT_VALUE)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1005, 0, 0x40000080), peer.ABORT_VALUE)  # SYNC producer

    def test_short_request_ignored(self):
        self.make()
        self.link.send(0x600 + NODE, bytes([0x40, 0x00, 0x10, 0x00]))
        self.assertEqual(self.frames(0x580 + NODE), [])


class Nmt(PeerCase):
    def test_boot_up_first(self):
        self.make()
        self.assertEqual(self.link.log[0][1:], (HB, b'\x00'))

    def test_broadcast_and_other_nodes(self):
        self.make(heartbeat_ms=10)
        self.nmt(0x01, node=6)
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)
        self.nmt(0x01, node=0)
        self.assertEqual(self.drive.nmt, peer.OPERATIONAL)
        self.link.advance(0.011)
        self.assertEqual(self.frames(HB)[-1][2], b'\x05')

    def test_pdos_only_in_operational(self):
        self.make()
        spec_checks.Ctx(self.link, NODE, PERIOD).csp_pdos()
        self.sdo.write(0x6040, 0, 0x0006, '<H')
        self.rpdo(0x0000, 0)                    # ignored in pre-operational
        self.assertEqual(self.sync(2), [])      # no TPDO in pre-operational
        self.assertEqual(self.drive.state, peer.READY_TO_SWITCH_ON)
        self.nmt(0x01)
        self.assertEqual(len(self.sync(2)), 2)
        self.nmt(0x02)
        self.assertEqual(self.sync(2), [])

    def test_reset_node_restores_defaults_keeps_position(self):
        self.make(position=123456)
        self.csp()
        self.sdo.write(0x1017, 0, 100, '<H')
        self.nmt(0x81)
        self.assertEqual(self.frames(HB)[-1][2], b'\x00')
        self.assertEqual(self.sdo.read(0x1A00, 0, '<B'), 1)             # default mapping: statusword
        self.assertEqual(self.sdo.read(0x1A00, 1), 0x60410010)
        self.assertEqual(self.sdo.read(0x1800, 1), 0x40000000 | TPDO1)  # valid, no RTR
        self.assertEqual(self.sdo.read(0x1801, 1) >> 31, 1)             # TPDO2 not valid
        self.assertEqual(self.sdo.read(0x1017, 0, '<H'), 0)
        self.assertEqual(self.sdo.read(0x6060, 0, '<b'), 0)
        self.assertEqual(self.sdo.read(0x6064, 0, '<i'), 123456)
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)

    def test_reset_communication_keeps_drive_state(self):
        self.make()
        self.sdo.write(0x6040, 0, 0x0006, '<H')
        self.sdo.write(0x6060, 0, 8, '<b')
        self.nmt(0x82)
        self.assertEqual(self.frames(HB)[-1][2], b'\x00')
        self.assertEqual(self.drive.state, peer.READY_TO_SWITCH_ON)
        self.assertEqual(self.sdo.read(0x6060, 0, '<b'), 8)


class Heartbeat(PeerCase):
    def test_producer_period_exact(self):
        self.make()
        self.link.clear()
        self.sdo.write(0x1017, 0, 100, '<H')
        t0 = self.link.now()
        self.link.advance(1.0)
        times = [round(t - t0, 9) for t, _, _ in self.frames(HB)]
        self.assertEqual(times, [round(0.1 * k, 9) for k in range(1, 11)])

    def test_default_from_option(self):
        self.make(heartbeat_ms=20)
        self.link.advance(0.1)
        self.assertEqual(len(self.frames(HB)) - 1, 5)   # boot-up + 5 heartbeats

    def test_no_1016_by_default(self):
        self.make()
        self.assertEqual(self.sdo.abort_code(self.sdo.upload, 0x1016, 0), peer.ABORT_NO_OBJECT)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1016, 1, 0x007F012C), peer.ABORT_NO_OBJECT)

    def test_1016_with_option(self):
        self.make(consumer_heartbeat=2)
        self.assertEqual(self.sdo.read(0x1016, 0, '<B'), 2)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1016, 0, 3, '<B'), peer.ABORT_READ_ONLY)
        self.sdo.write(0x1016, 1, 0x007F012C)               # node 127, 300 ms
        # CiA 301 0x1016: the same node-ID twice -> 0604 0043h
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1016, 2, 0x007F00C8), peer.ABORT_PARAM_INCOMPATIBLE)
        self.sdo.write(0x1016, 2, 0x007E00C8)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1016, 2, 0x017E00C8), peer.ABORT_VALUE)

    def test_consumer_loss(self):
        self.make(consumer_heartbeat=1)
        self.sdo.write(0x1016, 1, 0x007F0064)               # node 127, 100 ms
        self.csp()
        self.enable(0)
        self.link.advance(0.5)
        self.assertEqual(self.frames(EMCY), [], 'monitoring starts at the first heartbeat')
        self.link.send(0x77F, b'\x05')
        self.link.advance(0.099)
        self.assertEqual(self.frames(EMCY), [])
        self.link.advance(0.002)
        emcy = [d for _, _, d in self.frames(EMCY)]
        self.assertEqual(emcy, [bytes([0x30, 0x81, 0x11, 0, 0, 0, 0, 0])])   # 8130h, generic + communication
        self.assertIn(self.drive.state, (peer.FAULT_REACTION_ACTIVE, peer.FAULT))
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)               # 0x1029 default
        self.link.send(0x77F, b'\x05')                     # back; the fault stays until reset
        self.assertEqual(self.frames(EMCY), [])
        self.link.send(SYNC)
        for cw in (0x0000, 0x0080):
            self.sdo.write(0x6040, 0, cw, '<H')
        self.assertEqual([d for _, _, d in self.frames(EMCY)], [bytes(8)])
        self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)


class PdoRules(PeerCase):
    def test_fewer_pdos(self):
        self.make()
        for index in (0x1402, 0x1602, 0x1802, 0x1A02):
            self.assertEqual(self.sdo.abort_code(self.sdo.upload, index, 1), peer.ABORT_NO_OBJECT, hex(index))
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1802, 1, 0x80000385), peer.ABORT_NO_OBJECT)
        self.make(rpdos=4, tpdos=3)
        self.assertEqual(self.sdo.read(0x1403, 1), 0x80000505)
        self.assertEqual(self.sdo.read(0x1802, 1), 0xC0000385)
        self.assertEqual(self.sdo.abort_code(self.sdo.upload, 0x1803, 1), peer.ABORT_NO_OBJECT)

    def test_pdo_changes_refused_in_operational(self):
        self.make()
        self.nmt(0x01)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1800, 1, 0x80000000 | TPDO1), peer.ABORT_DEVICE_STATE)
        self.nmt(0x80)
        self.sdo.write(0x1800, 1, 0x80000000 | TPDO1)
        self.nmt(0x01)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1A00, 0, 0, '<B'), peer.ABORT_DEVICE_STATE)

    def test_unset_entry(self):
        self.make()
        self.sdo.write(0x1800, 1, 0x80000000 | TPDO1)
        self.sdo.write(0x1A00, 0, 0, '<B')
        self.sdo.write(0x1A00, 1, 0x60410010)
        self.sdo.write(0x1A00, 2, 0)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1A00, 0, 2, '<B'), peer.ABORT_PARAM_INCOMPATIBLE)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1A00, 0, 9, '<B'), peer.ABORT_PDO_LENGTH)

    def test_cob_id_rules(self):
        self.make()
        self.sdo.write(0x1801, 1, 0x80000000 | TPDO2)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1801, 1, 0x581), peer.ABORT_VALUE)     # restricted
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1801, 1, 0x20000285), peer.ABORT_VALUE)  # 29 bit
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1800, 3, 10, '<H'), peer.ABORT_VALUE)   # inhibit, valid
        self.sdo.write(0x1801, 3, 10, '<H')                                                          # invalid: ok
        self.assertEqual(self.sdo.abort_code(self.sdo.upload, 0x1800, 4), peer.ABORT_NO_SUB)

    def test_transmission_type_every_nth_sync(self):
        self.make()
        c = spec_checks.Ctx(self.link, NODE, PERIOD)
        c.remap(False, 1, [0x60410010], ttype=3)
        self.nmt(0x01)
        self.link.clear()
        got = []
        for k in range(1, 10):
            self.link.send(SYNC)
            got += [k] * len(self.frames(TPDO1))
        self.assertEqual(got, [3, 6, 9])

    def test_event_driven_tpdo_timer_and_inhibit(self):
        self.make()
        c = spec_checks.Ctx(self.link, NODE, PERIOD)
        c.remap(False, 2, [0x60410010], ttype=255)
        self.sdo.write(0x1801, 1, 0x80000000 | TPDO2)
        self.sdo.write(0x1801, 3, 500, '<H')                 # inhibit 50 ms
        self.sdo.write(0x1801, 5, 200, '<H')                 # event timer 200 ms
        self.sdo.write(0x1801, 1, TPDO2)
        self.nmt(0x01)
        t0 = self.link.now()
        self.assertEqual(len(self.frames(TPDO2)), 1)         # first: on NMT start
        self.sdo.write(0x6040, 0, 0x0006, '<H')              # change within the inhibit time
        self.assertEqual(self.frames(TPDO2), [])
        self.link.advance(0.05)
        (t, _, d), = self.frames(TPDO2)
        self.assertAlmostEqual(t - t0, 0.05, places=6)
        self.assertEqual(d, struct.pack('<H', 0x0231))
        self.link.advance(0.45)
        self.assertEqual([round(f[0] - t0, 6) for f in self.frames(TPDO2)], [0.25, 0.45])

class StateMachine(PeerCase):
    def test_fault_from_every_state_and_reset(self):
        # 13 from any state, 14 at the next SYNC, 15 on the 0->1 edge of bit 7.
        for cws in ((), (0x06,), (0x06, 0x07), (0x06, 0x0F), (0x06, 0x0F, 0x02)):
            self.make()
            self.sdo.write(0x605A, 0, 6, '<h')
            self.sdo.write(0x6060, 0, 8, '<b')
            for cw in cws:
                self.sdo.write(0x6040, 0, cw, '<H')
            before = self.drive.state
            self.link.send(0x000, bytes([0x01, NODE]))
            self.link.runner.command('fault 0x2310')
            self.assertEqual(self.drive.state, peer.FAULT_REACTION_ACTIVE, peer.STATE_NAMES[before])
            self.sdo.write(0x6040, 0, 0x0080, '<H')                 # ignored in fault reaction
            self.link.send(SYNC)
            self.assertEqual(self.drive.state, peer.FAULT)
            self.assertEqual(self.sdo.read(0x6041, 0, '<H') & 0x4F, 0x08)
            self.sdo.write(0x6040, 0, 0x0080, '<H')                 # bit 7 still 1: no edge
            self.assertEqual(self.drive.state, peer.FAULT)
            self.sdo.write(0x6040, 0, 0x0000, '<H')
            self.sdo.write(0x6040, 0, 0x0080, '<H')
            self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)
            self.assertEqual(self.drive.transitions[-3:], [13, 14, 15])

    def test_held_fault_refuses_reset_until_clear(self):
        self.make()
        self.link.runner.command('fault 0x4310 hold')
        self.link.send(SYNC)
        for cw in (0x0000, 0x0080):
            self.sdo.write(0x6040, 0, cw, '<H')
        self.assertEqual(self.drive.state, peer.FAULT)
        self.link.runner.command('clear')
        for cw in (0x0000, 0x0080):
            self.sdo.write(0x6040, 0, cw, '<H')
        self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)

    def test_no_transition_16_with_option_0_to_4(self):
        self.make()
        self.sdo.write(0x6060, 0, 8, '<b')
        for cw in (0x0006, 0x000F, 0x0002):
            self.sdo.write(0x6040, 0, cw, '<H')
        self.assertEqual(self.drive.state, peer.QUICK_STOP_ACTIVE)
        self.sdo.write(0x6040, 0, 0x000F, '<H')                     # 0x605A = 2: no way back
        self.assertEqual(self.drive.state, peer.QUICK_STOP_ACTIVE)
        self.link.send(SYNC)
        self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)
        self.assertEqual(self.drive.transitions[-2:], [11, 12])

    def test_bit7_blocks_commands(self):
        self.make()
        self.sdo.write(0x6040, 0, 0x0086, '<H')                     # shutdown + fault reset bit
        self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)
        self.sdo.write(0x6040, 0, 0x0006, '<H')
        self.assertEqual(self.drive.state, peer.READY_TO_SWITCH_ON)

    def test_statusword_bits(self):
        self.make()
        self.sdo.write(0x6060, 0, 8, '<b')
        got = []
        for cw in (0x0000, 0x0006, 0x0007, 0x000F, 0x0002):
            self.sdo.write(0x6040, 0, cw, '<H')
            got.append(self.sdo.read(0x6041, 0, '<H'))
        # SOD, RTSO, SO, OE + bit 12 (CSP follows), QSA: + voltage (4) and remote (9)
        self.assertEqual(got, [0x0250, 0x0231, 0x0233, 0x1237, 0x0217])


class Emcy(PeerCase):
    def test_emcy_bytes_and_registers(self):
        self.make()
        self.link.runner.command('fault 0x2310')
        self.assertEqual([d for _, _, d in self.frames(EMCY)], [bytes([0x10, 0x23, 0x03, 0, 0, 0, 0, 0])])
        self.assertEqual(self.sdo.read(0x603F, 0, '<H'), 0x2310)
        self.assertEqual(self.sdo.read(0x1001, 0, '<B'), 0x03)      # generic + current
        self.link.send(SYNC)
        for cw in (0x0000, 0x0080):
            self.sdo.write(0x6040, 0, cw, '<H')
        self.assertEqual([d for _, _, d in self.frames(EMCY)], [bytes(8)])   # 0000h, register 0
        self.assertEqual(self.sdo.read(0x603F, 0, '<H'), 0)
        self.assertEqual(self.sdo.read(0x1001, 0, '<B'), 0)

    def test_default_code_is_manufacturer_specific(self):
        self.make()
        self.link.runner.command('fault')
        self.assertEqual(self.frames(EMCY)[0][2][:3], bytes([0x00, 0xFF, 0x81]))

    def test_no_emcy_when_stopped_or_invalid(self):
        self.make()
        self.nmt(0x02)
        self.link.runner.command('fault')
        self.assertEqual(self.frames(EMCY), [])
        self.make()
        self.sdo.write(0x1014, 0, 0x80000000 | EMCY)
        self.link.runner.command('fault')
        self.assertEqual(self.frames(EMCY), [])
        self.assertIsNone(self.sdo.abort_code(self.sdo.write, 0x1014, 0, 0x90))
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x1014, 0, 0x91), peer.ABORT_VALUE)


class Csp(PeerCase):
    def test_enable_at_start_position_without_jump(self):
        self.make(position=123456)
        self.csp()
        self.link.clear()
        self.enable(123456)
        positions = [struct.unpack('<Hi', d)[1] for _, _, d in self.sync(5)]
        self.assertEqual(set(positions), {123456})
        self.assertEqual(self.drive.enable_log, [(123456, 123456)])
        self.assertEqual(self.drive.max_step, 0)

    def test_enable_with_a_stale_target_jumps(self):
        # What a master that forgets 0x607A := 0x6064 gets: the peer obeys.
        self.make(position=123456)
        self.csp()
        self.enable(0)
        positions = [struct.unpack('<Hi', d)[1] for _, _, d in self.sync(2)]
        self.assertEqual(positions[-1], 0)
        self.assertEqual(self.drive.max_step, 123456)

    def test_target_taken_at_sync_reported_at_next(self):
        self.make()
        self.csp()
        self.enable(0)
        seen = []
        for k in range(1, 6):
            self.rpdo(0x000F, 100 * k)
            self.assertEqual(self.drive.target, 0 if k == 1 else 100 * (k - 1), 'RPDO applied before SYNC')
            seen += [struct.unpack('<Hi', d)[1] for _, _, d in self.sync()]
        self.assertEqual(seen, [0, 100, 200, 300, 400])

    def test_velocity_uses_60c2(self):
        self.make()
        self.sdo.write(0x60C2, 1, 4, '<B')
        self.sdo.write(0x60C2, 2, -3, '<b')
        self.csp()
        self.enable(0)
        for k in range(1, 4):
            self.rpdo(0x000F, 40 * k)
            self.sync()
        self.assertEqual(self.sdo.read(0x606C, 0, '<i'), 10000)      # 40 counts per 4 ms

    def test_no_motion_unless_enabled_in_csp(self):
        self.make(position=7)
        self.csp()
        self.sdo.write(0x6060, 0, 0, '<b')
        self.enable(1000)
        self.sync(3)
        self.assertEqual(self.drive.actual, 7, 'mode 0: no motion')
        self.sdo.write(0x6060, 0, 8, '<b')
        self.rpdo(0x0006, 2000)
        self.sync(3)
        self.assertEqual(self.drive.actual, 7, 'ready to switch on: no motion')

    def test_quick_stop_holds_position(self):
        self.make()
        self.csp()
        self.enable(0)
        self.rpdo(0x000F, 500)
        self.sync(2)
        self.rpdo(0x0002, 900)
        sw = [struct.unpack('<Hi', d) for _, _, d in self.sync(3)]
        self.assertEqual([peer.STATE_BITS[peer.QUICK_STOP_ACTIVE], 0x0040], [sw[1][0] & 0x6F, sw[2][0] & 0x4F])
        self.assertEqual(self.drive.actual, 500)


class InterpolatedPosition(PeerCase):
    """Mode 7 (--modes ip): 0x60C1:1 in RPDO1, controlword bit 4 "enable ip
    mode", statusword bit 12 "ip mode active", 0x60C0 = 0 linear only."""

    def ip(self, position=0, modes='ip'):
        self.make(position=position, modes=modes)
        c = spec_checks.Ctx(self.link, NODE, PERIOD)
        c.remap(True, 1, [0x60400010, 0x60C10120])
        c.remap(False, 1, [0x60410010, 0x60640020])
        self.sdo.write(0x6060, 0, 7, '<b')
        self.sdo.write(0x60C0, 0, 0, '<h')
        self.nmt(0x01)
        self.link.clear()

    def test_ip_only_drive_objects_and_modes(self):
        self.make(modes='ip')
        self.assertEqual(self.sdo.read(0x6502), (1 << 6))              # IP only: no CSP bit
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x6060, 0, 8, '<b'), peer.ABORT_VALUE)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x60C0, 0, -1, '<h'), peer.ABORT_VALUE)
        self.assertEqual(self.sdo.read(0x60C1, 0, '<B'), 1)
        self.make(modes='csp')
        self.assertEqual(self.sdo.read(0x6502), (1 << 7))
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x6060, 0, 7, '<b'), peer.ABORT_VALUE)
        self.assertEqual(self.sdo.abort_code(self.sdo.read, 0x60C1, 1), 0x06020000)
        self.make(modes='csp,ip')
        self.assertEqual(self.sdo.read(0x6502), (1 << 6) | (1 << 7))
        with self.assertRaises(ValueError):
            peer.Drive(NODE, modes='pp')

    def test_set_points_taken_only_with_bit_4(self):
        self.ip(position=1000)
        self.enable(1000)                                    # 0x000F: Operation enabled, bit 4 clear
        sw = [struct.unpack('<Hi', d)[0] for _, _, d in self.sync(2)]
        self.assertEqual(sw[-1] & peer.SW_IP_ACTIVE, 0)
        self.rpdo(0x000F, 5000)                              # ignored without bit 4
        self.sync(2)
        self.assertEqual(self.drive.actual, 1000)
        self.rpdo(0x001F, 1000)                              # enable ip mode at the present position
        self.sync(1)
        last = None
        for target in range(1100, 2100, 100):                # a ramp of 100 counts per period
            self.rpdo(0x001F, target)
            got = self.sync(1)
            if got:
                last = struct.unpack('<Hi', got[-1][2])
        self.sync(2)
        self.assertEqual(self.drive.actual, 2000)
        self.assertNotEqual(last[0] & peer.SW_IP_ACTIVE, 0)
        self.assertEqual(self.drive.max_step, 100)           # linear: no jump at the start
        self.rpdo(0x000F, 9999)                              # bit 4 cleared: held where it is
        self.sync(3)
        self.assertEqual(self.drive.actual, 2000)
        self.assertEqual(self.drive.statusword() & peer.SW_IP_ACTIVE, 0)


class ControlAndCli(PeerCase):
    def test_silence_and_resume(self):
        self.make(heartbeat_ms=10)
        self.link.runner.command('silence')
        self.link.advance(0.1)
        self.assertEqual(self.frames(HB)[1:], [])
        self.link.runner.command('resume')
        self.link.advance(0.1)
        self.assertGreaterEqual(len(self.frames(HB)), 9)

    def test_local_nmt_and_reset(self):
        self.make(heartbeat_ms=10)
        self.nmt(0x01)
        self.link.runner.command('nmt preop')
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)
        self.link.runner.command('reset')
        self.assertEqual(self.frames(HB)[-1][2], b'\x00')

    def test_power_off_and_on(self):
        # Power off: nothing in or out, no heartbeat, SDO unanswered, NMT
        # ignored; power on: the boot-up (one byte 00h), pre-operational,
        # every default again (0x1017 back to --heartbeat-ms), position kept.
        self.make(heartbeat_ms=10, position=777)
        self.sdo.write(0x1017, 0, 20, '<H')
        self.nmt(0x01)
        self.link.runner.command('power off')
        self.frames(HB)
        self.link.advance(0.1)
        self.nmt(0x81)
        self.link.send(0x600 + NODE, struct.pack('<BHB4x', 0x40, 0x1000, 0))
        self.link.advance(0.05)
        self.assertEqual(self.frames(HB), [])
        self.assertEqual(self.frames(0x580 + NODE), [])
        self.link.runner.command('power on')
        self.assertEqual([f[2] for f in self.frames(HB)], [b'\x00'])
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)
        self.assertEqual(self.sdo.read(0x1017, 0, '<H'), 10)
        self.assertEqual(self.sdo.read(0x6064, 0, '<i'), 777)
        self.link.advance(0.1)
        self.assertEqual({f[2] for f in self.frames(HB)}, {b'\x7f'})
        self.link.runner.command('power on')          # already on: nothing
        self.assertEqual(self.frames(HB), [])

    def test_power_cycle_while_following(self):
        # A power cycle while following set-points in CSP (vcan.peer.power_cycle):
        # the drive comes back where the motor stopped, in Switch on disabled
        # and pre-operational, with nothing enabled and nothing followed until
        # a master configures and enables it again.
        self.make(heartbeat_ms=10, position=1000)
        self.csp()
        for cw in (0x06, 0x07, 0x0F):
            self.link.send(RPDO1, struct.pack('<Hi', cw, 1000))
            self.sync()
        for k in range(1, 6):
            self.link.send(RPDO1, struct.pack('<Hi', 0x0F, 1000 + 50 * k))
            self.sync()
        self.assertEqual(self.drive.actual, 1200)       # each set-point reached at the next SYNC
        self.frames(HB)
        self.link.runner.command('power off')
        self.link.send(RPDO1, struct.pack('<Hi', 0x0F, 9999))   # not heard: no supply
        self.sync(3)
        self.link.runner.command('power on')
        self.assertEqual([f[2] for f in self.frames(HB)], [b'\x00'])
        self.assertEqual(self.drive.nmt, peer.PREOPERATIONAL)
        self.assertEqual(self.drive.state, peer.SWITCH_ON_DISABLED)
        self.assertEqual(self.sdo.read(0x6064, 0, '<i'), 1200)   # where it stood at power off (1250 not reached)
        self.assertEqual(self.sdo.read(0x6060, 0, '<b'), 0)      # every default: no mode until written

    def test_interface_down_is_survived(self):
        # `ip link set vcan0 down` while running (vcan.peer.link_down): every
        # recv and send fails with ENETDOWN; the peer logs it once, loses
        # those frames (no retry loop), keeps its timers, and works again
        # when the interface is back.
        import can
        import errno as errno_

        class Cut:
            def __init__(self, bus):
                self.bus, self.down = bus, False

            def _check(self, what):
                if self.down:
                    raise can.CanOperationError(f'Failed to {what}: Network is down', errno_.ENETDOWN)

            def recv(self, timeout=None):
                self._check('receive')
                return self.bus.recv(timeout=timeout)

            def send(self, msg, timeout=None):
                self._check('transmit')
                self.bus.send(msg, timeout)

        logs = []
        self.make(heartbeat_ms=10)
        self.drive.log = logs.append
        cut = Cut(self.link.runner.bus)
        self.link.runner.bus = cut
        self.frames(HB)
        cut.down = True
        import contextlib
        import io
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.link.advance(0.1)                      # ten heartbeats due, all refused
            self.link.send(0x600 + NODE, struct.pack('<BHB4x', 0x40, 0x1000, 0))   # not received either
        self.assertEqual(self.frames(HB), [])
        self.assertEqual(self.frames(0x580 + NODE), [])
        failed = [m for m in logs if m.startswith('bus:')]
        self.assertEqual(len(failed), 1, failed)              # once, not per frame
        self.assertIn('Network is down', failed[0])
        self.assertEqual(err.getvalue().count('Network is down'), 1)
        cut.down = False
        self.link.advance(0.05)
        self.assertGreaterEqual(len(self.frames(HB)), 4)
        self.assertIn('bus: frames flow again', logs)
        self.assertEqual(self.sdo.read(0x1000, 0, '<I'), 0x00020192)

    def test_bad_command(self):
        import contextlib
        import io
        self.make()
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.link.runner.command('fault xyz')
            self.link.runner.command('explode')
        self.assertIn("'fault xyz'", err.getvalue())
        self.assertIn("'explode': unknown command", err.getvalue())

    def run_cli(self, *args):
        return subprocess.run([sys.executable, os.path.join(HERE, 'cia402_peer.py'), *args],
                              capture_output=True, text=True, timeout=60)

    def test_help(self):
        r = self.run_cli('--help')
        self.assertEqual(r.returncode, 0)
        for word in ('--control', '--position', '--consumer-heartbeat', '--powered-off', 'fault [CODE] [hold]',
                     'power off|on', 'Exit status'):
            self.assertIn(word, r.stdout)

    def test_bad_arguments(self):
        r = self.run_cli('-i', 'vcan0', '-n', '0')
        self.assertEqual(r.returncode, 2)
        self.assertIn('--node 0: a node-ID is 1..127', r.stderr)
        r = self.run_cli('-i', 'vcan0', '-n', '5', '--rpdos', '9')
        self.assertEqual(r.returncode, 2)

    def test_powered_off_run(self):
        # --powered-off: the program runs, but the drive sends nothing (no boot-up) until `power on`.
        r = self.run_cli('-i', 'peer-cli-test-off', '--bus-type', 'virtual', '-n', '5', '--heartbeat-ms', '10',
                         '--powered-off', '--duration', '0.2', '-v')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn('powered off: no frames in or out', r.stdout)
        self.assertIn(', powered off', r.stdout)
        self.assertNotIn('boot-up, NMT pre-operational', r.stdout)   # never booted (the summary says NMT boot-up)

    def test_virtual_bus_run(self):
        # The whole program on python-can's virtual bus: boot-up, then exit at --duration.
        r = self.run_cli('-i', 'peer-cli-test', '--bus-type', 'virtual', '-n', '5', '--duration', '0.2', '-v')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn('boot-up, NMT pre-operational', r.stdout)
        self.assertIn('0 SYNC;', r.stdout)


if __name__ == '__main__':
    unittest.main()


class DriveUnits(PeerCase):
    """--velocity-unit / --encoder-increments (issue 29, README "Drive units"):
    0x60A9 and 0x608F shown, CSV (0x60FF) and homing speeds (0x6099) taken in
    the unit, 0x606C reported in it. rpm: 4096 increments per revolution, so
    900 rpm = 61440 counts/s."""
    RPDO2, TPDO2_ = 0x300 + NODE, 0x280 + NODE

    def setup_units(self, unit, increments=4096, period=0.01):
        self.make(velocity_unit=unit, encoder_increments=increments)
        c = spec_checks.Ctx(self.link, NODE, period)
        c.csp_pdos()
        c.remap(True, 2, [0x60FF0020, 0x60710010, 0x60600008])
        c.remap(False, 2, [0x606C0020, 0x60770010, 0x60610008])
        self.sdo.write(0x60C2, 1, int(period * 1000), '<B')
        self.sdo.write(0x60C2, 2, -3, '<b')
        self.nmt(0x01)
        self.period = period
        return c

    def step(self, n=1):
        for _ in range(n):
            self.link.send(SYNC)
            self.link.advance(self.period)
        self.link.poll()
        self.link.queue = []

    def enable_in(self, mode, velocity=0, cw_extra=0):
        for cw in (0x0006, 0x0007, 0x000F):
            self.link.send(RPDO1, struct.pack('<Hi', cw, self.drive.actual))
            self.link.send(self.RPDO2, struct.pack('<ihb', velocity, 0, mode))
            self.step()
        self.assertEqual(self.drive.state, peer.OPERATION_ENABLED)

    def test_objects_shown(self):
        self.make(velocity_unit='rpm', encoder_increments=4096)
        self.assertEqual(self.sdo.read(0x60A9), 0x00B44700)
        self.assertEqual(self.sdo.read(0x608F, 1), 4096)
        self.assertEqual(self.sdo.read(0x608F, 2), 1)
        self.assertEqual(self.sdo.read(0x6502) & (1 << 8 | 1 << 5), 1 << 8 | 1 << 5)
        self.link.close()
        self.make(velocity_unit='inc/s')
        self.assertEqual(self.sdo.read(0x60A9), 0x00B50300)
        self.link.close()
        self.make()   # without the option: CSP only, no 0x60A9, CSV refused
        self.assertEqual(self.sdo.abort_code(self.sdo.read, 0x60A9), peer.ABORT_NO_OBJECT)
        self.assertEqual(self.sdo.abort_code(self.sdo.write, 0x6060, 0, 9, '<b'), peer.ABORT_VALUE)
        with self.assertRaises(ValueError):
            peer.Drive(NODE, velocity_unit='rpm')   # rpm without increments per revolution

    def test_csv_in_rpm_and_inc_per_s_same_shaft_speed(self):
        moved = {}
        for unit, v in (('rpm', 900), ('inc/s', 61440)):
            self.setup_units(unit)
            self.enable_in(9, v)
            for _ in range(10):
                self.link.send(self.RPDO2, struct.pack('<ihb', v, 0, 9))
                self.step()
            p0 = self.drive.actual
            for _ in range(100):               # 1 s
                self.link.send(self.RPDO2, struct.pack('<ihb', v, 0, 9))
                self.step()
            moved[unit] = self.drive.actual - p0
            self.assertEqual(self.sdo.read(0x606C, 0, '<i'), v, unit)   # 0x606C in the drive's unit
            self.link.close()
        self.assertEqual(moved['rpm'], moved['inc/s'])
        self.assertAlmostEqual(moved['rpm'], 61440, delta=1)   # 1 s at 61440 counts/s (sub-count remainder)

    def test_homing_speed_in_rpm(self):
        self.setup_units('rpm')
        self.drive.actual = 20480
        self.sdo.write(0x6098, 0, 19, '<b')
        self.sdo.write(0x6099, 1, 300)         # 300 rpm = 20480 counts/s
        self.sdo.write(0x6099, 2, 60)
        self.enable_in(6)
        self.link.send(RPDO1, struct.pack('<Hi', 0x001F, self.drive.actual))   # bit 4: start
        self.step(51)                          # the RPDO takes effect at the next SYNC, then 0.5 s: half way
        self.assertAlmostEqual(self.drive.actual, 10240, delta=1)
        self.assertEqual(self.sdo.read(0x606C, 0, '<i'), -300)
        self.step(51)
        self.assertEqual(self.drive.actual, 0)
        sw = self.sdo.read(0x6041, 0, '<H')
        self.assertEqual(sw & (1 << 12 | 1 << 10), 1 << 12 | 1 << 10, f'statusword 0x{sw:04X}')
