"""How cartpole_q.engines.compile compiles: an inlined helper's front end is run once.

numba inlines a ``compilable`` helper at every call; ``reuse_inlined_front_ends`` keeps the
untyped IR of each helper the first time and hands it to numba's ``inline_ir`` at later
calls, which copies it (each scope once). The machine code it leads to is checked
elsewhere, byte for byte (the golden hashes, the plain re-derivation); here, that the IR is
kept once per helper (and only for the functions ``compile`` built), that every call still
computes its own values, and that a copy made while inlining copies a scope once.
"""

from __future__ import annotations

import copy

from numba import njit
from numba.core import ir
from numba.core.inline_closurecall import InlineWorker

from cartpole_q.engines import compile as engine_compile
from cartpole_q.engines.compile import jit
from cartpole_q.rl.tabular import compilable


@compilable
def doubled(x: float) -> float:
    """A helper that callers inline."""
    return x * 2.0


@compilable
def three_calls(x: float) -> float:
    """Inlines ``doubled`` three times, at different arguments."""
    return doubled(x) + doubled(x + 1.0) + doubled(x + 2.0)


@compilable
def two_more_calls(x: float) -> float:
    """Inlines ``doubled`` twice more, in another compiled function."""
    return doubled(x) - doubled(1.0)


@njit(inline="always")
def tripled(x: float) -> float:
    """An inlined function this project did not build: numba's front end as before."""
    return x * 3.0


@njit
def tripled_twice(x: float) -> float:
    return tripled(x) + tripled(1.0)


def _kept_for(function: object) -> list[tuple[object, ...]]:
    return [key for key in engine_compile._FRONT_ENDS if key[0] is function]


def test_an_inlined_helper_is_translated_once_however_many_calls_inline_it() -> None:
    assert getattr(InlineWorker.inline_function, "__reuses_front_ends__", False)
    helper = jit(doubled).py_func
    assert three_calls(1.0) == 12.0 and two_more_calls(3.0) == 4.0  # as plain Python
    assert jit(three_calls)(1.0) == 12.0  # 2 + 4 + 6: each call its own argument
    assert len(_kept_for(helper)) == 1
    assert jit(two_more_calls)(3.0) == 4.0  # a later function reuses the kept IR intact
    assert len(_kept_for(helper)) == 1


def test_only_the_functions_this_module_built_are_kept() -> None:
    """Another function's IR may depend on what it reads when translated: not kept."""
    assert tripled_twice(2.0) == 9.0
    assert _kept_for(tripled.py_func) == []


def test_reusing_is_set_up_once() -> None:
    patched = InlineWorker.inline_function
    engine_compile.reuse_inlined_front_ends()
    assert InlineWorker.inline_function is patched


def test_while_inlining_a_functions_blocks_share_one_copy_of_their_scope() -> None:
    """numba copies a callee block by block; each copied its scope, every variable in it."""
    loc = ir.Loc("f.py", 1)
    scope = ir.Scope(None, loc)
    scope.define("x", loc)
    blocks = [ir.Block(scope, loc) for _ in range(3)]
    with engine_compile._one_scope_per_copy():
        copies = [copy.deepcopy(block) for block in blocks]
    (shared,) = {id(block.scope) for block in copies}
    assert shared != id(scope)
    assert copies[0].scope.get_exact("x").name == "x"
    assert copies[0].scope.get_exact("x").scope is copies[0].scope
    assert not hasattr(ir.Scope, "__deepcopy__")  # only while inlining
    assert len({id(copy.deepcopy(block).scope) for block in blocks}) == 3  # numba's own


def test_compile_all_fills_the_cache_with_the_studies_loops_too() -> None:
    """Issue 47 item 11: compile --all left the bandit, trajectory and Example 8.4 loops."""
    from cartpole_q.experiments.compiling import STUDY, STUDY_LOOPS, _compile, jobs_for
    from cartpole_q.experiments.workers import InProcess
    from cartpole_q.progress import NullReporter

    jobs = [job for job in jobs_for(None, True) if job.engine == STUDY]
    assert {job.algorithm for job in jobs} == set(STUDY_LOOPS)
    assert {"bandit_numba", "bandit_gymnasium"} <= set(STUDY_LOOPS)
    job = next(job for job in jobs if job.algorithm == "bandit_numba")
    line = _compile(InProcess(None, NullReporter()), job, None)
    assert line == "compiled bandit_numba (the bandit testbed, a study's loop)"
