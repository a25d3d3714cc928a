#!/usr/bin/python3
"""conformance.py: run the CiA 301 / CiA 402 checks of spec_checks.py
against one drive on a SocketCAN interface (the peer, cia402-emu, or a real
drive). Each check resets the node first (NMT reset node) and names the
clause it comes from. Where the specification allows several answers, the
check accepts all of them and reports the one it saw.

Exit status: 0 when no check failed, 1 otherwise, 2 on bad arguments.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import spec_checks  # noqa: E402
from link import SocketLink  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog='conformance.py',
        description='CiA 301/402 conformance checks against one drive on SocketCAN.',
        epilog='Example: /usr/bin/python3 tests/peers/conformance.py -i vcan0 -n 5\n'
               'Checks: ' + ', '.join(n for n, _, _ in spec_checks.CHECKS),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('-i', '--interface', required=True, help='SocketCAN interface (vcan0)')
    ap.add_argument('-n', '--node', type=int, required=True, help='node-ID of the drive, 1..127')
    ap.add_argument('--period-ms', type=float, default=10.0, help='pause after each SYNC, ms (default 10)')
    ap.add_argument('--only', nargs='+', metavar='CHECK', help='run only these checks')
    ap.add_argument('--list', action='store_true', help='list the checks and exit')
    a = ap.parse_args(argv)
    if a.list:
        for name, clause, _ in spec_checks.CHECKS:
            print(f'{name}: {clause}')
        return 0
    if not 1 <= a.node <= 127:
        ap.error('--node is 1..127')
    unknown = set(a.only or []) - {n for n, _, _ in spec_checks.CHECKS}
    if unknown:
        ap.error(f'unknown check(s): {", ".join(sorted(unknown))} (see --list)')
    link = SocketLink(a.interface)
    try:
        results = spec_checks.run(lambda: spec_checks.Ctx(link, a.node, a.period_ms / 1000.0), a.only,
                                  out=lambda s: print(s, flush=True))
    finally:
        link.close()
    counts = {r: sum(1 for x in results if x[2] == r) for r in ('PASS', 'FAIL', 'SKIP')}
    print(f"conformance: node {a.node} on {a.interface}: {counts['PASS']} passed, {counts['FAIL']} failed, "
          f"{counts['SKIP']} skipped")
    return 1 if counts['FAIL'] else 0


if __name__ == '__main__':
    sys.exit(main())
