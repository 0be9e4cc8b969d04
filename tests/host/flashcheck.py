"""Helpers of the flashing tests: a stand-in avrdude that records what it is
asked, an Intel HEX reader, and an ELF's flash bytes by binutils (avr-objdump,
avr-objcopy), a way independent of orfa.ihex."""

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, Tuple

STANDIN = '''#!%(python)s
"""A stand-in avrdude: appends its arguments (one JSON list per call) to
calls.jsonl, keeps a copy of each file it is told to write to flash, and
exits with the status in the file `status` (0 without it)."""
import json, os, shutil, sys
here = os.path.dirname(os.path.abspath(__file__))
args = sys.argv[1:]
with open(os.path.join(here, "calls.jsonl"), "a") as log:
    log.write(json.dumps(args) + "\\n")
for i, arg in enumerate(args[:-1]):
    if arg == "-U" and args[i + 1].startswith("flash:w:"):
        name = args[i + 1][len("flash:w:"):].rsplit(":", 1)[0]
        n = len([f for f in os.listdir(here) if f.startswith("written-")])
        shutil.copyfile(name, os.path.join(here, "written-%%d.hex" %% n))
status_file = os.path.join(here, "status")
status = int(open(status_file).read()) if os.path.exists(status_file) else 0
print("stand-in avrdude: %%s" %% ("done" if status == 0 else "failed"),
      file=sys.stderr if status else sys.stdout)
sys.exit(status)
'''


class Avrdude:
    """A stand-in `avrdude` in its own directory (put it first on PATH)."""

    def __init__(self, directory: Path):
        self.dir = directory
        directory.mkdir(parents=True, exist_ok=True)
        self.path = directory / "avrdude"
        self.path.write_text(STANDIN % {"python": sys.executable})
        self.path.chmod(0o755)

    def fail_with(self, status: int) -> None:
        (self.dir / "status").write_text(str(status))

    def calls(self) -> List[List[str]]:
        log = self.dir / "calls.jsonl"
        if not log.exists():
            return []
        return [json.loads(line) for line in log.read_text().splitlines()]

    def written(self) -> List[Path]:
        """Copies of the files written to flash, in call order."""
        return sorted(self.dir.glob("written-*.hex"), key=lambda p: int(p.stem.split("-")[1]))

    def env(self, **extra) -> Dict[str, str]:
        """The environment with the stand-in first on PATH and none of the
        make variables set from outside."""
        env = {k: v for k, v in os.environ.items() if k not in (
            "PORT", "PROGRAMMER", "AVRDUDE", "AVRDUDE_FLAGS", "BOARD", "MODE",
            "ADDR", "BUILD", "DRIVERS", "BAUD", "MAKEFLAGS", "MFLAGS")}
        env["PATH"] = "%s%s%s" % (self.dir, os.pathsep, env.get("PATH", ""))
        env.update(extra)
        return env


def read_ihex(path: Path) -> Dict[int, int]:
    """address -> byte of an Intel HEX file; every record's checksum and
    length checked, the end record required and last."""
    image: Dict[int, int] = {}
    base = 0
    lines = path.read_text().splitlines()
    assert lines, "empty hex file"
    for n, line in enumerate(lines, 1):
        assert line.startswith(":"), "line %d: no ':'" % n
        raw = bytes.fromhex(line[1:])
        assert len(raw) == raw[0] + 5, "line %d: length field %d, %d bytes" % (n, raw[0], len(raw))
        assert sum(raw) & 0xFF == 0, "line %d: bad checksum" % n
        count, addr, rtype, data = raw[0], raw[1] << 8 | raw[2], raw[3], raw[4:-1]
        if rtype == 0:
            for i, b in enumerate(data):
                where = base + addr + i
                assert where not in image, "line %d: 0x%X written twice" % (n, where)
                image[where] = b
        elif rtype == 1:
            assert count == 0 and n == len(lines), "line %d: end record not last" % n
            return image
        elif rtype == 2:
            base = (data[0] << 8 | data[1]) << 4
        elif rtype == 4:
            base = (data[0] << 8 | data[1]) << 16
        elif rtype in (3, 5):
            pass                        # start address: nothing to write
        else:
            raise AssertionError("line %d: record type %d" % (n, rtype))
    raise AssertionError("no end record")


def elf_flash_sections(elf: Path) -> List[Tuple[str, int, int]]:
    """(name, LMA, size) of the sections avr-objdump says load into flash
    (CONTENTS, ALLOC, LOAD, below the data space at 0x800000)."""
    out = subprocess.run(["avr-objdump", "-h", str(elf)], capture_output=True,
                         text=True, check=True).stdout.splitlines()
    sections = []
    for i, line in enumerate(out):
        words = line.split()
        if len(words) >= 7 and words[0].isdigit() and i + 1 < len(out):
            name, size, lma = words[1], int(words[2], 16), int(words[4], 16)
            flags = out[i + 1]
            if all(f in flags for f in ("CONTENTS", "ALLOC", "LOAD")) and lma < 0x800000:
                sections.append((name, lma, size))
    return sections


def elf_flash_image(elf: Path, tmp: Path) -> Dict[int, int]:
    """address -> byte of the ELF's flash sections, each dumped by avr-objcopy."""
    image: Dict[int, int] = {}
    for name, lma, size in elf_flash_sections(elf):
        out = tmp / ("section%s.bin" % name.replace(".", "_"))
        subprocess.run(["avr-objcopy", "-O", "binary", "-j", name, str(elf), str(out)],
                       check=True)
        data = out.read_bytes()
        assert len(data) == size, name
        for i, b in enumerate(data):
            image[lma + i] = b
    return image
