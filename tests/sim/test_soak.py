"""The differential soak, short: seeded random requests (valid and invalid;
local, EEPROM, slave and absent addresses) pipelined within the flow rule
(docs/protocol.md, "Flow") against an M32-D gateway with an EEPROM and an M128-S slave; every reply must
equal the reference model's (spec_model.py). The long run is `make soak`
(tools/soak.py); docs/testing.md has its figures."""

from conftest import require_builds, require_slave
from soak import run_soak

SEED = 8
REQUESTS = 3000


def test_soak_short():
    require_builds(["m32d"])
    require_slave("m128s", 0x10)
    fig = run_soak(REQUESTS, SEED, log=lambda s: None, check_every=1000)
    print(fig.report())
    assert fig.requests == REQUESTS
    assert fig.reset_checked              # both RESET registers read 00 at the end
    assert fig.replies + fig.no_reply == REQUESTS + fig.sync_requests
    # the mix reaches every error code the robot can give
    assert set(fig.errors) == {"ERROR %02X" % c for c in (2, 3, 4, 5, 6, 7)}, fig.errors
