"""A cheap way to hand a NumPy Generator to compiled code many times per second.

Passing a ``np.random.Generator`` to a numba function costs about 6 microseconds per call
(numba inspects the Python object's ctypes interface every time): more than one
CartPole step. The gymnasium engine calls the agent once per step, so it wraps its
generator once in this small compiled record and passes the record instead (about half a
microsecond). The record shares the generator's state: draws made through it advance the
Python generator exactly as direct draws would.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
from numba import njit, types
from numba.experimental import structref

from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined


@structref.register
class GeneratorHandleType(types.StructRef):
    """numba type of a record holding one NumPy Generator."""

    def preprocess_fields(self, fields):
        """Store plain (non-literal) field types."""
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class GeneratorHandle(structref.StructRefProxy):
    """Python-side proxy of the record; create it with :func:`wrap_generator`."""


structref.define_proxy(GeneratorHandle, GeneratorHandleType, ["rng"])

_HANDLE_TYPE = GeneratorHandleType([("rng", numba.typeof(np.random.default_rng(0)))])


@njit(cache=True)
def _wrap(rng: np.random.Generator) -> GeneratorHandle:
    handle: Any = structref.new(_HANDLE_TYPE)  # type: ignore[call-arg]
    handle.rng = rng
    return handle


def wrap_generator(rng: np.random.Generator) -> GeneratorHandle:
    """Wrap ``rng``; keep ``rng`` alive as long as the handle is used."""
    return _wrap(rng)
