"""Compiling plain functions with numba: the algorithms' hooks and the helpers they call.

The algorithms (:mod:`cartpole_q.rl`) are plain Python, so that configs, docs and doctests
use them without numba. Here they are compiled: :func:`jit` gives a numba dispatcher of a
function whose global names that refer to other plain functions marked
:func:`~cartpole_q.rl.tabular.compilable` (or already compiled) now refer to their compiled
versions, recursively. The function's own module is left untouched.

:func:`specialise` builds the compiled loops (:mod:`cartpole_q.engines.kernel`) the same way:
one template function, its placeholder globals (``ALGORITHM_STEP``, ``TWIN_STEP``) bound to
one algorithm's and one twin's compiled functions, cached on disk under a name that says
which. numba's cache key holds a function's bytecode and closure, not its globals, so the
name (with the algorithm's and twin's source digests in it) keeps the variants apart.

On tile-coded tables (``tiled=True``) every compilable helper that has a tiles variant
(:func:`~cartpole_q.rl.tabular.tiles_variant`: ``value``, ``shift``, the trace functions) is
replaced by it, recursively, so the same hooks run on tiles; a variant that calls its own
original gets the original (it applies it to the weights). Under sample averages
(``averaged=True``, ``agent.alpha: sample_average``) every helper that has an averaged
variant (:func:`~cartpole_q.rl.tabular.averaged_variant`: ``update``) is replaced by it the
same way. Validation never lets the two meet (sample averages are refused on tiles).
"""

from __future__ import annotations

import contextlib
import copy
import inspect
import types
from collections.abc import Callable, Iterator, Mapping
from typing import Any

from numba import njit
from numba.core.dispatcher import Dispatcher

import cartpole_q.rl.tiles  # noqa: F401  (registers the tiles variants before any compile)
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

_COMPILED: dict[tuple[Callable[..., Any], bool, bool], Dispatcher] = {}


_KEEPS_FRONT_END = "__cartpole_q_keeps_front_end__"
"""the attribute that marks a function this module built (see :func:`reuse_inlined_front_ends`)"""

_FRONT_ENDS: dict[tuple[Any, ...], Any] = {}
"""the untyped IR of each function inlined so far: (function, flags) -> IR"""


def reuse_inlined_front_ends() -> None:
    """Make numba run an inlined function's front end once per process, not once per call.

    At every call of an ``inline="always"`` function, numba translates the callee's bytecode
    and runs its untyped passes again, its own inlined callees included, recursively
    (``InlineWorker.inline_function`` calls ``run_untyped_passes``): a quarter of the
    compile time of the training loops, whose hooks call the same helpers many times. What
    those passes give depends only on the function and the compile flags, so the first
    result is kept (in :data:`_FRONT_ENDS`) and each later call inlines it through numba's
    own ``inline_ir``, which copies the callee's blocks before it changes them (the kept
    IR stays as it was: no deep copy of ours is needed). Each call gets its own function
    identity, as numba gives each call, so the inlined variables are named apart. The
    machine code is the same: the golden hashes and the plain re-derivation check it.

    Only this module's compiled functions are kept (:func:`jit` and :func:`specialise` mark
    them): their globals are a namespace of their own, fixed when they are built, and none
    is a closure, so their IR depends on nothing else. Every other inlined function (numba's
    own, a plug-in's) goes through numba's front end as before.

    Idempotent. Where numba's methods do not take the arguments they took when this was
    written (numba 0.68), nothing is changed and compiling only takes longer.
    """
    from numba.core.inline_closurecall import InlineWorker

    original = getattr(InlineWorker, "inline_function", None)
    if original is None or getattr(original, "__reuses_front_ends__", False):
        return
    expected = {
        "inline_function": ["self", "caller_ir", "block", "i", "function", "arg_typs"],
        "run_untyped_passes": ["self", "func", "enable_ssa"],
        "inline_ir": ["self", "caller_ir", "block", "i", "callee_ir", "callee_freevars", "arg_typs"],
    }  # fmt: skip
    for name, parameters in expected.items():
        method = getattr(InlineWorker, name, None)
        if method is None or list(inspect.signature(method).parameters) != parameters:
            return
    from numba.core.ir import Scope

    if "__deepcopy__" in vars(Scope):  # (numba copies scopes its own way: left to it)
        return

    def inline_function(
        self: Any, caller_ir: Any, block: Any, i: int, function: Any, arg_typs: Any = None
    ) -> Any:
        if not getattr(function, _KEEPS_FRONT_END, False) or function.__closure__ is not None:
            return original(self, caller_ir, block, i, function, arg_typs)
        flags = self.flags.copy()
        flags.enable_ssa = False  # (numba's run_untyped_passes sets it; not a caller's flag)
        key = (function, flags)
        kept = _FRONT_ENDS.get(key)
        if kept is None:
            kept = _FRONT_ENDS[key] = self.run_untyped_passes(function)
        else:
            self.flags.enable_ssa = False  # as numba's run_untyped_passes leaves the flags
        callee = kept.copy()  # the kept blocks: inline_ir copies them before changing them
        callee.func_id = kept.func_id.derive()  # a new unique name, as each call gets
        freevars = function.__code__.co_freevars
        with _one_scope_per_copy():
            return self.inline_ir(caller_ir, block, i, callee, freevars, arg_typs=arg_typs)

    inline_function.__reuses_front_ends__ = True  # type: ignore[attr-defined]
    InlineWorker.inline_function = inline_function  # type: ignore[method-assign]


@contextlib.contextmanager
def _one_scope_per_copy() -> Iterator[None]:
    """While inlining: a deep copy of a function's blocks copies their scope once, not per block.

    numba's ``inline_ir`` copies the callee's IR block by block, each ``copy.deepcopy``
    on its own, so every block copies the scope again, all its variables with it: blocks
    times variables (the n-step tree backup's ``step``: 72 blocks of 1,039 variables).
    Within one inlining, a scope is copied once and the other blocks share that copy, as
    the original blocks share the original scope (numba kept one of the equal copies
    anyway: the callee must have one scope).
    """
    from numba.core.ir import Scope

    copies: dict[int, Any] = {}

    def copied_once(scope: Any, memo: dict[int, Any]) -> Any:
        found = copies.get(id(scope))
        if found is None:
            found = copies[id(scope)] = memo[id(scope)] = Scope.__new__(Scope)
            found.__dict__.update(copy.deepcopy(scope.__dict__, memo))
        return found

    before = vars(Scope).get("__deepcopy__")
    Scope.__deepcopy__ = copied_once  # type: ignore[attr-defined]
    try:
        yield
    finally:
        if before is None:
            del Scope.__deepcopy__  # type: ignore[attr-defined]
        else:
            Scope.__deepcopy__ = before  # type: ignore[attr-defined]


reuse_inlined_front_ends()


def is_compilable(value: Any) -> bool:
    """Whether ``value`` is a plain function marked for compilation."""
    return isinstance(value, types.FunctionType) and bool(getattr(value, "__compilable__", False))


def jit(function: Callable[..., Any], tiled: bool = False, averaged: bool = False) -> Dispatcher:
    """``function`` compiled (inlined where compiled code calls it), its helpers compiled too.

    Compiled once per process (and per ``tiled`` and ``averaged``: for tile-coded tables
    and for sample averages, see the module docstring); numba compiles it for each argument
    types on first use.
    """
    if isinstance(function, Dispatcher):
        return function
    found = _COMPILED.get((function, tiled, averaged))
    if found is not None:
        return found
    assert isinstance(function, types.FunctionType), function
    namespace = _compiled_globals(function, tiled, averaged)
    rebuilt = types.FunctionType(
        function.__code__, namespace, function.__name__, function.__defaults__,
        function.__closure__,
    )  # fmt: skip
    rebuilt.__qualname__ = function.__qualname__
    rebuilt.__module__ = function.__module__
    rebuilt.__doc__ = function.__doc__
    setattr(rebuilt, _KEEPS_FRONT_END, True)
    dispatcher = njit(nogil=True, inline="always")(rebuilt)
    _COMPILED[(function, tiled, averaged)] = dispatcher
    return dispatcher


def _compiled_globals(
    function: types.FunctionType, tiled: bool = False, averaged: bool = False
) -> dict[str, Any]:
    """The function's globals, the compilable functions it names replaced by compiled ones.

    With ``tiled`` (``averaged``), by their tiles (averaged) variants where they have one
    (but a variant's own original stays the original, compiled for plain tables).
    """
    namespace = dict(function.__globals__)
    for name in _global_names(function.__code__):
        value = namespace.get(name)
        if isinstance(value, types.FunctionType) and is_compilable(value):
            variant = None
            if tiled:
                variant = getattr(value, "__tiled__", None)
            elif averaged:
                variant = getattr(value, "__averaged__", None)
            if variant is function:
                namespace[name] = jit(value)
            else:
                namespace[name] = jit(variant or value, tiled, averaged)
    return namespace


def _global_names(code: types.CodeType) -> set[str]:
    """Every name a code object (and the code objects nested in it) may look up globally."""
    names = set(code.co_names)
    for constant in code.co_consts:
        if isinstance(constant, types.CodeType):
            names |= _global_names(constant)
    return names


def specialise(
    template: Callable[..., Any],
    name: str,
    bindings: Mapping[str, Any],
    *,
    inline: bool = False,
    callee: bool = False,
    tiled: bool = False,
    averaged: bool = False,
) -> Dispatcher:
    """A compiled copy of ``template`` whose placeholder globals are ``bindings``.

    Args:
        template: a function of :mod:`cartpole_q.engines.kernel` (or alike) that calls its
            placeholders by global name (and compilable helpers, compiled as :func:`jit`
            does).
        name: a name unique to the bindings (it names the on-disk cache entry).
        bindings: placeholder name -> a compiled function, or a plain one (compiled here,
            as :func:`jit` does: an algorithm's hooks).
        inline: inline the copy where compiled code calls it (then it is not cached by
            itself: its callers' cache entries hold it).
        callee: only compiled code calls the copy (an episode loop): it is compiled without
            the wrapper that lets Python call it, whose unboxing of every argument costs
            about a tenth of a training pair's compile; called from Python, it fails.
        tiled: compile for tile-coded tables (see the module docstring); ``name`` must say so.
        averaged: compile for sample averages (see the module docstring); ``name`` must say so.
    """
    assert isinstance(template, types.FunctionType)
    namespace = _compiled_globals(template, tiled, averaged)
    namespace.update({
        key: jit(value, tiled, averaged) if isinstance(value, types.FunctionType) else value
        for key, value in bindings.items()
    })  # fmt: skip
    function = types.FunctionType(
        template.__code__, namespace, name, template.__defaults__, template.__closure__
    )
    function.__qualname__ = name
    function.__module__ = template.__module__
    function.__doc__ = template.__doc__
    setattr(function, _KEEPS_FRONT_END, True)
    if inline:
        return njit(nogil=True, inline="always")(function)
    # No C-callable wrapper either: nothing takes these functions' addresses. (numba's
    # stubs do not list these two options of its CPU target.)
    wrappers: dict[str, Any] = {"no_cfunc_wrapper": True, "no_cpython_wrapper": callee}
    compiled: Dispatcher = njit(nogil=True, cache=True, **wrappers)(function)
    return compiled


class LoopSet:
    """A study engine's compiled loops by their cache names, each compiled once per process.

    Args:
        templates: cache name -> the plain function compiled under it (no placeholders).
        notice: what to say before the first run on a machine compiles them.
    """

    def __init__(self, templates: Mapping[str, Callable[..., Any]], notice: str) -> None:
        self.templates = dict(templates)
        self._notice = notice
        self._compiled: dict[str, Any] = {}

    def __call__(self, name: str) -> Any:
        """The compiled function cached on disk under ``name`` (once per process)."""
        if name not in self._compiled:
            self._compiled[name] = specialise(self.templates[name], name, {})
        return self._compiled[name]

    def notice(self) -> str | None:
        """The notice when some loop is not in numba's cache yet (the first run), else ``None``."""
        from cartpole_q.numba_cache import is_cached

        if all(is_cached(name) for name in self.templates):
            return None
        return self._notice
