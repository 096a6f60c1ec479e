"""A compiled twin of Gymnasium's ``AcrobotEnv`` (``Acrobot-v1``), bit-identical to it.

``step`` repeats ``gymnasium.envs.classic_control.acrobot.AcrobotEnv.step`` operation by
operation: one RK4 step of ``_dsdt`` ("book" dynamics) over ``[0, dt]``, each array
operation of ``rk4`` done element by element in the same order, then ``wrap`` of the angles
and ``bound`` of the velocities. Two places need more than the same formula:

- ``x**2`` on a float64 is libm's ``pow(x, 2.0)`` in Gymnasium (NumPy scalars and Python
  floats both call it), and glibc's ``pow`` is not correctly rounded: about one square in a
  thousand differs from ``x * x`` by one ulp. LLVM rewrites ``pow(x, 2.0)`` as ``x * x``, so
  :data:`libm_pow` calls the C library's ``pow`` under a name LLVM does not know.
- ``reset`` stores the state as float32 and ``_get_ob`` then takes ``cos``/``sin`` of
  float32 numbers, which NumPy computes with its own vectorised float32 algorithm (on CPUs
  with FMA3; NumPy 2.4), not libm's ``cosf``. :func:`numpy_cos_f32` and
  :func:`numpy_sin_f32` repeat that algorithm, fused multiply-adds included. After a step the
  state is float64 and ``cos``/``sin`` are libm's, as in the twin.

The state is float64 ``(theta1, theta2, dtheta1, dtheta2)`` (after ``reset`` it holds the
float32 draws exactly); the observation is float32 ``(cos theta1, sin theta1, cos theta2,
sin theta2, dtheta1, dtheta2)``. ``reset`` draws four ``uniform(-0.1, 0.1)`` in order, as
``env.np_random.uniform(size=(4,))`` does. The registered environment has
``torque_noise_max = 0``, so a step draws nothing.

No ``gymnasium.make`` argument changes the dynamics the twin reproduces: ``params`` is
empty, and :func:`twin_params` accepts only ``max_episode_steps`` (the caller's time limit).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from llvmlite import binding, ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from cartpole_q.families.base import unsupported_key
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

MAX_EPISODE_STEPS = 500
"""the time limit ``Acrobot-v1`` is registered with"""
STATE_SIZE = 4
OBSERVATION_SIZE = 6
OBSERVATION_DTYPE = np.float32
OBSERVATION_KIND = "box"
STATE_DTYPE = np.float64
READS_ENVIRONMENT = False
N_ACTIONS = 3
PARAM_NAMES: tuple[str, ...] = ()
"""the ``gymnasium.make`` arguments in ``params`` (none)"""
SUPPORTED_KWARGS = ("max_episode_steps",)

# The class constants of AcrobotEnv and the locals of _dsdt.
DT = 0.2
LINK_LENGTH_1 = 1.0
LINK_MASS_1 = 1.0
LINK_MASS_2 = 1.0
LINK_COM_POS_1 = 0.5
LINK_COM_POS_2 = 0.5
LINK_MOI = 1.0
MAX_VEL_1 = 4 * math.pi
MAX_VEL_2 = 9 * math.pi
GRAVITY = 9.8
AVAIL_TORQUE = (-1.0, 0.0, 1.0)
RESET_LOW, RESET_HIGH = -0.1, 0.1

# The Python-float prefixes of _dsdt's products, evaluated left to right as Python does
# before the first NumPy scalar enters (m1 * lc1**2 + ...; names as in _dsdt).
_m1, _m2, _l1 = LINK_MASS_1, LINK_MASS_2, LINK_LENGTH_1
_lc1, _lc2, _I1, _I2 = LINK_COM_POS_1, LINK_COM_POS_2, LINK_MOI, LINK_MOI
D1_HEAD = _m1 * _lc1**2
D1_SQUARES = _l1**2 + _lc2**2
D1_COS = 2 * _l1 * _lc2
D2_SQUARE = _lc2**2
D2_COS = _l1 * _lc2
PHI2_COEF = _m2 * _lc2 * GRAVITY
PHI1_SQUARE_COEF = -_m2 * _l1 * _lc2
PHI1_CROSS_COEF = 2 * _m2 * _l1 * _lc2
PHI1_GRAVITY_COEF = (_m1 * _lc1 + _m2 * _l1) * GRAVITY
DDTHETA2_COEF = _m2 * _l1 * _lc2
DDTHETA2_DENOMINATOR_HEAD = _m2 * _lc2**2 + _I2
# rk4(derivs, y0, [0, dt]): dt = t[1] - t[0], dt2 = dt / 2.0, and the weight dt / 6.0.
RK4_DT = DT - 0
RK4_HALF_DT = RK4_DT / 2.0
RK4_SIXTH_DT = RK4_DT / 6.0

# NumPy 2.4's float32 sin/cos (loops_trigonometric.dispatch.cpp, simd_sincos_f32).
_f32 = np.float32
TWO_OVER_PI_F32 = _f32(float.fromhex("0x1.45f306p-1"))
CODYW_PIO2_HIGH_F32 = _f32(float.fromhex("-0x1.921fb0p+00"))
CODYW_PIO2_MED_F32 = _f32(float.fromhex("-0x1.5110b4p-22"))
CODYW_PIO2_LOW_F32 = _f32(float.fromhex("-0x1.846988p-48"))
RINT_MAGIC_F32 = _f32(float.fromhex("0x1.800000p+23"))
MAX_CODY_SIN_F32 = _f32(117435.992)
MAX_CODY_COS_F32 = _f32(71476.0625)
COS_POLY_F32 = tuple(
    _f32(float.fromhex(h))
    for h in ("0x1.98e616p-16", "-0x1.6c06dcp-10", "0x1.55553cp-05", "-0x1.000000p-01")
)
SIN_POLY_F32 = tuple(
    _f32(float.fromhex(h))
    for h in ("0x1.7d3bbcp-19", "-0x1.a06bbap-13", "0x1.11119ap-07", "-0x1.555556p-03")
)
ZERO_F32, ONE_F32 = _f32(0.0), _f32(1.0)


def twin_params(kwargs: Mapping[str, Any]) -> tuple[float, ...] | str:
    """Return ``params`` for ``gymnasium.make("Acrobot-v1", **kwargs)``, or why not.

    Returns:
        An empty tuple, or a sentence naming the first key the twin cannot
        reproduce.
    """
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    return ()


def _c_library_pow_address() -> int:
    """The address of the C library's ``pow``, the one NumPy and Python call."""
    try:
        function = ctypes.CDLL(None).pow
    except (AttributeError, OSError):  # pragma: no cover - platforms without a global libm
        function = ctypes.CDLL(ctypes.util.find_library("m")).pow
    address = ctypes.cast(function, ctypes.c_void_p).value
    assert address is not None
    return address


# Under its own name LLVM cannot recognise ``pow`` and fold ``pow(x, 2.0)`` into ``x * x``.
# The symbol is registered at import, so cached machine code finds it too.
_POW_SYMBOL = "cartpole_q_twin_libm_pow"
binding.add_symbol(_POW_SYMBOL, _c_library_pow_address())


def _libm_pow(typingctx: Any, base: Any, exponent: Any) -> Any:
    """``pow(base, exponent)`` from the C library, never rewritten by LLVM (``x * x``)."""
    signature = types.float64(types.float64, types.float64)

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        double = ir.DoubleType()
        function = cgutils.get_or_insert_function(  # type: ignore[no-untyped-call]
            builder.module, ir.FunctionType(double, [double, double]), _POW_SYMBOL
        )
        return builder.call(function, args)

    return signature, codegen


libm_pow: Any = intrinsic(_libm_pow)
"""``libm_pow(base, exponent)``, callable from compiled code"""


def _fma_f32(typingctx: Any, a: Any, b: Any, c: Any) -> Any:
    """``a * b + c`` in float32 with one rounding (``llvm.fma.f32``)."""
    signature = types.float32(types.float32, types.float32, types.float32)

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        return builder.fma(*args)

    return signature, codegen


fma_f32: Any = intrinsic(_fma_f32)
"""``fma_f32(a, b, c)`` on float32 numbers, callable from compiled code"""


@njit(cache=True, nogil=True, inline="always")
def _numpy_sincos_f32(x: np.float32, cosine: bool) -> np.float32:
    """NumPy's float32 ``sin`` (``cosine`` false) or ``cos`` of a finite float32."""
    if abs(x) > (MAX_CODY_COS_F32 if cosine else MAX_CODY_SIN_F32):
        # NumPy hands these to libm's cosf/sinf (never reached from reset's range).
        return np.cos(x) if cosine else np.sin(x)  # type: ignore[no-any-return]  # NumPy ufuncs: Any
    # NumPy's source multiplies, then adds the magic number; its compiled code fuses the two.
    quadrant = fma_f32(x, TWO_OVER_PI_F32, RINT_MAGIC_F32)
    quadrant = quadrant - RINT_MAGIC_F32
    reduced = fma_f32(quadrant, CODYW_PIO2_HIGH_F32, x)
    reduced = fma_f32(quadrant, CODYW_PIO2_MED_F32, reduced)
    reduced = fma_f32(quadrant, CODYW_PIO2_LOW_F32, reduced)
    reduced2 = reduced * reduced
    cos_value = fma_f32(COS_POLY_F32[0], reduced2, COS_POLY_F32[1])
    cos_value = fma_f32(cos_value, reduced2, COS_POLY_F32[2])
    cos_value = fma_f32(cos_value, reduced2, COS_POLY_F32[3])
    cos_value = fma_f32(cos_value, reduced2, ONE_F32)
    sin_value = fma_f32(SIN_POLY_F32[0], reduced2, SIN_POLY_F32[1])
    sin_value = fma_f32(sin_value, reduced2, SIN_POLY_F32[2])
    sin_value = fma_f32(sin_value, reduced2, SIN_POLY_F32[3])
    sin_value = fma_f32(sin_value, reduced2, ZERO_F32)
    sin_value = fma_f32(sin_value, reduced, reduced)
    quarter_turns = np.int32(quadrant) + (1 if cosine else 0)
    result = sin_value if quarter_turns & 1 == 0 else cos_value
    if quarter_turns & 2 == 2:
        result = ZERO_F32 - result
    return result  # type: ignore[no-any-return]  # fma_f32 is compiled: Any to mypy


@njit(cache=True, nogil=True, inline="always")
def numpy_cos_f32(x: np.float32) -> np.float32:
    """``np.cos`` of a float32 scalar, as NumPy 2.4 computes it on an FMA3 CPU."""
    return _numpy_sincos_f32(x, True)


@njit(cache=True, nogil=True, inline="always")
def numpy_sin_f32(x: np.float32) -> np.float32:
    """``np.sin`` of a float32 scalar, as NumPy 2.4 computes it on an FMA3 CPU."""
    return _numpy_sincos_f32(x, False)


@njit(cache=True, nogil=True, inline="always")
def _dsdt(
    theta1: float, theta2: float, dtheta1: float, dtheta2: float, torque: float
) -> tuple[float, float, float, float]:
    """``AcrobotEnv._dsdt`` ("book" dynamics) without the torque's zero derivative."""
    d1 = D1_HEAD + _m2 * (D1_SQUARES + D1_COS * np.cos(theta2)) + _I1 + _I2
    d2 = _m2 * (D2_SQUARE + D2_COS * np.cos(theta2)) + _I2
    phi2 = PHI2_COEF * np.cos(theta1 + theta2 - math.pi / 2.0)
    phi1 = (
        PHI1_SQUARE_COEF * libm_pow(dtheta2, 2.0) * np.sin(theta2)
        - PHI1_CROSS_COEF * dtheta2 * dtheta1 * np.sin(theta2)
        + PHI1_GRAVITY_COEF * np.cos(theta1 - math.pi / 2)
        + phi2
    )
    ddtheta2 = (
        torque + d2 / d1 * phi1 - DDTHETA2_COEF * libm_pow(dtheta1, 2.0) * np.sin(theta2) - phi2
    ) / (DDTHETA2_DENOMINATOR_HEAD - libm_pow(d2, 2.0) / d1)
    ddtheta1 = -(d2 * ddtheta2 + phi1) / d1
    return dtheta1, dtheta2, ddtheta1, ddtheta2


@njit(cache=True, nogil=True, inline="always")
def _wrap(x: float, low: float, high: float) -> float:
    """Gymnasium's ``wrap``: shift ``x`` by whole turns into ``[low, high]``."""
    diff = high - low
    while x > high:
        x = x - diff
    while x < low:
        x = x + diff
    return x


@njit(cache=True, nogil=True, inline="always")
def _bound(x: float, low: float, high: float) -> float:
    """Gymnasium's ``bound``: ``min(max(x, low), high)`` with Python's tie rules."""
    x = low if low > x else x
    return high if high < x else x


@njit(cache=True, nogil=True, inline="always")
def _write_observation(state: np.ndarray, observation: np.ndarray) -> None:
    """``_get_ob`` of a float64 state."""
    observation[0] = np.float32(np.cos(state[0]))
    observation[1] = np.float32(np.sin(state[0]))
    observation[2] = np.float32(np.cos(state[1]))
    observation[3] = np.float32(np.sin(state[1]))
    observation[4] = np.float32(state[2])
    observation[5] = np.float32(state[3])


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: tuple[float, ...]
) -> None:
    """Draw a start state into ``state`` and write its float32 ``observation``.

    Gymnasium keeps the start state as float32, so ``_get_ob`` takes NumPy's float32
    ``cos``/``sin`` of it.
    """
    for i in range(4):
        value = np.float32(rng.uniform(RESET_LOW, RESET_HIGH))
        state[i] = np.float64(value)
    theta1, theta2 = np.float32(state[0]), np.float32(state[1])
    observation[0] = numpy_cos_f32(theta1)
    observation[1] = numpy_sin_f32(theta1)
    observation[2] = numpy_cos_f32(theta2)
    observation[3] = numpy_sin_f32(theta2)
    observation[4] = np.float32(state[2])
    observation[5] = np.float32(state[3])


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: tuple[float, ...],
) -> tuple[float, bool]:
    """Advance ``state`` by one RK4 step in place (nothing drawn); write the observation.

    Returns:
        The reward (-1, or 0 on the step that terminates) and whether the tip rose above
        the bar. Truncation is the caller's time limit.
    """
    torque = AVAIL_TORQUE[action]
    y0, y1, y2, y3 = state[0], state[1], state[2], state[3]
    k1_0, k1_1, k1_2, k1_3 = _dsdt(y0, y1, y2, y3, torque)
    k2_0, k2_1, k2_2, k2_3 = _dsdt(
        y0 + RK4_HALF_DT * k1_0,
        y1 + RK4_HALF_DT * k1_1,
        y2 + RK4_HALF_DT * k1_2,
        y3 + RK4_HALF_DT * k1_3,
        torque,
    )
    k3_0, k3_1, k3_2, k3_3 = _dsdt(
        y0 + RK4_HALF_DT * k2_0,
        y1 + RK4_HALF_DT * k2_1,
        y2 + RK4_HALF_DT * k2_2,
        y3 + RK4_HALF_DT * k2_3,
        torque,
    )
    k4_0, k4_1, k4_2, k4_3 = _dsdt(
        y0 + RK4_DT * k3_0,
        y1 + RK4_DT * k3_1,
        y2 + RK4_DT * k3_2,
        y3 + RK4_DT * k3_3,
        torque,
    )
    # y0 + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4), element by element
    n0 = y0 + RK4_SIXTH_DT * (k1_0 + 2 * k2_0 + 2 * k3_0 + k4_0)
    n1 = y1 + RK4_SIXTH_DT * (k1_1 + 2 * k2_1 + 2 * k3_1 + k4_1)
    n2 = y2 + RK4_SIXTH_DT * (k1_2 + 2 * k2_2 + 2 * k3_2 + k4_2)
    n3 = y3 + RK4_SIXTH_DT * (k1_3 + 2 * k2_3 + 2 * k3_3 + k4_3)
    state[0] = _wrap(n0, -math.pi, math.pi)
    state[1] = _wrap(n1, -math.pi, math.pi)
    state[2] = _bound(n2, -MAX_VEL_1, MAX_VEL_1)
    state[3] = _bound(n3, -MAX_VEL_2, MAX_VEL_2)
    _write_observation(state, observation)
    terminated = -np.cos(state[0]) - np.cos(state[1] + state[0]) > 1.0
    return (0.0 if terminated else -1.0), terminated
