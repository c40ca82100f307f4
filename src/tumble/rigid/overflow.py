"""A rigid run whose energy overflows while its state stays finite is a failure.

A double holds numbers up to 1.8e308. A body spun at ``|ω| = 1e155`` rad/s has a finite
state, and most methods step it without a NaN (``lie-euler``, ``rkmk4``, the splittings), but

* its kinetic energy ``T = ½ m|v|² + ½ ω·(RᵀL)`` is inf once ``|ω||L|`` passes 3.6e308
  (``I = 1`` kg m²: from 1.9e154 rad/s), and
* even where ``T`` is finite (the T-handle, ``I ≈ 1e-4`` kg m²: ``T = 4.9e305`` J) the
  square of the spin, ``|ω|² = 1e310``, is not: the energy is within a few hundred times of
  overflowing, and a step of any length turns the body by so many radians that its
  attitude has no correct digit.

Those runs used to end with status 0. :func:`simulate <tumble.rigid.simulate>` and
:func:`simulate_batch <tumble.rigid.simulate_batch>` now check what they record: the first
record whose energy ``T + V`` or ``|ω|²`` is not finite ends the run,
:attr:`~tumble.ode.driver.Status.FAILED`, with its time and the cause in the message; the
trajectory keeps the records before it (at least the first). A run that fails on its own
(a state that becomes non-finite, an implicit step that does not converge) keeps its cause:
those already end FAILED, and say when. The loops are not touched: the
check reads the records once, and first only screens them with one dot product
(:func:`may_overflow`), which every run whose numbers stay far from 1e154 passes; only a run
that fails the screen has its energies computed.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from typing import TYPE_CHECKING

import numpy as np

from tumble.ode.driver import Status
from tumble.rigid.body import RigidBody
from tumble.rigid.methods import METHODS
from tumble.rigid.trajectory import Trajectory

if TYPE_CHECKING:
    from tumble.rigid.batch import BatchTrajectory

LARGEST = sys.float_info.max
"""The largest double, 1.8e308."""


def may_overflow(Y: np.ndarray, R: np.ndarray | None, body: RigidBody) -> bool:
    """False when no record can overflow: the screen of one body's records.

    ``Y`` holds the records' ``(x, p, L)``, shape (n, 9), ``R`` their attitudes when they
    may leave SO(3) (a method that does not declare ``"orthogonality"``; None: rotations).
    With ``s = Σ|Y|²`` over the records and ``c = max(1/m², 1/m, tr I⁻¹, (tr I⁻¹)²)``,
    every quantity checked and every term on the way (``|v|²``, ``m|v|²``,
    ``ω·(RᵀL) ≤ tr I⁻¹ ‖R‖² |L|²``, ``|ω|² ≤ (tr I⁻¹)² ‖R‖² |L|²``) of every record is
    at most ``c s (1 + Σ‖R‖²_F)``; while that is below ``LARGEST/8`` nothing overflows.
    One BLAS dot product (two with ``R``), which overflows to inf without a warning: about
    1.5 µs on a short run.
    """
    inverse = body.inertia_inverse
    trace = inverse.item(0) + inverse.item(4) + inverse.item(8)
    c = max(1.0 / body.mass / body.mass, 1.0 / body.mass, trace, trace * trace)
    size = float(np.vdot(Y, Y))
    if R is not None:
        size *= 1.0 + float(np.vdot(R, R))
    return not c * size < LARGEST / 8


def may_overflow_batch(batch: BatchTrajectory) -> bool:
    """:func:`may_overflow` for a batch: ``Σ|v|²`` and ``Σ|L|²`` over every body and record
    (a stopped body's NaN rows make it True: then the records decide)."""
    mass = max(body.mass for body in batch.bodies)
    trace = max(float(np.trace(body.inertia_inverse)) for body in batch.bodies)
    rotations = "orthogonality" in METHODS[batch.method].conserves  # else R may leave SO(3)
    turn = 1.0 + (0.0 if rotations else float(np.vdot(batch.R, batch.R)))
    size = max(1.0, mass) * float(np.vdot(batch.v, batch.v))
    size += max(trace, trace * trace) * turn * float(np.vdot(batch.L_world, batch.L_world))
    return not size < LARGEST / 8


def first_overflow(run: Trajectory) -> int | None:
    """Index of the first record of ``run`` whose energy or ``|ω|²`` is not finite, or None."""
    with np.errstate(over="ignore", invalid="ignore"):
        spin = np.einsum("ni,ni->n", run.omega_body, run.omega_body)
        bad = ~(np.isfinite(run.energy) & np.isfinite(spin))
    return int(np.argmax(bad)) if bad.any() else None


def checked(run: Trajectory, Y: np.ndarray, R: np.ndarray | None, loaded: bool) -> Trajectory:
    """``run`` ended at its first record that overflows (:func:`first_overflow`), if any.

    ``Y``, ``R`` as :func:`may_overflow` (the run's records); ``loaded``: whether the loads
    have a potential (then its energy is checked too). A run that failed already (a
    non-finite state, an unconverged step) keeps its own cause and records.
    """
    potential = run.potential_energy
    if run.status < 0 or not (may_overflow(Y, R, run.body) or loaded and _any_overflow(potential)):
        return run
    index = first_overflow(run)
    if index is None:
        return run
    kept = max(index, 1)
    q_raw = None if run.q_raw is None else run.q_raw[:kept]
    return dataclasses.replace(
        run, t=run.t[:kept], x=run.x[:kept], v=run.v[:kept], R=run.R[:kept],
        L_world=run.L_world[:kept], q_raw=q_raw, potential_energy=potential[:kept],
        status=Status.FAILED, message=overflow_message(run, index),
    )  # fmt: skip


def checked_batch(batch: BatchTrajectory, loaded: bool) -> BatchTrajectory:
    """Each body of ``batch`` that did not fail already ended at its first record that
    overflows, as :func:`checked` (its later rows NaN, its status FAILED); in place."""
    if not may_overflow_batch(batch) and not (loaded and _any_overflow(batch.potential_energy)):
        return batch
    t_last = batch.t_last if batch.t_last is not None else np.full(len(batch), batch.t[-1])
    for k in np.flatnonzero(batch.status >= 0).tolist():
        run = batch[k]
        index = first_overflow(run)
        if index is None:
            continue
        kept = max(index, 1)
        batch.messages[k] = overflow_message(run, index)
        batch.status[k] = Status.FAILED
        for array in (batch.x, batch.v, batch.R, batch.L_world, batch.potential_energy):
            array[k, kept:] = np.nan
        if batch.q_raw is not None:
            batch.q_raw[k, kept:] = np.nan
        batch.n_recorded[k] = kept
        t_last[k] = run.t[kept - 1]
    batch.t_last = t_last
    for name in ("q", "omega_body", "kinetic_energy", "energy", "orthogonality_error"):
        batch.__dict__.pop(name, None)  # computed before the cut: forget them
    return batch


def _any_overflow(energy: np.ndarray) -> bool:
    """Whether ``Σ energy²`` is not finite (a screen: then the records decide)."""
    return not math.isfinite(float(np.vdot(energy, energy)))


def overflow_message(run: Trajectory, index: int) -> str:
    """Why ``run`` ends at record ``index``: what overflowed there, when, and the last record
    kept."""
    speed, spin, L = (_length(a[index]) for a in (run.v, run.omega_body, run.L_world))
    kinetic = float(run.kinetic_energy[index])
    if not math.isfinite(kinetic) and math.isfinite(spin * L):
        what = (
            f"the kinetic energy ½ m|v|² overflows: |v| = {speed:.3g} m/s is too large for "
            "double precision"
        )
    elif not math.isfinite(kinetic):
        what = (
            f"the kinetic energy ½ ω·L overflows: |ω| = {spin:.3g} rad/s and |L| = {L:.3g} "
            f"kg m²/s, past the largest double, {LARGEST:.2g}: the spin is too large for "
            "double precision"
        )
    elif not math.isfinite(spin * spin):
        what = (
            f"|ω|² overflows: |ω| = {spin:.3g} rad/s, and the energy, {kinetic:.3g} J, is "
            f"within {LARGEST / kinetic:.2g}× of the largest double: the spin is too large for "
            "double precision"
        )
    else:
        what = "the potential energy of the loads overflows: the body is too far away"
    kept = (
        f"the run ends with the last record before it, t={float(run.t[index - 1])!r}"
        if index > 0
        else "the run ends with its initial state"
    )
    return f"at t={float(run.t[index])!r} {what} (the state itself is finite); {kept}"


def _length(a: np.ndarray) -> float:
    """``|a|`` without overflow in the squares (scaled by the largest entry)."""
    largest = float(np.max(np.abs(a)))
    if not 0 < largest < math.inf:
        return largest
    return largest * float(np.sqrt(np.sum((a / largest) ** 2)))
