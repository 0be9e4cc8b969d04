"""The driver commands: drivers, servo, motor, adc, gpio, spi, status; each
on the gateway itself or, with --addr, on a slave board."""

from __future__ import annotations

from .common import address, connect, show_address, table
from .names import board_of, driver_name


def target(args):
    """The 8-bit address of --addr, None for the gateway itself."""
    return None if args.addr is None else address(args, args.addr, "--addr")


def registers(record) -> str:
    first, last = record.start, record.start + record.count - 1
    return "0x%02X" % first if record.count == 1 else "0x%02X-0x%02X" % (first, last)


def cmd_drivers(args) -> int:
    addr = target(args)
    with connect(args) as gw:
        records = gw.drivers(addr)
        where = show_address(args, gw.local if addr is None else addr)
    rows = [["%04X" % r.uid, driver_name(r.uid), "%d.%d" % (r.major, r.minor), registers(r)]
            for r in records]
    print("%s: %s, %d drivers" % (where, board_of(records), len(records)))
    print(table(rows, ["UID", "driver", "version", "registers"]))
    return 0


def add_parsers(sub, common) -> None:
    cmd = sub.add_parser(
        "drivers", parents=[common], help="the drivers a board reports (introspection)",
        description="List the drivers of the gateway (or of the slave at --addr): UID,"
                    " name, version and the registers each one maps.",
        epilog="example: orfa --sim m32d drivers; orfa --port PORT drivers --addr 0x10")
    cmd.set_defaults(func=cmd_drivers)
