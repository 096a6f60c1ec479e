"""A cheap way to hand a run's arrays and generator to compiled code many times per second.

The gymnasium engine calls compiled code once per environment step. Each argument of such a
call costs time to check: a NumPy Generator about 6 microseconds (numba inspects the Python
object's ctypes interface every time), a named tuple or a tuple of arrays about a
microsecond. So what stays the same for a whole run (the agent's generator, the tables, the
algorithm's memory and parameters, the grid, gamma) goes once into this small compiled
record, and every step passes the record and a few numbers. The record refers to the same
arrays and generator: what compiled code changes through it, the Python side sees.
"""

from __future__ import annotations

from typing import Any

import numba
from numba import njit, types
from numba.experimental import structref

from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

FIELDS = ("rng", "q", "visits", "memory", "params", "grid", "gamma")
"""the record's fields, in order"""


@structref.register
class StepContextType(types.StructRef):
    """numba type of a run's step context."""

    def preprocess_fields(self, fields: Any) -> Any:
        """Store plain (non-literal) field types."""
        # numba's own functions carry no annotations: the untyped calls below are its.
        return tuple((name, types.unliteral(typ)) for name, typ in fields)  # type: ignore[no-untyped-call]


class StepContext(structref.StructRefProxy):
    """Python-side proxy of the record; create it with :func:`step_context`."""


structref.define_proxy(StepContext, StepContextType, list(FIELDS))  # type: ignore[no-untyped-call]


@njit(cache=True)
def _new(context_type: Any, rng: Any, q: Any, visits: Any, memory: Any, params: Any,
         grid: Any, gamma: float) -> Any:  # fmt: skip
    context: Any = structref.new(context_type)  # type: ignore[call-arg]
    context.rng = rng
    context.q = q
    context.visits = visits
    context.memory = memory
    context.params = params
    context.grid = grid
    context.gamma = gamma
    return context


def step_context(rng: Any, q: Any, visits: Any, memory: Any, params: Any, grid: Any,
                 gamma: float) -> StepContext:  # fmt: skip
    """The record of a run; keep ``rng`` and the arrays alive as long as it is used."""
    values = (rng, q, visits, memory, params, grid, gamma)
    fields = [
        (name, numba.typeof(value))  # type: ignore[no-untyped-call]
        for name, value in zip(FIELDS, values, strict=True)
    ]
    context_type = StepContextType(fields)  # type: ignore[no-untyped-call]
    context: StepContext = _new(context_type, *values)
    return context
