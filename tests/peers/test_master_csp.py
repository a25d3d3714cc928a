"""Unit tests of master_csp.py (the independent CSP master) against the
independent peer drive on python-can's virtual bus and a virtual clock
(link.VirtualLink): no AF_CAN, no sleeping. Part of ctest `peers.unit`.

The master must pass against a drive that follows the CiA 402 tables (the
peer), and fail at the step that matters against drives that do not: one
whose 0x6061 shows a new mode only at SYNCs (as cia402-emu --eds did before
issue 26 item 3), one that takes a mode outside its 0x6502, one that does not
follow the CSP targets.
"""

import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import cia402_peer as peer  # noqa: E402
import master_csp  # noqa: E402
from link import VirtualLink  # noqa: E402

NODE = 5
MOVE = dict(distance=20000, move_cycles=100, hold_cycles=10, tolerance=2000)


class TapLink(VirtualLink):
    """VirtualLink that also keeps the wire in order (what the master sent and
    what it received), as candump would: `wire` is [(can_id, data)]."""

    def __init__(self, drive):
        self.wire = []
        super().__init__(drive)

    def send(self, can_id, data=b''):
        self.wire.append((can_id, bytes(data)))
        super().send(can_id, data)

    def _got(self, t, can_id, data):
        self.wire.append((can_id, bytes(data)))
        super()._got(t, can_id, data)


class ModeShownAtSyncOnly(peer.Drive):
    """0x6061 shows a new 0x6060 only at the next SYNC (the old strict emulator)."""

    def _build_od(self):
        super()._build_od()
        self.shown_mode = getattr(self, 'shown_mode', peer.MODE_NONE)
        self.od.entries[(0x6061, 0)]._get = lambda: self.shown_mode

    def _on_sync(self, now):
        self.shown_mode = self.mode
        return super()._on_sync(now)


class TakesAnyMode(peer.Drive):
    """0x6060 takes every value, whatever 0x6502 says."""

    def _build_od(self):
        super()._build_od()
        self.od.entries[(0x6060, 0)].check = lambda v: 0


class DoesNotMove(peer.Drive):
    """Enables, but the position never follows 0x607A."""

    def _on_sync(self, now):
        out = super()._on_sync(now)
        self.demand = self.actual
        return out


class MasterCsp(unittest.TestCase):
    def run_master(self, drive):
        link = TapLink(drive)
        self.addCleanup(link.close)
        lines = []
        ok = master_csp.CspMaster(link, NODE, period=0.004).run(**MOVE, out=lines.append)
        return ok, lines, link

    def test_passes_against_the_peer_and_its_trace_checks(self):
        ok, lines, link = self.run_master(peer.Drive(NODE, position=1000))
        self.assertTrue(ok, '\n'.join(lines))
        self.assertEqual([line.split(':')[0] for line in lines],
                         ['PASS boot', 'PASS mode', 'PASS pdos', 'PASS start', 'PASS enable', 'PASS move', 'PASS end'])
        self.assertEqual(link.drive.actual, 1000 + MOVE['distance'])
        results = master_csp.check_trace(link.wire, NODE, MOVE['distance'])
        self.assertTrue(all(ok for ok, _ in results), results)
        # The trace check sees a wrong distance.
        self.assertFalse(all(ok for ok, _ in master_csp.check_trace(link.wire, NODE, MOVE['distance'] + 5)))

    def test_fails_when_0x6061_follows_only_at_sync(self):
        ok, lines, _ = self.run_master(ModeShownAtSyncOnly(NODE))
        self.assertFalse(ok)
        self.assertTrue(lines[-1].startswith('FAIL mode: 0x6060 = 8 written in pre-operational, 0x6061 still shows 0'),
                        lines[-1])

    def test_fails_when_a_mode_outside_0x6502_is_taken(self):
        ok, lines, _ = self.run_master(TakesAnyMode(NODE))
        self.assertFalse(ok)
        self.assertIn('0x6060 = 9 (CSV, not in 0x6502 = 0x00000080): accepted', lines[-1])

    def test_fails_when_the_drive_does_not_follow(self):
        ok, lines, _ = self.run_master(DoesNotMove(NODE))
        self.assertFalse(ok)
        self.assertTrue(lines[-1].startswith('FAIL move: cycle'), lines[-1])

    def test_trace_check_reads_candump_lines(self):
        path = os.path.join(os.environ.get('TMPDIR', '/tmp'), f'master_csp_test_{os.getpid()}.log')
        self.addCleanup(lambda: os.path.exists(path) and os.remove(path))
        with open(path, 'w') as f:
            f.write('(1700000000.000100) vcan0 000#8105\n(1700000000.000200) vcan0 705#00\n'
                    '(1700000000.000300) vcan0 080#\n(1700000000.000400) vcan0 085#1086110000000000\n')
        frames = master_csp.read_trace(path)
        self.assertEqual(frames[0], (0x000, b'\x81\x05'))
        self.assertEqual(frames[2], (0x080, b''))
        results = dict((text.split(' (')[0], ok) for ok, text in master_csp.check_trace(frames, NODE, 0))
        self.assertTrue(results['boot-up 705#00 after NMT reset node'])
        self.assertFalse(results['0x6061 read as 8 after that write, before the first SYNC'])
        self.assertFalse(results['no EMCY 085#'])


if __name__ == '__main__':
    unittest.main()
