"""board.adc: the ADC driver's RC (settings, channels) and RD (results)."""

from __future__ import annotations

from typing import Iterable, List, Optional, Tuple

#: RC settings bits 0-1, by reference name (docs/registers.md "ADC");
#: 0b11 is the internal reference too.
REFERENCES = {"aref": 0, "avcc": 1, "internal": 2}
#: Volts of the references the board knows (AREF is the user's pin).
VREF = {"avcc": 5.0, "internal": 2.56}
_BITS10 = 0x04
CHANNELS = 8


class Adc:
    def __init__(self, board):
        self.board = board

    def configure(self, channels: Iterable[int] = range(CHANNELS), reference: str = "avcc",
                  bits: int = 10) -> None:
        """Enable `channels` (0-7 of the ADC port) with a reference and a
        resolution (8 or 10 bits): one 2-byte write of RC."""
        if reference not in REFERENCES:
            raise ValueError("reference %r: one of %s" % (reference, ", ".join(REFERENCES)))
        if bits not in (8, 10):
            raise ValueError("bits must be 8 or 10, not %r" % (bits,))
        mask = 0
        for ch in channels:
            if not isinstance(ch, int) or not 0 <= ch < CHANNELS:
                raise ValueError("ADC channel %r: channels are 0..%d" % (ch, CHANNELS - 1))
            mask |= 1 << ch
        settings = REFERENCES[reference] | (_BITS10 if bits == 10 else 0)
        self.board.write("adc", "RC", [settings, mask])

    @staticmethod
    def _decode_config(data: bytes) -> Tuple[str, int, Tuple[int, ...]]:
        settings, mask = data[0], data[1]
        ref = settings & 0x03
        name = "internal" if ref >= REFERENCES["internal"] else \
            next(k for k, v in REFERENCES.items() if v == ref)
        return name, 10 if settings & _BITS10 else 8, \
            tuple(ch for ch in range(CHANNELS) if mask >> ch & 1)

    def config(self) -> Tuple[str, int, Tuple[int, ...]]:
        """(reference, bits, enabled channels) as RC reads back."""
        return self._decode_config(self.board.read("adc", "RC", 2))

    def _sample(self):
        b = self.board
        (rc, rd), = b.execute([[b.op_read("adc", "RC", 2), b.op_read("adc", "RD", 2 * CHANNELS)]])
        ref, bits, _ = self._decode_config(rc)
        if bits == 10:
            raw = [rd[i] << 8 | rd[i + 1] for i in range(0, 2 * CHANNELS, 2)]
        else:
            raw = list(rd[:CHANNELS])
        return ref, bits, raw

    def read(self) -> List[int]:
        """The 8 channels' raw results (channels not enabled: 0): RC and RD
        read in one request, so the resolution always matches."""
        return self._sample()[2]

    def volts(self, vref: Optional[float] = None) -> List[float]:
        """The 8 channels in volts: raw * vref / 1024 (10 bits) or / 256;
        vref defaults to the reference's (AVCC 5.0 V, internal 2.56 V);
        with AREF give it."""
        ref, bits, raw = self._sample()
        if vref is None:
            if ref not in VREF:
                raise ValueError("the ADC uses the AREF pin: give its voltage (vref=...)")
            vref = VREF[ref]
        full = 1 << bits
        return [r * vref / full for r in raw]
