"""Where per-body work runs: in order in this process (:data:`SERIAL`), or each body on the MPI
rank that owns it (:class:`vfem.parallel.Ranks`, whose ``map`` is the same call).

The contact formulations are handed one (their ``executor``) by whoever builds them instead of
fetching the run's ranks themselves, so that contact does not depend on the MPI layer above it
(issue 38); without one they run serially.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Protocol

import numpy as np


class Executor(Protocol):
    #: how many processes share the work (owners run from 0 to size - 1)
    size: int

    def map(self, indices: Iterable[int], compute: Callable[[int], object],
            owners: list[int] | None = None) -> dict:
        """``compute(i)`` for every ``i`` of ``indices`` (each body's work on its owner, or on
        ``owners[i]``), every value to every caller, keyed by ``i``."""

    def total(self, indices: Iterable[int], compute: Callable[[int], np.ndarray],
              shape: tuple[int, ...]) -> np.ndarray:
        """The sum of ``compute(i)`` (arrays of ``shape``, or 0 for nothing to add) over
        ``indices``, each on its owner; the sum, the same numbers, to every caller (what each
        body adds to a shared matrix, without sending any body's part to every rank)."""


class Serial:
    """Every body in this process, in order."""

    size = 1

    def map(self, indices: Iterable[int], compute: Callable[[int], object],
            owners: list[int] | None = None) -> dict:
        return {i: compute(i) for i in indices}

    def total(self, indices: Iterable[int], compute: Callable[[int], np.ndarray],
              shape: tuple[int, ...]) -> np.ndarray:
        out = np.zeros(shape)
        for i in indices:
            out += compute(i)
        return out


#: the executor of a serial run (and of formulations built without one)
SERIAL = Serial()
