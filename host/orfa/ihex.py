"""An AVR ELF's flash image as Intel HEX, in pure Python (no avr-objcopy).

What `avr-objcopy -O ihex -R .eeprom` makes of the firmware: the bytes the
ELF's loadable segments put in flash, at their load (physical) addresses.
`.text` loads at 0 and `.data`'s initial values right after it (their run
address is in RAM, 0x800060 on; the start-up code copies them). avr-gcc's
ELF files place RAM at 0x800000 and EEPROM at 0x810000 (fuses, lock bits and
the signature above), so flash is every address below 0x800000.
"""

from __future__ import annotations

import re
import struct
from typing import Iterable, List, Optional, Tuple

from .errors import ElfError

#: avr-gcc's address of the data space in an ELF: flash lies below it.
AVR_DATA_BASE = 0x800000
#: ELF machine number of the AVR.
EM_AVR = 83
PT_LOAD = 1
#: Data bytes per record, as avr-objcopy writes them.
RECORD_BYTES = 16

Segment = Tuple[int, bytes]


def is_elf(data: bytes) -> bool:
    return data[:4] == b"\x7fELF"


def flash_segments(elf: bytes) -> List[Segment]:
    """(load address, bytes) of each loadable segment that goes to flash,
    in address order, adjacent ones joined."""
    if not is_elf(elf):
        raise ElfError("not an ELF file")
    if len(elf) < 52 or elf[4] != 1 or elf[5] != 1:
        raise ElfError("not a 32-bit little-endian ELF (an AVR's)")
    machine, = struct.unpack_from("<H", elf, 18)
    if machine != EM_AVR:
        raise ElfError("an ELF for machine %d, not the AVR (%d)" % (machine, EM_AVR))
    phoff, = struct.unpack_from("<I", elf, 28)
    phentsize, phnum = struct.unpack_from("<HH", elf, 42)
    if phnum and (phentsize < 32 or phoff + phnum * phentsize > len(elf)):
        raise ElfError("truncated ELF: program headers past the end")
    pieces = []
    for i in range(phnum):
        (p_type, p_offset, _vaddr, p_paddr, p_filesz, _memsz, _flags,
         _align) = struct.unpack_from("<8I", elf, phoff + i * phentsize)
        if p_type != PT_LOAD or p_filesz == 0 or p_paddr >= AVR_DATA_BASE:
            continue
        if p_offset + p_filesz > len(elf):
            raise ElfError("truncated ELF: a segment past the end")
        if p_paddr + p_filesz > AVR_DATA_BASE:
            raise ElfError("a segment at 0x%X runs out of flash" % p_paddr)
        pieces.append((p_paddr, elf[p_offset:p_offset + p_filesz]))
    pieces.sort()
    joined: List[Segment] = []
    for addr, data in pieces:
        if joined and joined[-1][0] + len(joined[-1][1]) > addr:
            raise ElfError("segments overlap at 0x%X" % addr)
        if joined and joined[-1][0] + len(joined[-1][1]) == addr:
            joined[-1] = (joined[-1][0], joined[-1][1] + data)
        else:
            joined.append((addr, data))
    if not joined:
        raise ElfError("the ELF has nothing to put in flash")
    return joined


#: the note avr-gcc and avr-libc put in an ELF: the device it was built for
DEVICE_NOTE = b".note.gnu.avr.deviceinfo"


def elf_device(elf: bytes) -> Optional[str]:
    """The device an AVR ELF was built for ("atmega32"), from its
    .note.gnu.avr.deviceinfo section (its descriptor ends with the device's
    name in a string table); None when the ELF has no such note."""
    if not is_elf(elf) or len(elf) < 52:
        return None
    shoff, = struct.unpack_from("<I", elf, 32)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", elf, 46)
    if not shnum or shentsize < 40 or shoff + shnum * shentsize > len(elf) or shstrndx >= shnum:
        return None
    sections = [struct.unpack_from("<10I", elf, shoff + i * shentsize) for i in range(shnum)]
    names_at, names_size = sections[shstrndx][4], sections[shstrndx][5]
    names = elf[names_at:names_at + names_size]
    for sh in sections:
        name = names[sh[0]:names.find(b"\0", sh[0])]
        if name != DEVICE_NOTE:
            continue
        note = elf[sh[4]:sh[4] + sh[5]]
        if len(note) < 12:
            return None
        namesz, descsz, _type = struct.unpack_from("<3I", note, 0)
        desc = note[12 + (namesz + 3) // 4 * 4:][:descsz]
        strings = [w for w in desc.split(b"\0") if w]
        last = strings[-1] if strings else b""
        return last.decode("ascii") if re.fullmatch(rb"[a-z][a-z0-9]+", last) else None
    return None


def _record(rtype: int, addr: int, data: bytes) -> str:
    body = bytes([len(data), addr >> 8 & 0xFF, addr & 0xFF, rtype]) + data
    return ":%s%02X" % (body.hex().upper(), -sum(body) & 0xFF)


def to_ihex(segments: Iterable[Segment]) -> str:
    """Intel HEX text: data records of up to 16 bytes that never cross a
    64 KiB boundary, an extended linear address record (type 04) before
    data above 64 KiB (the ATmega128's upper flash), the end record."""
    lines = []
    upper = 0
    for addr, data in segments:
        pos = 0
        while pos < len(data):
            here = addr + pos
            if here >> 16 != upper:
                upper = here >> 16
                lines.append(_record(4, 0, struct.pack(">H", upper)))
            room = 0x10000 - (here & 0xFFFF)
            chunk = data[pos:pos + min(RECORD_BYTES, room)]
            lines.append(_record(0, here & 0xFFFF, chunk))
            pos += len(chunk)
    lines.append(_record(1, 0, b""))
    return "\n".join(lines) + "\n"


def elf_to_ihex(elf: bytes) -> str:
    """The flash image of an AVR ELF (`.text` + `.data`) as Intel HEX."""
    return to_ihex(flash_segments(elf))
