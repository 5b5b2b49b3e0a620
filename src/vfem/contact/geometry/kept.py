"""What the contact geometry derives from arrays and asks for again: the last few answers, found
by their arguments compared exactly (issue 40).

A pair's set-up, the candidate search and the invariants ask the same questions of the same
surface many times over (a facet set's search trees, a body mesh's simplices at each sampled
load factor, a pair's facing patches): :class:`Kept` holds the last few answers and hands one
back when every argument is the same — arrays equal entry for entry (the arguments are copied
when kept, so a caller changing its array later cannot make a stale answer match), anything
else the same object. Nothing is approximated: a miss recomputes.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)
                and a.shape == b.shape and np.array_equal(a, b))
    if isinstance(a, int) and isinstance(b, int):
        return a == b
    return a is b


class Kept:
    """The last ``size`` answers of ``make()`` by their arguments ``key`` (a tuple of arrays,
    None, integers (equal) or other objects (the same one): :func:`_same`)."""

    def __init__(self, size: int):
        self.size = size
        self.entries: list[tuple[tuple, object]] = []

    def get(self, key: tuple, make: Callable[[], object], keep: bool = True):
        """The answer kept for ``key``, or ``make()`` (kept if ``keep``)."""
        for args, value in self.entries:
            if len(args) == len(key) and all(_same(a, b) for a, b in zip(args, key)):
                return value
        value = make()
        if keep:
            self.entries.append((tuple(np.array(a, copy=True) if isinstance(a, np.ndarray)
                                       else a for a in key), value))
            del self.entries[:-self.size]
        return value

    def clear(self) -> None:
        """Let go of every answer kept."""
        self.entries.clear()
