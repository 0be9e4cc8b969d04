#!/usr/bin/env python3
"""The differential soak (tests/sim/soak.py) from the command line:

    python3 tools/soak.py --requests 100000 --seed 8

Seeded random requests, pipelined within the flow rule (docs/protocol.md),
against a simulated M32-D gateway with an EEPROM at A0 and an M128-S slave
at 0x10; every reply compared with the reference model
(tests/sim/spec_model.py).
Prints the figures at the end; exits 1 at the first difference (with the
seed, the request's index, the request, expected and got)."""

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "host"), str(ROOT / "tests" / "sim")]

from soak import SoakFailure, run_soak  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--requests", type=int, default=100000)
    ap.add_argument("--seed", type=int, default=8)
    ap.add_argument("--no-long-blank", action="store_true",
                    help="no lines of 129 or more spaces (empty: no reply)")
    args = ap.parse_args()
    try:
        fig = run_soak(args.requests, args.seed, long_blank=not args.no_long_blank,
                       log=lambda s: print(s, flush=True))
    except SoakFailure as e:
        print(e, flush=True)
        return 1
    print("soak: seed %d passed" % args.seed)
    print(fig.report())
    return 0


if __name__ == "__main__":
    sys.exit(main())
