"""Test-side CANopen tooling for tests/peers: a link to one device and an
SDO client, written from CiA 301 (independent of fieldbus/ and of the peer).

Two links with the same interface:
  VirtualLink  the peer (cia402_peer.Drive) in-process on python-can's
               `virtual` interface, on a virtual clock: advance() steps the
               peer's timers exactly, nothing sleeps;
  SocketLink   any device on a SocketCAN interface (the peer or cia402-emu
               as a separate process), in real time.
"""

from __future__ import annotations

import itertools
import struct
import time

SDO_RX_BASE, SDO_TX_BASE, HEARTBEAT_BASE, EMCY_BASE = 0x600, 0x580, 0x700, 0x080


class SdoAbort(Exception):
    def __init__(self, index, sub, code):
        super().__init__(f'SDO abort 0x{index:04X}:{sub:02X}: 0x{code:08X}')
        self.index, self.sub, self.code = index, sub, code


class Link:
    """Frames to and from one bus, with the time they arrived."""

    def __init__(self):
        self.queue = []      # (t, can_id, data) received and not yet consumed
        self.log = []        # everything received

    def _got(self, t, can_id, data):
        self.queue.append((t, can_id, bytes(data)))
        self.log.append((t, can_id, bytes(data)))

    def clear(self):
        self.poll()
        self.queue.clear()

    def wait_for(self, pred, timeout=1.0):
        """The first queued or arriving frame with pred(can_id, data), or None
        after `timeout` seconds (of the link's clock). Only that frame is
        taken from the queue."""
        t_end = self.now() + timeout
        while True:
            self.poll()
            for k, frame in enumerate(self.queue):
                if pred(frame[1], frame[2]):
                    del self.queue[k]
                    return frame
            if self.now() >= t_end:
                return None
            self.step(t_end)


class VirtualLink(Link):
    """The peer in-process on python-can's virtual bus and a virtual clock."""

    _channels = itertools.count()

    def __init__(self, drive, t0=100.0):
        super().__init__()
        import can
        import cia402_peer
        channel = f'peer-test-{next(self._channels)}'
        self.bus = can.Bus(interface='virtual', channel=channel)
        self.peer_bus = can.Bus(interface='virtual', channel=channel)
        self.t = t0
        self.drive = drive
        self.runner = cia402_peer.Runner(drive, self.peer_bus, clock=lambda: self.t)
        self.runner.start(self.t)
        self.poll()

    def now(self):
        return self.t

    def send(self, can_id, data=b''):
        import can
        self.bus.send(can.Message(arbitration_id=can_id, data=bytes(data), is_extended_id=False))
        self.runner.pump(self.t)
        self.poll()

    def poll(self):
        while True:
            msg = self.bus.recv(timeout=0)
            if msg is None:
                return
            self._got(self.t, msg.arbitration_id, msg.data)

    def step(self, t_end):
        """Advance to the peer's next timer, or to t_end."""
        deadline = self.runner.next_deadline()
        if deadline is not None and deadline <= self.t and deadline == getattr(self, '_stuck', None):
            raise AssertionError(f'peer timer at {deadline} does not fire at {self.t}')
        self._stuck = deadline if deadline is not None and deadline <= self.t else None
        self.t = t_end if deadline is None or deadline > t_end else max(self.t, deadline)
        self.runner.pump(self.t)
        self.poll()

    def advance(self, dt):
        t_end = self.t + dt
        while self.t < t_end:
            self.step(t_end)

    def close(self):
        self.bus.shutdown()
        self.peer_bus.shutdown()


class SocketLink(Link):
    """A device on a SocketCAN interface, in real time. Waits run on
    time.monotonic(); a frame's time is its kernel receive stamp
    (CLOCK_REALTIME), used only for intervals between frames."""

    def __init__(self, channel):
        super().__init__()
        import can
        self.bus = can.Bus(interface='socketcan', channel=channel)

    def now(self):
        return time.monotonic()

    def send(self, can_id, data=b''):
        import can
        self.bus.send(can.Message(arbitration_id=can_id, data=bytes(data), is_extended_id=False))

    def poll(self):
        while True:
            msg = self.bus.recv(timeout=0)
            if msg is None:
                return
            if not (msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id):
                self._got(msg.timestamp, msg.arbitration_id, msg.data)

    def step(self, t_end):
        msg = self.bus.recv(timeout=max(0.0, min(0.01, t_end - time.monotonic())))
        if msg is not None and not (msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id):
            self._got(msg.timestamp, msg.arbitration_id, msg.data)

    def advance(self, dt):
        t_end = time.monotonic() + dt
        while time.monotonic() < t_end:
            self.step(t_end)

    def close(self):
        self.bus.shutdown()


class SdoClient:
    """An SDO client (CiA 301 7.2.4): expedited and segmented, both ways."""

    def __init__(self, link: Link, node: int, timeout=0.5):
        self.link, self.node, self.timeout = link, node, timeout

    def request(self, data: bytes) -> bytes:
        """Send one 8-byte request; the server's 8-byte response."""
        self.link.send(SDO_RX_BASE + self.node, bytes(data).ljust(8, b'\x00'))
        frame = self.link.wait_for(lambda i, d: i == SDO_TX_BASE + self.node, self.timeout)
        if frame is None:
            raise TimeoutError(f'node {self.node}: no SDO response to {bytes(data).hex()}')
        return frame[2]

    @staticmethod
    def _check(resp: bytes, index, sub):
        if resp[0] == 0x80:
            raise SdoAbort(*struct.unpack_from('<HBI', resp, 1))

    def upload(self, index: int, sub: int = 0) -> bytes:
        resp = self.request(struct.pack('<BHB', 0x40, index, sub))
        self._check(resp, index, sub)
        if resp[0] >> 5 != 2 or struct.unpack_from('<HB', resp, 1) != (index, sub):
            raise AssertionError(f'bad initiate upload response {resp.hex()}')
        if resp[0] & 0x02:                         # expedited
            n = (resp[0] >> 2) & 0x03 if resp[0] & 0x01 else 0
            return resp[4:8 - n]
        size = struct.unpack_from('<I', resp, 4)[0] if resp[0] & 0x01 else None
        data, toggle = b'', 0
        while True:
            resp = self.request(bytes([0x60 | toggle << 4]))
            self._check(resp, index, sub)
            if resp[0] >> 5 != 0 or (resp[0] >> 4) & 1 != toggle:
                raise AssertionError(f'bad upload segment {resp.hex()} (toggle {toggle})')
            n = (resp[0] >> 1) & 0x07
            data += resp[1:8 - n]
            if resp[0] & 0x01:
                break
            toggle ^= 1
        if size is not None and len(data) != size:
            raise AssertionError(f'segmented upload: {len(data)} bytes, size indicated {size}')
        return data

    def download(self, index: int, sub: int, data: bytes, segmented=False):
        data = bytes(data)
        if not segmented and 1 <= len(data) <= 4:
            resp = self.request(struct.pack('<BHB', 0x23 | (4 - len(data)) << 2, index, sub) + data)
            self._check(resp, index, sub)
            if resp[0] != 0x60:
                raise AssertionError(f'bad initiate download response {resp.hex()}')
            return
        resp = self.request(struct.pack('<BHBI', 0x21, index, sub, len(data)))
        self._check(resp, index, sub)
        if resp[0] != 0x60:
            raise AssertionError(f'bad initiate download response {resp.hex()}')
        toggle, pos = 0, 0
        while True:
            chunk = data[pos:pos + 7]
            pos += len(chunk)
            last = pos >= len(data)
            resp = self.request(bytes([toggle << 4 | (7 - len(chunk)) << 1 | int(last)]) + chunk)
            self._check(resp, index, sub)
            if resp[0] != 0x20 | toggle << 4:
                raise AssertionError(f'bad download segment response {resp.hex()} (toggle {toggle})')
            if last:
                return
            toggle ^= 1

    # typed helpers
    def read(self, index, sub=0, fmt='<I'):
        return struct.unpack(fmt, self.upload(index, sub))[0]

    def write(self, index, sub, value, fmt='<I', segmented=False):
        self.download(index, sub, struct.pack(fmt, value), segmented)

    def abort_code(self, fn, *args, **kw):
        """The abort code fn(*args) ends with (None if it succeeds)."""
        try:
            fn(*args, **kw)
        except SdoAbort as e:
            return e.code
        return None
