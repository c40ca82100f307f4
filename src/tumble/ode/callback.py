"""A plain Python right-hand side called from ``solve``'s compiled loops.

:func:`tumble.solve` with a Python ``fun`` (not compiled by numba) runs the same compiled
loops as with a numba one (:mod:`tumble.ode.compiled`): the stages, the error norm, the step
control, the dense output's coefficients run compiled, and only ``fun`` itself runs in
Python. The loop calls it through a C function pointer, a :mod:`ctypes` callback made here
(:class:`PythonRightHandSide`), so that for a step of dopri5 Python runs the six calls of
``fun`` and nothing else.

The exchange, for ``k = fun(t, z)``:

1. the loop writes the stage point ``z`` into :attr:`PythonRightHandSide.z`, an array of
   shape ``(n,)`` that Python holds too (the same memory), and calls the pointer with ``t``;
2. the callback runs ``out[:] = fun(t, z)`` (a list, a tuple or an array of ``n`` numbers;
   ``out`` is :attr:`PythonRightHandSide.out`, also shared) and returns 0;
3. the loop copies ``out`` into its stage ``k``.

``fun`` receives the same array ``z`` at every call, overwritten by the next: a ``fun`` that
keeps ``y`` must keep a copy (scipy's ``solve_ivp`` hands over a new array each time).

An exception raised by ``fun`` (``KeyboardInterrupt`` too) cannot cross the compiled frames:
the callback keeps it in :attr:`PythonRightHandSide.error` and returns 1, the loop makes the
stage NaN, so the step is not finite and the loop returns at once (a fixed step) or after its
tries shrink to the minimum step (an adaptive one: about twenty tries, each made of calls that
return 1 at once, ``fun`` is not called again), and :meth:`PythonRightHandSide.reraise` raises
it, unchanged, from the Python frame that called the loop.

The measured costs (``benchmarks/bench_python_rhs.py``): the callback itself, from the loop
into Python and back, 0.07 µs; copying a list of two numbers into ``out`` 0.23 µs (an array
0.16 µs); what remains is ``fun`` (Van der Pol: 0.4 µs returning a list, 0.8 µs returning a
``np.array``).
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba import types
from numba.core.errors import TypingError
from numba.extending import intrinsic

CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double)
"""The C signature the loops call: ``int callback(double t)``; 0 when ``fun`` returned."""


class Callback(NamedTuple):
    """What the compiled loops hold in the place of a compiled ``fun``: the callback's
    address, the stage point ``z`` and the result ``out`` it shares with Python."""

    address: int
    z: np.ndarray
    out: np.ndarray


@intrinsic
def call_address(typingctx, address, t):
    """``((int (*)(double)) address)(t)``: call the C function at ``address`` (an integer
    argument, not a constant: the loops are cached on disk, the address is this
    process's)."""
    if not isinstance(address, types.Integer) or not isinstance(t, types.Float):
        raise TypingError("call_address(address: int, t: float)")
    signature = types.int32(types.intp, types.float64)

    def codegen(context, builder, sig, args):
        function_type = ir.FunctionType(ir.IntType(32), [ir.DoubleType()])
        address_value = context.cast(builder, args[0], sig.args[0], types.intp)
        pointer = builder.inttoptr(address_value, function_type.as_pointer())
        return builder.call(pointer, [context.cast(builder, args[1], sig.args[1], types.float64)])

    return signature, codegen


class PythonRightHandSide:
    """``fun(t, y)`` made callable from compiled code (module docstring: the exchange).

    Parameters
    ----------
    fun : callable
        The user's right-hand side ``fun(t, y) -> sequence of n floats``.
    n : int
        The size of the state.

    Attributes
    ----------
    callback : Callback
        What the loops receive as their ``fun``.
    error : BaseException or None
        The exception ``fun`` raised, if it did (then every later call returns 1 at once).
    """

    def __init__(self, fun: Callable, n: int):
        self.fun = fun
        z, out = np.zeros(n), np.zeros(n)
        self.z, self.out = z, out
        self.error: BaseException | None = None
        failed = [False]  # a cell the closure reads: no attribute lookup per call

        def trampoline(t: float) -> int:
            if failed[0]:
                return 1
            try:
                out[:] = fun(t, z)
            except BaseException as error:  # noqa: BLE001 — raised again by reraise
                self.error, failed[0] = error, True
                return 1
            return 0

        self._c_function = CALLBACK(trampoline)  # kept alive as long as the loops may call it
        address = ctypes.cast(self._c_function, ctypes.c_void_p).value
        assert address is not None
        self.callback = Callback(int(address), z, out)

    def reraise(self) -> None:
        """Raise the exception ``fun`` raised in the loop, if any."""
        if self.error is not None:
            error, self.error = self.error, None
            raise error
