"""A reference model of the protocol for the differential soak (tests/sim/soak.py).

Given a request line, it predicts the exact reply bytes of an ORFA gateway
(local address AA after reset) with, on its simulated I2C bus, a 256-byte
24C02-like EEPROM (sim/parts/eeprom24.c: one word-address byte, reads
auto-increment and wrap at 256, writes wrap inside their 8-byte page) and one
ORFA slave board; every other address is absent (ERROR 06).

It is written from docs/protocol.md and docs/registers.md (the tables of what a
slave board answers), not from the firmware: where the two disagree the soak stops and prints both.

Pure Python, no I/O. The board facts (driver list, UIDs, register starts)
come from introspecting the running boards once (soak.py), checked against
the static expectation in host/orfa/boards.py; a driver the model does not
know (one appended later, such as a reset-cause register) is left alone: its
registers are "out of scope" and the generator never touches them.

Scope: parse errors (02-05, first error of the line, both length limits,
comments, empty lines), V, X, L/Lxx, C/Cxxxx, EEPROM frames, absent
addresses, and on each board the registers whose behaviour the model owns
completely: introspection, status, GPIO ports with nothing else on their
pins, motors (no servo ever pulses, so no pin conflict), servo RS and SP
with width-0 triples or writes that are refused, the SPI and ADC registers
as far as they are deterministic without SPI exchanges or ADC conversions
(DATA unreadable, CONFIG read, refused writes; RC/RD read, RD write).
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from orfa.boardmap import F_CPU  # the boards' clock (board.h, through the map)
LINE_MAX = 128
REPLY_MAX = 127
HEXDIGITS = set("0123456789abcdefABCDEF")

# Status register values (docs/registers.md).
OK, BAD_LENGTH, BAD_VALUE, PIN_BUSY, NOT_WRITABLE, NOT_READABLE, READ_WRAPPED, \
    NOT_BOUND, NO_REGISTER = range(9)

# Protocol error codes (docs/protocol.md, "Errors").
E_COMMAND, E_HEX, E_DATA, E_NO_P, E_ADDR_NACK, E_DATA_NACK = 2, 3, 4, 5, 6, 7

UID_INTRO, UID_SPI, UID_ADC, UID_MOTOR = 0x0000, 0x0001, 0x0040, 0x0060
UID_GPIO = (0x0020, 0x0021)
UID_SERVO = {0x0031: 16, 0x0030: 32}

#: GPIO ports of each board in register order, and those whose every line is
#: GPIO's with nothing attached in the simulator (docs/boards.md): their
#: value register reads PORTx back (an output shows its level, an input its
#: pull-up, a floating input reads 0 in the simulator).
GPIO_PORTS = {"m32d": "ABCD", "m128s": "AF"}
GPIO_FREE_PORTS = {"m32d": "A", "m128s": "AF"}


class OutOfScope(Exception):
    """The request does something the model does not own (the generator
    then draws another one); nothing of the model's state has changed."""


def twi_khz(khz: int) -> int:
    """The bus clock the gateway sets for `C<khz>` and replies (docs/protocol.md):
    the shortest SCL period not faster than asked, `16 + 2*TWBR*4^TWPS`
    cycles, with the smallest prescaler that reaches it; the reply is that
    rate in kHz rounded down. (firmware/twi_rate.c's rule, in Python.)"""
    f = max(khz, 1) * 1000
    period = -(-F_CPU // f)
    extra = max(period - 16, 0)
    twbr, twps = 255, 3
    for ps in range(4):
        div = 2 << (2 * ps)
        need = -(-extra // div)
        if need <= 255:
            twbr, twps = need, ps
            break
    return F_CPU // ((16 + twbr * (2 << (2 * twps))) * 1000)


# --- the parser (docs/protocol.md) ----------------------------------------------

@dataclass
class Request:
    cmd: str                       # "V" "X" "L" "C" "S"
    args: bytes = b""              # L: 0/1 byte, C: 0/2 bytes
    frames: List[Tuple[int, bytes, int]] = field(default_factory=list)
    # frames: (address, written bytes, read count)


def parse(line: str):
    """None (no reply), an error code (int), or a Request. `line` is the
    text before its terminator (no CR or LF in it)."""
    if line[:1] == "#" or line.strip(" ") == "":
        return None
    state = "begin"
    cmd = None
    hi = None             # first digit of a byte in progress
    args = bytearray()
    frames: List[list] = []
    reply = 0
    for n, ch in enumerate(line, 1):
        if n > LINE_MAX:
            if state == "begin":
                # only spaces so far and a command after column 128: the
                # protocol does not say which rule comes first
                raise OutOfScope("command after 128 leading spaces")
            return E_DATA
        is_hex = ch in HEXDIGITS
        if hi is not None and not is_hex:
            return E_HEX                      # a byte with one digit
        if ch == " ":
            continue
        if state == "begin":
            c = ch.upper()
            if c in "VX":
                cmd, state = c, "done"
            elif c in "LC":
                cmd, state = c, "args"
            elif c == "S":
                cmd, state, reply = "S", "addr", 3   # "SW"/"SR" and the "P"
                frames.append(None)
            else:
                return E_COMMAND
            continue
        if state == "done":
            return E_DATA                     # anything after a complete command
        if state == "rdone" and is_hex:
            return E_DATA                     # a second count byte
        up = ch.upper()
        if not is_hex:
            if state in ("wdata", "rdone") and up == "S":
                if reply + 2 > REPLY_MAX:
                    return E_DATA
                reply += 2
                frames.append(None)
                state = "addr"
                continue
            if state in ("wdata", "rdone") and up == "P":
                state = "done"
                continue
            if state == "rcount" and up in "SP":
                return E_DATA                 # a read frame without its count
            return E_HEX
        if hi is None:
            hi = ch
            continue
        b = int(hi + ch, 16)
        hi = None
        if state == "args":
            args.append(b)
            if cmd == "L":
                if b & 0xFE == 0:
                    return E_DATA             # L00, L01
                state = "done"
            elif len(args) == 2:
                if args == b"\0\0":
                    return E_DATA             # C0000
                state = "done"
        elif state == "addr":
            frames[-1] = [b, bytearray(), 0]
            state = "rcount" if b & 1 else "wdata"
        elif state == "wdata":
            if reply + 1 > REPLY_MAX:
                return E_DATA
            reply += 1
            frames[-1][1].append(b)
        elif state == "rcount":
            if b == 0 or reply + 2 * b > REPLY_MAX:
                return E_DATA
            reply += 2 * b
            frames[-1][2] = b
            state = "rdone"
    # the line ended
    if hi is not None:
        return E_HEX
    if state in ("addr", "wdata", "rcount", "rdone"):
        return E_NO_P
    if state == "args" and cmd == "C" and len(args) == 1:
        return E_DATA
    return Request(cmd, bytes(args), [(a, bytes(d), c) for a, d, c in frames])


# --- one board's register map (docs/registers.md) ---------------------------------

@dataclass
class Record:
    uid: int
    major: int
    minor: int
    start: int
    count: int

    def raw(self) -> bytes:
        return bytes([self.uid >> 8, self.uid & 0xFF, self.major, self.minor,
                      self.start, self.count])


class BoardModel:
    """The register map of one ORFA board as docs/registers.md has it."""

    def __init__(self, board: str, records: Sequence[Record]):
        self.board = board
        self.records = list(records)
        self.count = len(self.records)
        last = self.records[-1]
        self.end = last.start + last.count        # first unmapped register
        # register -> (driver record, offset)
        self.owner: Dict[int, Tuple[Record, int]] = {}
        for rec in self.records:
            for off in range(rec.count):
                self.owner[rec.start + off] = (rec, off)
        self.by_uid = {rec.uid: rec for rec in self.records}
        gpio = [r for r in self.records if r.uid in UID_GPIO]
        self.gpio = gpio[0] if gpio else None
        self.nports = self.gpio.count // 2 if self.gpio else 0
        ports = GPIO_PORTS[board]
        assert self.nports in (0, len(ports)), (board, self.nports)
        #: GPIO port indices the model owns
        self.free_ports = [ports.index(p) for p in GPIO_FREE_PORTS[board]] if self.gpio else []
        servo = [r for r in self.records if r.uid in UID_SERVO]
        self.servo = servo[0] if servo else None
        self.channels = UID_SERVO[self.servo.uid] if self.servo else 0
        self.reset()

    def reset(self) -> None:
        self.sel = 0              # selected register, None after an unmapped one
        self.status = OK
        self.cursor = 0           # introspection: 0 = the count, n = driver n
        self.port = {i: 0 for i in self.free_ports}    # PORTx
        self.ddr = {i: 0 for i in self.free_ports}     # DDRx
        self.motor = [0, 0, 0, 0]

    def snapshot(self):
        return (self.sel, self.status, self.cursor, dict(self.port), dict(self.ddr),
                list(self.motor))

    def restore(self, snap) -> None:
        (self.sel, self.status, self.cursor, port, ddr, motor) = snap
        self.port, self.ddr, self.motor = dict(port), dict(ddr), list(motor)

    # --- what a register is ----------------------------------------------------
    def kind(self, reg: int) -> Tuple[str, int]:
        """("intro"|"status"|"gpio_val"|"gpio_mode"|"motor"|"servo_rs"|
        "servo_sp"|"spi_data"|"spi_config"|"adc_rc"|"adc_rd"|"unknown", offset)."""
        rec, off = self.owner[reg]
        if rec.uid == UID_INTRO:
            return ("intro" if off == 0 else "status"), 0
        if rec is self.gpio:
            if off < self.nports:
                return "gpio_val", off
            return "gpio_mode", off - self.nports
        if rec.uid == UID_MOTOR:
            return "motor", off
        if rec is self.servo:
            return ("servo_rs" if off == 0 else "servo_sp"), 0
        if rec.uid == UID_SPI:
            return ("spi_data" if off == 0 else "spi_config"), 0
        if rec.uid == UID_ADC:
            return ("adc_rc" if off == 0 else "adc_rd"), 0
        return "unknown", off

    # --- drivers: check (newest byte), write (all or nothing), read ------------
    def check(self, reg: int, data: bytes) -> int:
        kind, off = self.kind(reg)
        n = len(data)
        if kind == "status":
            return NOT_WRITABLE
        if kind == "intro":
            return BAD_LENGTH if n > 1 else OK
        if kind in ("gpio_val", "gpio_mode"):
            return BAD_LENGTH if n > 2 else OK
        if kind == "motor":
            return BAD_LENGTH if off + n > 4 else OK
        if kind == "servo_rs":
            return OK
        if kind == "servo_sp":
            if n > 48:
                return BAD_LENGTH
            if (n - 1) % 3 == 0 and data[-1] >= self.channels:
                return BAD_VALUE
            return OK
        if kind == "spi_config":
            return BAD_LENGTH if n > 3 else OK
        if kind == "spi_data":
            return BAD_LENGTH if n - 1 > 64 else OK
        if kind == "adc_rd":
            return NOT_WRITABLE
        if kind == "adc_rc":
            return BAD_LENGTH if n > 2 else OK
        raise OutOfScope("check of register %02X (%s)" % (reg, kind))

    def write(self, reg: int, data: bytes) -> int:
        kind, off = self.kind(reg)
        n = len(data)
        if kind == "intro":
            if n != 1:
                return BAD_LENGTH
            if data[0] > self.count:
                self.cursor = 1
                return BAD_VALUE
            self.cursor = data[0]
            return OK
        if kind in ("gpio_val", "gpio_mode"):
            if off not in self.free_ports:
                raise OutOfScope("GPIO port %d" % off)
            if n not in (1, 2):
                return BAD_LENGTH
            mask = data[1] if n == 2 else 0xFF
            regs = self.port if kind == "gpio_val" else self.ddr
            regs[off] = (regs[off] & ~mask | data[0] & mask) & 0xFF
            return OK
        if kind == "motor":
            nxt = list(self.motor)
            nxt[off:off + n] = data
            if nxt[2] > 1 or nxt[3] > 1:
                return BAD_VALUE
            self.motor = nxt
            return OK
        if kind == "servo_rs":
            return OK
        if kind == "servo_sp":
            if n == 1:
                return OK           # selects the first channel reads give: all 0 here
            if n % 3:
                return BAD_LENGTH
            if any(data[i + 1] or data[i + 2] for i in range(0, n, 3)):
                raise OutOfScope("a servo would pulse")
            return OK               # width 0: the channel stays off
        raise OutOfScope("write of register %02X (%s)" % (reg, kind))

    def read(self, reg: int, maxlen: int) -> bytes:
        """One answer of the register's driver (b"": it cannot be read)."""
        kind, off = self.kind(reg)
        if kind == "intro":
            if self.cursor == 0:
                return bytes([self.count])
            if self.cursor > self.count:
                self.cursor = 1
                self.status = READ_WRAPPED
            rec = self.records[self.cursor - 1].raw()[:min(maxlen, 6)]
            self.cursor += 1
            return rec
        if kind == "gpio_val":
            if off not in self.free_ports:
                raise OutOfScope("GPIO port %d" % off)
            return bytes([self.port[off]])
        if kind == "gpio_mode":
            if off not in self.free_ports:
                raise OutOfScope("GPIO port %d" % off)
            return bytes([self.ddr[off]])
        if kind == "motor":
            return bytes(self.motor[off:4][:maxlen])
        if kind == "servo_rs":
            return bytes(min(self.channels // 8, maxlen))
        if kind == "servo_sp":
            return bytes(min(2 * self.channels, maxlen))   # no channel ever on
        if kind == "spi_data":
            return b""              # no exchange ever made
        if kind == "spi_config":
            return (b"\x02" + b"\xff" * 8)[:maxlen]
        if kind == "adc_rc":
            return b"\0\0"[:maxlen]
        if kind == "adc_rd":
            return bytes(min(8, maxlen))      # 8-bit mode, no channel enabled
        raise OutOfScope("read of register %02X (%s)" % (reg, kind))

    # --- the register map (regmap.h) -----------------------------------------------
    def select(self, reg: int) -> bool:
        if reg >= self.end:
            self.sel = None
            self.status = NO_REGISTER
            return False
        if self.kind(reg)[0] == "unknown":
            raise OutOfScope("register %02X of an unknown driver" % reg)
        self.sel = reg
        return True

    def reg_check(self, data: bytes) -> int:
        if self.sel is None:
            return NO_REGISTER
        return self.check(self.sel, data)

    def reg_write(self, data: bytes) -> int:
        if self.sel is None:
            st = NO_REGISTER
        elif self.sel == 1:
            st = NOT_WRITABLE
        else:
            st = self.write(self.sel, data)
        self.status = st
        return st

    def read_start(self) -> None:
        if self.sel is not None and self.sel != 1:
            self.status = OK

    def reg_read(self, maxlen: int) -> bytes:
        if self.sel is None:
            return b""
        if self.sel == 1:
            return bytes([self.status]) * maxlen
        got = self.read(self.sel, maxlen)
        if not got:
            self.status = NOT_READABLE
        return got

    # --- frames: the gateway's local address (docs/registers.md "Frames") -------
    def local_write(self, data: bytes) -> Optional[int]:
        """A write frame to the local address: None or the error code."""
        if not data:
            return None
        if not self.select(data[0]):
            return E_DATA_NACK
        taken = b""
        for b in data[1:]:
            taken += bytes([b])
            st = self.reg_check(taken)
            if st != OK:
                self.status = st
                return E_DATA_NACK
        if taken and self.reg_write(taken) != OK:
            return E_DATA_NACK
        return None

    def local_read(self, count: int):
        """A read frame of the local address: the bytes, or the error code."""
        self.read_start()
        out = b""
        while len(out) < count:
            got = self.reg_read(count - len(out))
            if not got:
                return E_ADDR_NACK
            out += got
        return out

    # --- frames: a slave board on the bus (docs/registers.md) ---------------------------
    SLAVE_BUF = 64

    def slave_write(self, data: bytes) -> Optional[int]:
        """A write frame to the slave through the gateway: the slave refuses
        the byte AFTER the one that makes the write invalid (ERROR 07 then);
        a frame that ends with that byte is acknowledged in full."""
        refused = False
        taken = b""
        for i, b in enumerate(data):
            if i == 0:
                ok = self.select(b)
            elif len(taken) >= self.SLAVE_BUF:
                self.status = BAD_LENGTH
                ok = False
            else:
                taken += bytes([b])
                st = self.reg_check(taken)
                if st != OK:
                    self.status = st
                ok = st == OK
            if not ok:
                refused = True
                if i + 1 < len(data):
                    return E_DATA_NACK
                break
        if not refused and taken:
            self.reg_write(taken)          # the status register tells
        return None

    def slave_read(self, count: int) -> bytes:
        """A read frame of the slave: its read address is always acknowledged;
        FF when there is nothing to read. Its driver is asked for up to the
        free room of its 64-byte buffer at a time."""
        self.read_start()
        buf_len = 0
        out = b""
        answer = b""
        dead = False
        while len(out) < count:
            if dead:
                out += b"\xff"
                continue
            if not answer:
                if buf_len >= self.SLAVE_BUF:
                    buf_len = 0
                answer = self.reg_read(self.SLAVE_BUF - buf_len)
                if not answer:
                    dead = True
                    continue
                buf_len += len(answer)
            out += answer[:1]
            answer = answer[1:]
        return out


class Eeprom24:
    """sim/parts/eeprom24.c: 256 bytes erased to FF, one word-address byte,
    reads auto-increment (wrap at 256), writes wrap inside 8-byte pages."""

    def __init__(self):
        self.mem = bytearray(b"\xff" * 256)
        self.ptr = 0

    def snapshot(self):
        return (bytes(self.mem), self.ptr)

    def restore(self, snap) -> None:
        self.mem, self.ptr = bytearray(snap[0]), snap[1]

    def write(self, data: bytes) -> None:
        for i, b in enumerate(data):
            if i == 0:
                self.ptr = b
            else:
                self.mem[self.ptr] = b
                self.ptr = (self.ptr & ~7) | ((self.ptr + 1) & 7)

    def read(self, count: int) -> bytes:
        out = bytearray()
        for _ in range(count):
            out.append(self.mem[self.ptr])
            self.ptr = (self.ptr + 1) & 0xFF
        return bytes(out)


class GatewayModel:
    """The gateway (local board), its bus: the EEPROM and one slave board."""

    def __init__(self, local: BoardModel, slave: BoardModel, slave_addr: int,
                 eeprom_addr: int = 0xA0):
        self.local_board = local
        self.slave = slave
        self.slave_addr = slave_addr
        self.eeprom_addr = eeprom_addr
        self.eeprom = Eeprom24()
        self.local = 0xAA
        self.khz = twi_khz(100)

    def snapshot(self):
        return (self.local, self.khz, self.eeprom.snapshot(),
                self.local_board.snapshot(), self.slave.snapshot())

    def restore(self, snap) -> None:
        self.local, self.khz, ee, lb, sb = snap
        self.eeprom.restore(ee)
        self.local_board.restore(lb)
        self.slave.restore(sb)

    def reply(self, line: str) -> Optional[bytes]:
        """The reply line (with CR LF) to `line`, or None for no reply.
        Raises OutOfScope, with the model unchanged, for what it does not own."""
        snap = self.snapshot()
        try:
            return self._reply(line)
        except OutOfScope:
            self.restore(snap)
            raise

    def _reply(self, line: str) -> Optional[bytes]:
        req = parse(line)
        if req is None:
            return None
        if isinstance(req, int):
            return b"ERROR %02X\r\n" % req
        if req.cmd == "V":
            return b"V1.1\r\n"
        if req.cmd == "X":
            return b"X\r\n"
        if req.cmd == "L":
            if req.args:
                self.local = req.args[0] & 0xFE
            return b"L%02X\r\n" % self.local
        if req.cmd == "C":
            if req.args:
                self.khz = twi_khz(req.args[0] << 8 | req.args[1])
            return b"C%04X\r\n" % self.khz
        return self._i2c(req.frames)

    def _i2c(self, frames) -> bytes:
        text = b""
        for addr, data, count in frames:
            dev = addr & 0xFE
            is_read = bool(addr & 1)
            if dev == self.local:
                board = self.local_board
                if is_read:
                    got = board.local_read(count)
                    if isinstance(got, int):
                        return b"ERROR %02X\r\n" % got
                else:
                    err = board.local_write(data)
                    if err:
                        return b"ERROR %02X\r\n" % err
            elif dev == self.slave_addr:
                if is_read:
                    got = self.slave.slave_read(count)
                else:
                    err = self.slave.slave_write(data)
                    if err:
                        return b"ERROR %02X\r\n" % err
            elif dev == self.eeprom_addr:
                if is_read:
                    got = self.eeprom.read(count)
                else:
                    self.eeprom.write(data)
            else:
                return b"ERROR %02X\r\n" % E_ADDR_NACK
            if is_read:
                text += b"SR" + got.hex().upper().encode()
            else:
                text += b"SW" + b"A" * len(data)
        return text + b"P\r\n"


# --- the request generator -----------------------------------------------------------

JUNK = "VXLCSPvxlcsp0123456789abcdefABCDEFGQZgz#!*:., \t-"
ABSENT = (0x12, 0x14, 0x20, 0x22, 0x30, 0x50, 0x7E, 0xA2, 0xA4, 0xAC, 0xE0, 0xEE, 0xFE)


class Generator:
    """Seeded random requests, valid and invalid, for a GatewayModel. Each
    call of `next()` gives (line, terminator); the model judges them, so the
    generator needs no knowledge of what they should answer."""

    def __init__(self, model: GatewayModel, seed: int, long_blank: bool = True):
        self.m = model
        self.rng = random.Random(seed)
        self.long_blank = long_blank
        self.kinds = [
            (3, self.version), (1, self.clear), (3, self.local_addr), (3, self.clock),
            (10, self.eeprom), (22, self.registers), (6, self.multi), (3, self.absent),
            (8, self.mutant), (3, self.junk), (2, self.too_long), (2, self.reply_limit),
            (3, self.blank), (2, self.comment),
        ]
        self.total = sum(w for w, _ in self.kinds)

    # --- text ------------------------------------------------------------------
    def case(self, text: str) -> str:
        r = self.rng.random()
        if r < 0.7:
            return text
        if r < 0.85:
            return text.lower()
        return "".join(c.lower() if self.rng.random() < 0.5 else c for c in text)

    def sep(self) -> str:
        r = self.rng.random()
        return "" if r < 0.45 else " " if r < 0.9 else "  "

    def render(self, tokens: Sequence[str]) -> str:
        lead = " " * self.rng.choice((0, 0, 0, 0, 1, 3))
        tail = " " * self.rng.choice((0, 0, 0, 0, 1, 2))
        body = tokens[0]
        for tok in tokens[1:]:
            body += self.sep() + tok
        return self.case(lead + body + tail)

    def frames_text(self, frames) -> List[str]:
        """[(addr, data bytes, read count)] -> tokens "S" "10" "20" ... "P"."""
        toks: List[str] = []
        for addr, data, count in frames:
            toks += ["S", "%02X" % addr]
            if addr & 1:
                toks.append("%02X" % count)
            else:
                toks += ["%02X" % b for b in data]
        return toks + ["P"]

    def terminator(self) -> str:
        r = self.rng.random()
        return "\n" if r < 0.8 else "\r" if r < 0.93 else "\r\n"

    # --- kinds ------------------------------------------------------------------
    def version(self):
        return self.render(["V"])

    def clear(self):
        return self.render(["X"])

    def local_addr(self):
        r = self.rng.random()
        if r < 0.3:
            return self.render(["L"])
        if self.m.local != 0xAA and r < 0.75:
            addr = 0xAA | self.rng.randrange(2)          # back home
        elif r < 0.85:
            addr = self.rng.choice((0x10, 0x11, 0xA0, 0x12, 0x20, 0xAB, 0x00, 0x01))
        else:
            addr = self.rng.randrange(256)
        return self.render(["L", "%02X" % addr])

    def clock(self):
        r = self.rng.random()
        if r < 0.3:
            return self.render(["C"])
        if self.m.khz < 30 and r < 0.8:
            khz = 100
        elif r < 0.85:
            khz = self.rng.randrange(30, 0x1D0)
        elif r < 0.95:
            khz = self.rng.randrange(0x1D0, 0x10000)
        elif r < 0.98:
            khz = self.rng.randrange(0, 30)       # slow; the next ones bring it back
        else:
            khz = 0
        return self.render(["C", "%02X" % (khz >> 8), "%02X" % (khz & 0xFF)])

    def eeprom_frames(self):
        ee = self.m.eeprom_addr
        r = self.rng.random()
        word = self.rng.randrange(256)
        if r < 0.4:
            data = bytes(self.rng.randrange(256) for _ in range(self.rng.randrange(0, 17)))
            return [(ee, bytes([word]) + data, 0)]
        if r < 0.75:
            return [(ee, bytes([word]), 0), (ee | 1, b"", self.rng.randrange(1, 33))]
        if r < 0.85:
            return [(ee | 1, b"", self.rng.randrange(1, 20))]
        if r < 0.93:
            return [(ee, b"", 0)]                      # address probe
        return [(ee, bytes([word]), 0), (ee, bytes([self.rng.randrange(256)]), 0),
                (ee | 1, b"", self.rng.randrange(1, 9))]

    def eeprom(self):
        return self.render(self.frames_text(self.eeprom_frames()))

    def board_frames(self):
        """Register frames for the local board or the slave."""
        if self.rng.random() < 0.5:
            addr, b = self.m.local, self.m.local_board
        else:
            addr, b = self.m.slave_addr, self.m.slave
        rng = self.rng
        w, rd = addr, addr | 1

        def sel_read(reg, count):
            return [(w, bytes([reg]), 0), (rd, b"", count)]

        r = rng.randrange(20)
        if r == 0:
            return sel_read(0, rng.choice((1, 1, 2, 5)))                        # count
        if r == 1:
            return [(w, bytes([0, rng.randrange(0, b.count + 2)]), 0),
                    (rd, b"", rng.choice((1, 3, 6, 6, 7, 12, 18, 30, 36, 60, 61)))]
        if r == 2:
            return [(rd, b"", rng.randrange(1, 13))]                            # as selected
        if r == 3:
            return sel_read(1, rng.randrange(1, 4))                             # status
        if r == 4:
            # introspection writes, good and bad
            n = rng.choice((0, 1, b.count, b.count + 1, 0x40, 0xFF))
            extra = bytes(rng.randrange(256) for _ in range(rng.choice((0, 0, 1, 2))))
            return [(w, bytes([0, n]) + extra, 0)]
        if r == 5:
            data = bytes(rng.randrange(256) for _ in range(rng.choice((1, 1, 2, 3))))
            return [(w, bytes([1]) + data, 0)]                                  # status: no
        if r in (6, 7, 8) and b.free_ports:
            port = rng.choice(b.free_ports)
            reg = b.gpio.start + port + (b.nports if rng.random() < 0.5 else 0)
            n = rng.choice((1, 2, 2, 3, 0))
            data = bytes(rng.randrange(256) for _ in range(n))
            fr = [(w, bytes([reg]) + data, 0)]
            if rng.random() < 0.6:
                fr.append((rd, b"", rng.randrange(1, 4)))
            return fr
        if r == 9:
            reg = rng.randrange(b.end, 256)                                      # unmapped
            data = bytes(rng.randrange(256) for _ in range(rng.choice((0, 0, 1, 2))))
            fr = [(w, bytes([reg]) + data, 0)]
            if rng.random() < 0.5:
                fr.append((rd, b"", rng.randrange(1, 4)))
            return fr
        if r == 10 and UID_MOTOR in b.by_uid:
            start = b.by_uid[UID_MOTOR].start
            off = rng.randrange(4)
            n = rng.randrange(0, 6)
            data = bytes(rng.choice((0, 1, 1, 2, 0x80, 0xFF)) if off + i >= 2
                         else rng.randrange(256) for i in range(n))
            fr = [(w, bytes([start + off]) + data, 0)]
            if rng.random() < 0.5:
                fr.append((rd, b"", rng.randrange(1, 5)))
            return fr
        if r == 11 and b.servo:
            rs = b.servo.start
            if rng.random() < 0.5:
                data = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 12)))
                return [(w, bytes([rs]) + data, 0), (rd, b"", rng.randrange(1, 6))]
            return sel_read(rs + 1, rng.randrange(1, 40))
        if r == 12 and b.servo:
            sp = b.servo.start + 1
            kind = rng.randrange(4)
            chans = b.channels
            if kind == 0:                       # width 0 triples: channels stay off
                data = b"".join(bytes([rng.randrange(chans), 0, 0])
                                for _ in range(rng.randrange(1, 5)))
            elif kind == 1:                     # a channel that does not exist
                good = b"".join(bytes([rng.randrange(chans), 5, 0xDC])
                                for _ in range(rng.randrange(0, 3)))
                data = good + bytes([rng.randrange(chans, 256)]) + \
                    bytes(rng.randrange(256) for _ in range(rng.choice((0, 1, 2, 3))))
            elif kind == 2:                     # a length not a multiple of 3
                data = bytes([rng.randrange(chans), 0, 0, rng.randrange(chans)])[
                    :rng.choice((2, 4))]
            else:                               # select the first channel
                data = bytes([rng.randrange(chans)])
            return [(w, bytes([sp]) + data, 0)]
        if r == 13 and UID_SPI in b.by_uid:
            spi = b.by_uid[UID_SPI].start
            if rng.random() < 0.5:
                return sel_read(spi + rng.randrange(2), rng.randrange(1, 12))
            data = bytes(rng.randrange(256) for _ in range(rng.randrange(4, 7)))
            return [(w, bytes([spi + 1]) + data, 0)]                             # refused
        if r == 14 and UID_ADC in b.by_uid:
            adc = b.by_uid[UID_ADC].start
            if rng.random() < 0.6:
                return sel_read(adc + rng.randrange(2), rng.randrange(1, 10))
            data = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 3)))
            return [(w, bytes([adc + 1]) + data, 0)]                             # RD: refused
        if r == 15:
            return [(w, b"", 0)]                                                # probe
        # introspection records, the common case
        k = rng.randrange(1, 11)
        return [(w, bytes([0, rng.randrange(1, b.count + 1)]), 0), (rd, b"", 6 * k)]

    def registers(self):
        return self.render(self.frames_text(self.board_frames()))

    def absent_frames(self):
        addr = self.rng.choice(ABSENT)
        if self.rng.random() < 0.5:
            return [(addr | 1, b"", self.rng.randrange(1, 4))]
        return [(addr, bytes(self.rng.randrange(256) for _ in range(self.rng.randrange(3))), 0)]

    def absent(self):
        return self.render(self.frames_text(self.absent_frames()))

    def multi(self):
        frames = []
        for _ in range(self.rng.randrange(2, 4)):
            pick = self.rng.random()
            frames += (self.eeprom_frames() if pick < 0.4 else self.board_frames()
                       if pick < 0.9 else self.absent_frames())
        return self.render(self.frames_text(frames))

    def valid_text(self) -> str:
        w, fn = self.pick_kind(("version", "local_addr", "clock", "eeprom", "registers",
                                "multi", "absent"))
        return fn()

    def pick_kind(self, names):
        choices = [(w, f) for w, f in self.kinds if f.__name__ in names]
        return self.rng.choice(choices)

    def mutant(self):
        text = self.valid_text()
        for _ in range(self.rng.choice((1, 1, 1, 2, 3))):
            i = self.rng.randrange(len(text) + 1)
            op = self.rng.randrange(3)
            ch = self.rng.choice(JUNK)
            if op == 0:
                text = text[:i] + ch + text[i:]
            elif op == 1 and text:
                text = text[:i] + text[i + 1:]
            else:
                text = text[:i] + ch + text[i + 1:]
        return text

    def junk(self):
        return "".join(self.rng.choice(JUNK) for _ in range(self.rng.randrange(1, 40)))

    def too_long(self):
        """Lines around and over the 128-character limit."""
        r = self.rng.random()
        n = self.rng.choice((126, 127, 128, 128, 129, 129, 130, 160, 200))
        if r < 0.4:
            # a valid request padded with spaces to n characters
            text = "V" if self.rng.random() < 0.5 else "S %02X 00 01 P" % self.m.eeprom_addr
            pad = n - len(text)
            cut = self.rng.randrange(pad + 1)
            return text[:1] + " " * cut + text[1:] + " " * (pad - cut)
        if r < 0.8:
            # a long EEPROM write: the request limit comes before the reply limit
            k = (n - 8) // 2
            data = "".join("%02X" % self.rng.randrange(256) for _ in range(max(k, 0)))
            text = "S%02X%02X%s" % (self.m.eeprom_addr, self.rng.randrange(256), data)
            text = (text + "P" + " " * n)[:n]
            return text
        # junk or an error early in a long line: the first error decides
        return self.junk() + "z" * (n - 40)

    def reply_limit(self):
        """Requests whose reply is at or just over 127 characters."""
        ee = self.m.eeprom_addr
        r = self.rng.random()
        if r < 0.5:
            count = self.rng.choice((60, 61, 62, 0x7F, 0x80, 0xFF))
            return self.render(["S", "%02X" % ee, "00", "S", "%02X" % (ee | 1),
                                "%02X" % count, "P"])
        # many small frames: 'S' itself can break the limit
        frames = [(ee | 1, b"", self.rng.randrange(1, 5))
                  for _ in range(self.rng.randrange(12, 30))]
        return "".join(self.frames_text(frames))

    def blank(self):
        n = self.rng.choice((0, 0, 1, 3, 20, 128, 129, 200)) if self.long_blank else \
            self.rng.choice((0, 0, 1, 3, 20, 128))
        return " " * n

    def comment(self):
        n = self.rng.choice((0, 5, 40, 127, 150, 200))
        return "#" + "".join(self.rng.choice(JUNK.replace("#", "") + "#")
                             for _ in range(n))

    # --- one request ----------------------------------------------------------------
    def next(self) -> Tuple[str, str, Optional[bytes]]:
        """(line, terminator, expected reply or None): the model has taken it."""
        while True:
            x = self.rng.randrange(self.total)
            for w, fn in self.kinds:
                if x < w:
                    break
                x -= w
            line = fn()
            term = self.terminator()
            try:
                reply = self.m.reply(line)
            except OutOfScope:
                continue
            return line, term, reply
