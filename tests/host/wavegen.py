"""Waveforms drawn here, as the simulator's pins would carry them, for the
tests of orfa.decode and of `orfa plot`'s decoded rows: a serial line's 8N1
frames and an I2C bus bit by bit. Times in CPU cycles."""

from orfa import decode, waves


def serial(data, bit, t=1000, gap=0, stop=1):
    """The edges of DATA sent 8N1 at BIT cycles a bit from cycle T, idle
    high (STOP: the stop bit's level, 0 for a framing error)."""
    edges, level, starts = [], 1, []
    for byte in data:
        starts.append(t)
        bits = [0] + [byte >> i & 1 for i in range(8)] + [stop]
        for k, b in enumerate(bits):
            if b != level:
                edges.append((int(round(t + k * bit)), b))
                level = b
        t += 10 * bit + gap
        if level == 0:
            edges.append((int(round(t - gap)), 1))   # back to idle after a bad stop bit
            level = 1
    return edges, starts


class Bus:
    """An I2C bus drawn bit by bit: a master at QUARTER cycles a quarter bit
    (100 kHz: 18), SDA changing while SCL is low."""

    def __init__(self, quarter=18, t=500):
        self.q = quarter
        self.t = t
        self.level = {"sda": 1, "scl": 1}
        self.edges = {"sda": [], "scl": []}

    def set(self, name, level, wait=None):
        if self.level[name] != level:
            self.edges[name].append((self.t, level))
            self.level[name] = level
        self.t += self.q if wait is None else wait

    def start(self):
        self.set("sda", 1)
        self.set("scl", 1)
        self.set("sda", 0)
        self.set("scl", 0)

    def bit(self, b, stretch=0):
        self.set("sda", b)
        self.t += stretch                          # a slave holds SCL low
        self.set("scl", 1, 2 * self.q)
        self.set("scl", 0)

    def byte(self, value, ack, stretch=0):
        for i in range(8):
            self.bit(value >> (7 - i) & 1, stretch if i == 0 else 0)
        self.bit(0 if ack else 1)

    def restart(self):
        self.start()

    def stop(self):
        self.set("sda", 0)
        self.set("scl", 1)
        self.set("sda", 1, 10 * self.q)

    def frames(self):
        """What orfa.decode reads on the bus drawn so far."""
        end = self.t + 100
        return decode.i2c(waves.window("sda", 1, self.edges["sda"], 0, end),
                          waves.window("scl", 1, self.edges["scl"], 0, end))
