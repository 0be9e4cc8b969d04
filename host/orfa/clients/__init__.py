"""One client per driver (board.gpio, board.servo, ...), each a thin layer
of register accesses over orfa.board.Board."""
