"""Closing: what makes an object with a close() a context manager (a
Gateway, a Board, a SimControl): `with X(...) as x:` closes it at the end."""

from __future__ import annotations


class Closing:
    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
