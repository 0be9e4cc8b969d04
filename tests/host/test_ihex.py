"""orfa.ihex, the pure-Python ELF -> Intel HEX of `orfa flash`, against
binutils: the same flash bytes as avr-objdump/avr-objcopy find in the ELF,
and as `avr-objcopy -O ihex -R .eeprom` (the build's .hex) writes."""

import struct
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from flashcheck import elf_flash_image, elf_flash_sections, read_ihex  # noqa: E402

from orfa import ihex  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

# .data (initial values in flash after .text), EEPROM contents (not flash),
# and a table placed across the ATmega128's 64 KiB line.
PROGRAM = r"""
#include <avr/eeprom.h>
#include <avr/pgmspace.h>
volatile unsigned char d[5] = {1, 2, 3, 4, 5};
unsigned char EEMEM e[4] = {9, 8, 7, 6};
const unsigned char hi[40] __attribute__((section(".hi"), used)) = {
    0xAA, 0x55, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18};
int main(void) { return d[1] + eeprom_read_byte(&e[1]) + pgm_read_byte(&hi[2]); }
"""


@pytest.fixture(scope="module")
def far_elf(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ihex")
    (tmp / "t.c").write_text(PROGRAM)
    elf = tmp / "t.elf"
    subprocess.run(["avr-gcc", "-mmcu=atmega128", "-Os", str(tmp / "t.c"), "-o", str(elf),
                    "-Wl,--section-start=.hi=0xFFF8"], check=True)
    return elf


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_far_flash_data_and_no_eeprom(far_elf, tmp_path):
    sections = {name: (lma, size) for name, lma, size in elf_flash_sections(far_elf)}
    assert set(sections) == {".text", ".data", ".hi"}       # .eeprom is at 0x810000
    image = read_ihex(write(tmp_path, "t.hex", ihex.elf_to_ihex(far_elf.read_bytes())))
    assert image == elf_flash_image(far_elf, tmp_path)
    assert image[0xFFF8] == 0xAA and image[0x10000] == 7   # both sides of 64 KiB
    assert not any(0x800000 <= a for a in image)


def test_same_bytes_as_avr_objcopy(far_elf, tmp_path):
    ours = read_ihex(write(tmp_path, "ours.hex", ihex.elf_to_ihex(far_elf.read_bytes())))
    theirs = tmp_path / "theirs.hex"
    subprocess.run(["avr-objcopy", "-O", "ihex", "-R", ".eeprom", str(far_elf), str(theirs)],
                   check=True)
    assert ours == read_ihex(theirs)


@pytest.mark.parametrize("build", ["m32d-gate", "m32d-slave", "m128s-gate", "m128s-slave"])
def test_each_build_the_same_as_its_hex(build, tmp_path):
    elf = ROOT / "build" / build / "orfa.elf"
    if not elf.is_file():
        subprocess.run(["make", "--no-print-directory", "BOARD=" + build.split("-")[0],
                        "MODE=" + build.split("-")[1], "firmware"], cwd=ROOT, check=True,
                       capture_output=True)
    ours = read_ihex(write(tmp_path, "ours.hex", ihex.elf_to_ihex(elf.read_bytes())))
    assert ours == read_ihex(elf.with_name("orfa.hex"))
    assert ours == elf_flash_image(elf, tmp_path)


def test_records():
    data = bytes(range(256)) * 2
    text = ihex.to_ihex([(0xFFE8, data[:40]), (0x20000, data[:3])])
    lines = text.splitlines()
    assert lines[0] == ":10FFE800000102030405060708090A0B0C0D0E0F91"
    assert lines[1] == ":08FFF800101112131415161765"              # stops at 64 KiB
    assert lines[2] == ":020000040001F9"                          # upper 16 bits: 1
    assert lines[3] == ":1000000018191A1B1C1D1E1F2021222324252627F8"
    assert lines[4] == ":020000040002F8"
    assert lines[5] == ":03000000000102FA"
    assert lines[6:] == [":00000001FF"]
    assert text.endswith("\n")


def elf_header(machine=83, phnum=0, cls=1):
    ident = b"\x7fELF" + bytes([cls, 1, 1]) + bytes(9)
    return ident + struct.pack("<HHIIIIIHHHHHH", 2, machine, 1, 0, 52, 0, 0, 52, 32,
                               phnum, 40, 0, 0)


def test_bad_elves():
    with pytest.raises(ihex.ElfError, match="not an ELF file"):
        ihex.elf_to_ihex(b":00000001FF\n")
    with pytest.raises(ihex.ElfError, match="not a 32-bit little-endian ELF"):
        ihex.elf_to_ihex(elf_header(cls=2))
    with pytest.raises(ihex.ElfError, match="an ELF for machine 40, not the AVR"):
        ihex.elf_to_ihex(elf_header(machine=40))
    with pytest.raises(ihex.ElfError, match="program headers past the end"):
        ihex.elf_to_ihex(elf_header(phnum=2))
    with pytest.raises(ihex.ElfError, match="nothing to put in flash"):
        ihex.elf_to_ihex(elf_header())
    segment = struct.pack("<8I", 1, 200, 0, 0, 16, 16, 5, 2)      # data past the end
    with pytest.raises(ihex.ElfError, match="a segment past the end"):
        ihex.elf_to_ihex(elf_header(phnum=1) + segment)


def test_the_device_an_elf_was_built_for(far_elf, tmp_path):
    assert ihex.elf_device(far_elf.read_bytes()) == "atmega128"
    # the note as avr-gcc writes it is what the device is read from: without
    # it, no device (a HEX file never has one)
    bare = tmp_path / "bare.elf"
    subprocess.run(["avr-objcopy", "-R", ".note.gnu.avr.deviceinfo", str(far_elf), str(bare)],
                   check=True)
    assert ihex.elf_device(bare.read_bytes()) is None
    assert ihex.elf_device(b":00000001FF\n") is None
    tiny = tmp_path / "t.c"
    tiny.write_text("int main(void) { return 0; }\n")
    subprocess.run(["avr-gcc", "-mmcu=atmega32", str(tiny), "-o", str(tmp_path / "t32.elf")],
                   check=True)
    assert ihex.elf_device((tmp_path / "t32.elf").read_bytes()) == "atmega32"
