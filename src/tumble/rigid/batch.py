"""``simulate_batch``: many bodies (or many initial states of one body) in compiled calls.

The batch is one stepper of the driver (:class:`BatchStepper`, a stepper of many members:
:func:`~tumble.ode.driver.march` keeps each body's status, message, steps and last finite
state, ``Outcome.members``), marched in blocks of steps that end on recorded steps. Body
``k`` of a batch has, bit for bit, the numbers of :func:`~tumble.rigid.simulate` run
alone with body ``k``'s arguments. The ``lie`` and ``quat`` methods (``rkmk4``, ``rk4-quat``,
…) run batches of at least :data:`SOA_MIN_BODIES` bodies in the structure-of-arrays loops of
:mod:`tumble.rigid.soa` (bodies as columns, vectorised, the one-body loop's numbers bit for
bit); the other methods, and smaller batches, run the one-body loop of
:mod:`tumble.rigid._compiled` once per body, one body per thread (numba ``prange``). The
initial states are checked and built for all bodies at once with NumPy (the same operations
``simulate`` applies to one body).
"""

from __future__ import annotations

import itertools
import json
import operator
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks, so3
from tumble._progress import announce_compilation, progress_bar
from tumble.ode.contract import UNCONVERGED
from tumble.ode.driver import Block, Compiled, Grid, Status, Stepper, Stops, march
from tumble.rigid import initial, overflow
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import (
    Impulse,
    Load,
    State,
    compiled_loads,
    for_body,
    potential_energy,
    split_loads,
)
from tumble.rigid.methods import FAMILIES, METHODS, Method, get_method
from tumble.rigid.simulation import check_free, problem
from tumble.rigid.steppers import unconverged_message
from tumble.rigid.trajectory import Trajectory

FIXED_METHODS = [name for name, method in METHODS.items() if not method.adaptive]
"""The methods ``simulate_batch`` runs (every fixed-step method)."""


@dataclass
class BatchTrajectory:
    """The trajectories of ``N`` bodies on one time grid; ``batch[k]`` is body ``k``'s.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times (s), shared by every body.
    x, v : ndarray, shape (N, n, 3)
        Centre of mass (m) and its velocity (m/s), world frame.
    R : ndarray, shape (N, n, 3, 3)
        Attitude, body to world.
    L_world : ndarray, shape (N, n, 3)
        Angular momentum about the centre of mass, world frame (kg m²/s).
    bodies : tuple of RigidBody
        Body ``k`` of the batch (the same object ``N`` times when one body was given).
    method : str
        The method's name.
    settings : dict
        ``h``, ``record_every``, as :class:`~tumble.rigid.trajectory.Trajectory`'s.
    status : ndarray of int, shape (N,)
        Per body, a :class:`~tumble.ode.driver.Status` code.
        0: reached ``t_end``; -1: stopped by a non-finite state. A stopped body ends, as in
        :func:`~tumble.rigid.simulate`, with its last finite state (at ``t_last``); its rows
        after that one are NaN.
    messages : list of str
        What happened to each body.
    n_steps : ndarray of int, shape (N,)
        Steps taken by each body.
    n_recorded : ndarray of int, shape (N,)
        How many samples of each body are valid (all ``n`` unless it stopped early).
    q_raw : ndarray, shape (N, n, 4), optional
        The quaternions the ``quat`` method carried.
    potential_energy : ndarray, shape (N, n), optional
        ``V`` of the loads that have a potential, J (zeros if None).
    t_last : ndarray, shape (N,), optional
        Time (s) of each body's last valid sample, row ``n_recorded[k] - 1``: ``t_end``, or
        for a stopped body the time of its last finite state, which lies between two times
        of ``t`` when ``record_every > 1``. None: every sample lies on ``t``.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    R: np.ndarray
    L_world: np.ndarray
    bodies: tuple[RigidBody, ...]
    method: str
    settings: dict = field(default_factory=dict)
    status: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    messages: list[str] = field(default_factory=list)
    n_steps: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    n_recorded: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    q_raw: np.ndarray | None = None
    t_last: np.ndarray | None = None
    potential_energy: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.potential_energy is None:
            self.potential_energy = np.zeros(self.x.shape[:2])

    def __len__(self) -> int:
        return len(self.bodies)

    def __getitem__(self, k: int) -> Trajectory:
        """Body ``k``'s :class:`~tumble.rigid.trajectory.Trajectory` (its valid samples)."""
        k = range(len(self))[k]  # negative indices; IndexError out of range
        n = int(self.n_recorded[k])
        t = self.t[:n]
        if self.t_last is not None and t[-1] != self.t_last[k]:  # stopped between samples
            t = np.append(t[:-1], self.t_last[k])
        return Trajectory(
            t=t,
            x=self.x[k, :n],
            v=self.v[k, :n],
            R=self.R[k, :n],
            L_world=self.L_world[k, :n],
            body=self.bodies[k],
            method=self.method,
            settings=dict(self.settings),
            status=Status(int(self.status[k])),
            message=self.messages[k],
            n_steps=int(self.n_steps[k]),
            q_raw=None if self.q_raw is None else self.q_raw[k, :n],
            potential_energy=self.potential_energy[k, :n],
        )

    @property
    def success(self) -> np.ndarray:
        """Per body: True unless it stopped on a non-finite state, shape (N,)."""
        return self.status >= 0

    @cached_property
    def _inverse_inertia(self) -> np.ndarray:
        return _per_body(self.bodies, lambda body: body.inertia_inverse)

    @cached_property
    def q(self) -> np.ndarray:
        """Unit quaternions ``[w, x, y, z]`` with ``w ≥ 0``, shape (N, n, 4)."""
        if self.q_raw is not None:
            with np.errstate(invalid="ignore", over="ignore"):
                q = self.q_raw / np.linalg.norm(self.q_raw, axis=-1, keepdims=True)
        else:
            with np.errstate(invalid="ignore"):
                U, _, Vt = np.linalg.svd(np.nan_to_num(self.R))  # nearest rotation
                q = so3.quat_from_matrix(U @ Vt)
            q[~np.isfinite(self.R).all(axis=(-1, -2))] = np.nan
        return np.where(q[..., :1] < 0, -q, q)

    @cached_property
    def omega_body(self) -> np.ndarray:
        """Body-frame angular velocity ``ω = I⁻¹ Rᵀ L``, shape (N, n, 3), rad/s."""
        with np.errstate(over="ignore", invalid="ignore"):
            body_L = np.einsum("knji,knj->kni", self.R, self.L_world)
            return body_L @ self._inverse_inertia.swapaxes(-1, -2)

    @cached_property
    def kinetic_energy(self) -> np.ndarray:
        """Kinetic energy ``½ m |v|² + ½ ω·(Rᵀ L)``, shape (N, n), J."""
        mass = _per_body(self.bodies, lambda body: body.mass)[:, None]
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged body: inf, no warning
            body_L = np.einsum("knji,knj->kni", self.R, self.L_world)
            rotational = 0.5 * np.einsum("kni,kni->kn", self.omega_body, body_L)
            return 0.5 * mass * np.einsum("kni,kni->kn", self.v, self.v) + rotational

    @cached_property
    def energy(self) -> np.ndarray:
        """Total energy ``T + V``, shape (N, n), J (as :attr:`Trajectory.energy
        <tumble.rigid.trajectory.Trajectory.energy>`)."""
        with np.errstate(over="ignore", invalid="ignore"):
            return self.kinetic_energy + self.potential_energy

    @cached_property
    def orthogonality_error(self) -> np.ndarray:
        """``‖RᵀR − I‖_F`` at each sample, shape (N, n)."""
        with np.errstate(over="ignore", invalid="ignore"):
            defect = np.einsum("knai,knaj->knij", self.R, self.R) - np.eye(3)
            return np.linalg.norm(defect, axis=(-2, -1))

    def to_xarray(self):
        """An ``xarray.Dataset`` with dimensions ``(body, time, …)``.

        The variables, units and attributes of :meth:`Trajectory.to_xarray
        <tumble.rigid.trajectory.Trajectory.to_xarray>` with a leading ``body`` dimension, and
        per body ``mass``, ``inertia``, ``status`` and ``message``.
        """
        return batch_dataset(self)


def batch_dataset(batch: BatchTrajectory):
    """Build :meth:`BatchTrajectory.to_xarray`'s dataset (the single-body layout + ``body``)."""
    import xarray as xr

    template = batch[0].to_xarray()  # names, dimensions, units and run attributes
    data_vars = {
        name: xr.Variable(("body", *var.dims), getattr(batch, name), attrs=var.attrs)
        for name, var in template.data_vars.items()
    }
    data_vars["mass"] = xr.Variable("body", [b.mass for b in batch.bodies], {"units": "kg"})
    inertia = np.array([b.inertia for b in batch.bodies])
    data_vars["inertia"] = xr.Variable(("body", "row", "col"), inertia, {"units": "kg m2"})
    data_vars["status"] = xr.Variable("body", batch.status)
    if batch.t_last is not None:
        description = "time of the body's last valid sample (its last finite state if stopped)"
        data_vars["t_last"] = xr.Variable(
            "body", batch.t_last, {"units": "s", "description": description}
        )
    data_vars["message"] = xr.Variable("body", np.array(batch.messages, dtype=str))
    attrs = {k: v for k, v in template.attrs.items() if k not in ("mass", "inertia", "status")}
    attrs.pop("message", None)
    attrs["settings"] = json.dumps({k: v for k, v in batch.settings.items() if v is not None})
    coords = {name: template.coords[name] for name in template.coords}
    coords["time"] = ("time", batch.t, {"units": "s"})
    coords["body"] = np.arange(len(batch))
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _per_body(bodies, value_of) -> np.ndarray:
    """``value_of(body)`` for every body of the batch, evaluated once per distinct body.

    Returned C-contiguous and read-only: the type the kernels take for a single body's data.
    """
    if all(map(operator.is_, bodies, itertools.repeat(bodies[0]))):  # one body: C loops only
        value = np.asarray(value_of(bodies[0]), dtype=float)
        stacked = np.broadcast_to(value, (len(bodies), *value.shape)).copy()
    else:
        keys = list(map(id, bodies))
        distinct = dict(zip(keys, bodies, strict=True))
        values = {key: np.asarray(value_of(body), dtype=float) for key, body in distinct.items()}
        stacked = np.array([values[key] for key in keys])
    stacked.setflags(write=False)
    return stacked


def _bodies(body_or_bodies) -> tuple[list[RigidBody], bool]:
    """The list of bodies and whether one body was given (to broadcast)."""
    if isinstance(body_or_bodies, RigidBody):
        return [body_or_bodies], True
    if not isinstance(body_or_bodies, Sequence) or len(body_or_bodies) == 0:
        raise _checks.fail(
            "body_or_bodies", body_or_bodies, "a tumble.RigidBody or a non-empty sequence of them"
        )
    for index, body in enumerate(body_or_bodies):
        if not isinstance(body, RigidBody):
            raise _checks.fail(f"body_or_bodies[{index}]", body, "a tumble.RigidBody")
    return list(body_or_bodies), False


_ROW_SHAPES = {"x0": (3,), "v0": (3,), "R0": (3, 3), "q0": (4,), "omega0": (3,), "L0": (3,)}


def _batch_size(bodies, one_body: bool, arrays: dict) -> tuple[int, str]:
    """``N`` and where it came from: the bodies, or the first per-body array given."""
    if not one_body:
        return len(bodies), f"{len(bodies)} bodies"
    for name, value in arrays.items():
        if value is not None:
            try:
                shape = np.shape(value)
            except ValueError:  # a ragged nesting
                raise _checks.fail(name, value, "an array of one row per body") from None
            if len(shape) != 1 + len(_ROW_SHAPES[name]) or shape[0] == 0:
                expected = ", ".join(["N", *map(str, _ROW_SHAPES[name])])
                raise _checks.fail(
                    f"{name}.shape", shape, f"({expected}): one row per body (N ≥ 1)"
                )
            return shape[0], f"the first axis of {name}"
    return 1, "one body and no per-body arrays"


def _rows(value, name: str, n: int, source: str) -> np.ndarray | None:
    """``value`` as a finite float array of shape ``(n, *row)``, or None."""
    if value is None:
        return None
    array = _checks.array(name, value, finite=False)  # numbers; the rows' entries below
    expected = (n, *_ROW_SHAPES[name])
    if array.shape != expected:
        raise _checks.fail(
            f"{name}.shape", array.shape, f"{expected}: one row per body",
            remedy=f"N = {n}, from {source}",
        )  # fmt: skip
    bad = ~np.isfinite(array.reshape(n, -1)).all(axis=1)
    if bad.any():
        index = int(np.argmax(bad))
        raise _checks.fail(f"{name}[{index}]", array[index].tolist(), "every entry finite")
    return array


def _initial_states(bodies, R0, q0, omega0, L0, x0, v0, n: int):
    """``(R, Y)`` of shapes (N, 3, 3) and (N, 9), as :func:`initial.initial_state` per body."""
    if omega0 is not None and L0 is not None:
        raise _checks.fail(
            "L0", "<array>", "None when omega0 is given",
            remedy="give at most one of omega0 (body-frame angular velocity) and L0 (world "
            "angular momentum); they describe the same thing",
        )  # fmt: skip
    if R0 is not None and q0 is not None:
        raise _checks.fail("q0", "<array>", "None when R0 is given",
                           remedy="give at most one of R0 and q0 (both describe the initial "
                           "attitude)")  # fmt: skip
    if q0 is not None:
        zero = ~np.any(q0, axis=-1)
        if np.any(zero):
            index = int(np.argmax(zero))
            raise _checks.fail(
                f"q0[{index}]", q0[index].tolist(), "a quaternion [w, x, y, z] of non-zero norm"
            )
        R = so3.matrix_from_quat(q0)  # normalised there, without overflow in |q|²
    elif R0 is not None:
        R = so3.validate_rotation(R0, name="R0", atol=1e-9)
    else:
        R = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    if L0 is not None:
        L = L0.copy()
    else:
        omega = np.zeros((n, 3)) if omega0 is None else omega0
        inertia = _per_body(bodies, lambda body: body.inertia)
        with np.errstate(over="ignore", invalid="ignore"):  # too large a spin: a status, later
            L = (R @ (inertia @ omega[..., None]))[..., 0]
    mass = _per_body(bodies, lambda body: body.mass)[:, None]
    x = np.zeros((n, 3)) if x0 is None else x0
    v = np.zeros((n, 3)) if v0 is None else v0
    with np.errstate(over="ignore"):
        return R, np.concatenate([x, mass * v, L], axis=1)


def _kernel_loads(forces, bodies):
    """``(F (N, 3), tau, points, point_forces)`` for the constant loads; else a ValueError."""
    loads, impulses = split_loads(forces)
    if impulses or not all(load.compiled for load in loads):
        raise _checks.fail(
            "forces", forces,
            "constant loads only: tumble.Gravity, and tumble.Force and tumble.Torque with "
            "constant vectors",
            remedy="impulses and callable forces need tumble.simulate (one body per call)",
        )  # fmt: skip
    F = _per_body(bodies, lambda body: compiled_loads(loads, body.mass)[0]).copy()
    return (F, *compiled_loads(loads, bodies[0].mass)[1:])


def record_times(
    grid: Grid, every: int, k0: int = 0, k1: int | None = None, step0: int = 0
) -> np.ndarray:
    """The kernel's sample times ``t_old + h_k`` (exactly) at the recorded steps ``k`` of
    ``k0 + 1 … k1``, those with ``step0 + k`` a multiple of ``every`` (by default the whole
    grid's: steps ``every, 2 every, …``)."""
    first = k0 + 1 + (-(step0 + k0 + 1)) % every
    k = np.arange(first, (grid.n if k1 is None else k1) + 1, every)
    t_old = grid.t0 + (k - 1) * grid.h
    return t_old + (np.where(k == grid.n, grid.t1, grid.t0 + k * grid.h) - t_old)


def simulate_batch(
    body_or_bodies: RigidBody | Sequence[RigidBody],
    t_end: float,
    *,
    method: str = "rkmk4",
    h: float | None = None,
    t0: float = 0.0,
    x0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    R0: ArrayLike | None = None,
    q0: ArrayLike | None = None,
    omega0: ArrayLike | None = None,
    L0: ArrayLike | None = None,
    forces: Sequence[Load | Impulse] = (),
    events: Sequence[Callable[[float, State], float]] = (),
    record_every: int = 1,
    progress: bool = False,
) -> BatchTrajectory:
    """Simulate ``N`` rigid bodies from ``t0`` to ``t_end`` in compiled, parallel blocks.

    Each body obeys :func:`~tumble.rigid.simulate`'s equations,

    .. math::

        \\dot x = p/m,\\quad \\dot R = R\\,\\hat\\omega,\\quad \\dot p = F,\\quad
        \\dot L = \\tau,\\qquad \\omega = I^{-1} R^T L,

    and body ``k`` gets the numbers ``simulate`` gives it alone (same kernel, same steps).

    Parameters
    ----------
    body_or_bodies : RigidBody or sequence of RigidBody
        One body, run from ``N`` initial states (``N`` from the per-body arrays), or ``N``
        bodies (different masses and inertias).
    t_end : float
        End time (s), > ``t0``; the last step lands on it.
    method : str
        A fixed-step method of :data:`tumble.rigid.METHODS` (:data:`FIXED_METHODS`; default
        ``"rkmk4"``).
    h : float
        Step (s).
    t0 : float
        Start time (s).
    x0, v0 : array_like, shape (N, 3), optional
        Initial positions (m) and velocities (m/s); default 0.
    R0 : array_like, shape (N, 3, 3), or scipy.spatial.transform.Rotation, optional
        Initial attitudes (rotation matrices, or one scipy ``Rotation`` of ``N``), or
    q0 : array_like, shape (N, 4), or scipy.spatial.transform.Rotation, optional
        as quaternions ``[w, x, y, z]``; default identity.
    omega0 : array_like, shape (N, 3), optional
        Initial body-frame angular velocities (rad/s), or
    L0 : array_like, shape (N, 3), optional
        world angular momenta (kg m²/s); default at rest.
    forces : sequence
        Constant loads, the same for every body: :class:`~tumble.Gravity` (``m g`` with each
        body's mass), :class:`~tumble.Force` and :class:`~tumble.Torque` with constant vectors,
        :class:`~tumble.MagneticDipole`, :class:`~tumble.GravityGradient` (with each body's
        inertia).
    events : sequence
        Not supported (must be empty): use :func:`~tumble.rigid.simulate`.
    record_every : int
        Keep every k-th step (and the last), to bound memory.
    progress : bool
        Show a progress bar (rich): the batch then marches in about 50 blocks (the same
        numbers, bit for bit, as in one).

    Returns
    -------
    BatchTrajectory
        Arrays with a leading body axis; ``batch[k]`` is body ``k``'s
        :class:`~tumble.rigid.trajectory.Trajectory`.

    Raises
    ------
    ValueError
        For an adaptive method, impulses, callable loads or events, and for per-body arrays
        whose shape is not ``(N, …)`` (the message names the argument and both shapes).

    Examples
    --------
    Three spins of one body about x, at 1, 2 and 3 rad/s, turn by exactly ω t with
    ``lie-euler``:

    >>> import numpy as np
    >>> from tumble import RigidBody, simulate_batch
    >>> omega0 = [[1.0, 0, 0], [2.0, 0, 0], [3.0, 0, 0]]
    >>> batch = simulate_batch(RigidBody(1.0, np.eye(3)), 1.0, method="lie-euler", h=0.1,
    ...                        omega0=omega0)
    >>> len(batch), batch.R.shape
    (3, (3, 11, 3, 3))
    >>> np.allclose(batch.R[:, -1, 1, 1], np.cos([1.0, 2.0, 3.0]))
    True
    """
    spec = get_method(method)
    if spec.adaptive:
        raise _checks.fail(
            "method", method, "a fixed-step method, one of " + ", ".join(map(repr, FIXED_METHODS)),
            remedy=f"{method!r} is adaptive: use tumble.simulate for it",
        )  # fmt: skip
    t0, t_end = initial.check_times(t0, t_end)
    h, _, _ = initial.check_steps(spec, h, None, None)
    every = initial.check_record_every(record_every)
    progress = _checks.flag("progress", progress)
    if _checks.callables("events", events):
        raise _checks.fail(
            "events", events, "empty", remedy="simulate_batch locates no events: use simulate"
        )
    forces = _checks.items("forces", forces, "a sequence of constant loads")
    bodies, one_body = _bodies(body_or_bodies)
    R0, q0 = so3.from_scipy(R0, "R0"), so3.from_scipy(q0, "q0", quaternion=True)  # N rotations
    arrays = {"omega0": omega0, "L0": L0, "R0": R0, "q0": q0, "x0": x0, "v0": v0}
    n_bodies, source = _batch_size(bodies, one_body, arrays)
    rows = {name: _rows(value, name, n_bodies, source) for name, value in arrays.items()}
    bodies = bodies * n_bodies if one_body else bodies
    R, Y = _initial_states(bodies, rows["R0"], rows["q0"], rows["omega0"], rows["L0"],
                           rows["x0"], rows["v0"], n_bodies)  # fmt: skip
    inverses = _per_body(bodies, lambda body: body.inertia_inverse)
    initial.warn_large_step(spec, h, t_end - t0, inverses, R, Y[:, 6:])
    check_free(spec, split_loads(forces)[0])
    loads = _kernel_loads(forces, bodies)
    # GravityGradient takes each body's inertia (broadcast over time, as the mass below)
    inertias = _per_body(bodies, lambda body: body.inertia)[:, None]
    conservative = [load for load in for_body(split_loads(forces)[0], inertias)
                    if load.conservative]  # fmt: skip
    settings = {"h": h, "rtol": None, "atol": None, "record_every": every, "compiled": True}
    batch = _run(spec, tuple(bodies), R, Y, loads, t0, t_end, h, every, settings, progress)
    if conservative:  # V for every body and sample at once (mass broadcast over time)
        masses = _per_body(batch.bodies, lambda body: body.mass)[:, None]
        batch.potential_energy = potential_energy(conservative, batch.x, batch.R, masses)
    return overflow.checked_batch(batch, bool(conservative))


class BatchStepper(Stepper):
    """Every body of a batch in the method's compiled batch loop: a stepper of many members
    (module docstring of :mod:`tumble.ode.driver`), with a compiled part and no Python step.

    The state is ``(attitude, Y)`` with a leading body axis; samples are stacked along axis 1
    (time). A body whose state stops being finite stops alone: the blocks go on for the
    others, each block's :class:`~tumble.ode.driver.Stops` say which bodies stopped in it, at
    which step and why (a non-finite state, or an implicit flow that did not converge), and
    the driver keeps each body's account (``Outcome.members``). :attr:`failed` remembers,
    over the run, the step each body stopped before (-1: none), so that no later block
    marches it. The method's family (:data:`~tumble.rigid.methods.FAMILIES`) gives the loop
    and the carried attitude: ``split`` methods carry ``R_p = R P`` with each body's
    principal axes ``P``. ``block_steps`` bounds the steps of one block; a block goes on
    from the loops' own arrays ``(Z, R_N)`` when handed the state the last one returned
    (packing it again would normalise a quaternion once more: the numbers would depend on
    the blocks).
    """

    time_axis = 1

    def __init__(self, method: Method, problem, block_steps: int | None = None):
        self.method, self.problem = method, problem
        self.family = FAMILIES[method.family]
        self.batch = self.family.batch_loop(method)
        n_bodies = len(problem.m)
        self.failed = np.full(n_bodies, -1, dtype=np.int64)
        self.causes = np.zeros(n_bodies, dtype=np.int64)
        self._block_steps = block_steps
        self._handed: tuple = (None, None)  # the state the last block handed back, its (Z, RN)

    @property
    def compiled(self) -> Compiled:
        """The batch loop as the compiled part (made when asked: no reference cycle)."""
        return Compiled(self._march_block, block_steps=self._block_steps)

    def start(self, state: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """The stepped state for ``(R, Y)`` with a leading body axis."""
        R, Y = state
        return self.family.start(R, Y, self.problem.axes)

    def record(self, state) -> tuple:
        attitude, Y = state
        q = attitude[:, None] if self.family.quaternion else np.empty((len(Y), 1, 0))
        return self.family.matrix(attitude, self.problem.axes)[:, None], Y[:, None], q

    def _march_block(self, state, grid: Grid, k0: int, k1: int, every: int, step0: int) -> Block:
        from tumble.rigid._compiled.base import Records

        times = record_times(grid, every, k0, k1, step0)
        n_bodies, size = len(state[1]), len(times)
        records = Records(*(np.empty((n_bodies, size, *shape)) for shape in RECORD_SHAPES))
        counts, before = np.zeros(n_bodies, dtype=np.int64), self.failed.copy()
        Z, RN = self._handed[1] if state is self._handed[0] else self.family.pack(*state)
        if self.family.columns and n_bodies >= SOA_MIN_BODIES:
            _march_columns(self.method, self.family.quaternion, self.problem, grid, Z, RN,
                           (k0, k1, every, step0), records, counts, self.failed)  # fmt: skip
        else:
            announce_compilation(self.batch, f"the batch loop of {self.method.name}")
            self.batch(self.problem, grid, Z, RN, k0, k1, every, step0, records, counts,
                       self.failed, self.causes)  # fmt: skip
        failed = np.where(before < 0, self.failed, -1)  # those that stopped in this block
        messages = {
            k: unconverged_message(self.method, grid.time(failed[k] - 1), grid.time(failed[k]))
            for k in np.flatnonzero(failed >= 0).tolist()
            if self.causes[k] == UNCONVERGED
        }
        q = records.q if self.family.quaternion else np.empty((n_bodies, size, 0))
        new = self.family.read(Z, RN)
        self._handed = (new, (Z, RN))  # the next block goes on from them: not packed again
        return Block(
            t=times,
            records=(records.R, records.Y, q),
            state=new,
            stops=Stops(counts, failed, messages),
        )


SOA_FAMILIES = tuple(name for name, family in FAMILIES.items() if family.columns)
"""The families whose batches run in the structure-of-arrays loops of :mod:`tumble.rigid.soa`
(bodies as columns, vectorised; the numbers of the one-body loop, bit for bit)."""

SOA_MIN_BODIES = 32
"""Fewer bodies run one per thread: with a handful of columns the vector loops' set-up costs
more than the one-body loop (measured: one body 0.14× as fast in the columns, 10³ bodies
2.5×)."""


def _march_columns(
    method: Method, quaternion: bool, problem, grid: Grid, Z, RN, steps: tuple, records,
    counts, failed,
) -> None:  # fmt: skip
    """:func:`tumble.rigid.soa.run_batch` on the batch's state ``Z`` (N, nz), ``RN``
    (N, 3, 3), updated in place (its blocks turn their bodies into columns and back), over
    ``steps = (k0, k1, every, step0)``; ``quaternion``: the chart carries q (else R)."""
    from tumble.rigid.soa import run_batch

    announce_compilation(run_batch, f"the batch loop of {method.name}")
    run_batch(quaternion, problem, grid, Z, RN, *steps, records, counts, failed)


RECORD_SHAPES = ((), (3, 3), (4,), (9,))
"""Shapes of one sample in the kernels' ``Records``: t, R, q, Y."""


SAMPLE_BYTES = 8 * sum(int(np.prod(shape)) for shape in RECORD_SHAPES)
"""Bytes of one body's sample in a block's ``Records``."""

BLOCK_BYTES = 1 << 26
"""A block's records take at most about this much (64 MiB; at least one sample of every
body): a batch marches in blocks of that many steps, so that a long run needs its record
and one block, not twice its record."""


def _run(spec, bodies, R, Y, loads, t0, t_end, h, every, settings, progress) -> BatchTrajectory:
    """March every body (in blocks); lay the samples out as (body, time, …) arrays."""
    mass = _per_body(bodies, lambda body: body.mass)
    inv_I = _per_body(bodies, lambda body: body.inertia_inverse)
    family = FAMILIES[spec.family]
    if family.principal_frame:  # each distinct body's principal frame, once
        moments = _per_body(bodies, lambda body: family.frame(body.inertia)[0])
        axes = _per_body(bodies, lambda body: family.frame(body.inertia)[1])
    else:  # unused by the other loops: placeholders of the same (read-only) array type
        moments, axes = np.ones((len(bodies), 3)), np.tile(np.eye(3), (len(bodies), 1, 1))
        moments.setflags(write=False)
        axes.setflags(write=False)
    inertia = _per_body(bodies, lambda body: body.inertia)
    block = every * max(1, BLOCK_BYTES // (len(bodies) * SAMPLE_BYTES))
    stepper = BatchStepper(spec, problem(spec, inv_I, mass, loads, axes, moments, inertia),
                           block)  # fmt: skip
    with progress_bar(progress, t_end - t0, "simulating") as update:
        advance = (lambda t: update(completed=t - t0)) if progress else None
        out = march(stepper, (t0, t_end), stepper.start((R, Y)), h=h, record_every=every,
                    progress=advance)  # fmt: skip
    samples = dict(zip(("R", "Y", "q"), out.records, strict=True))
    members = out.members
    assert members is not None
    Ys = samples["Y"]
    return BatchTrajectory(
        t=out.t,
        x=Ys[..., :3],
        v=Ys[..., 3:6] / mass[:, None, None],
        R=samples["R"],
        L_world=Ys[..., 6:],
        bodies=bodies,
        method=spec.name,
        settings=settings,
        status=members.status,
        messages=members.messages,
        n_steps=members.n_steps,
        n_recorded=members.n_recorded,
        q_raw=samples["q"] if family.quaternion else None,
        t_last=members.t_last,
    )
