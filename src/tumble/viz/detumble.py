"""A detumbling satellite's picture: its rate, what its magnetorquers command, its attitude.

:func:`detumble_figure` draws one PNG through :mod:`tumble.viz._figure`, three panels on one
time axis (in orbits): ``|ω|`` on a log scale with the threshold that ends the run, the
event that found it and twice the orbit rate (where a B-dot law stops taking energy out:
the field turns that fast in the body as the satellite goes round); the commanded dipole,
each body axis against its saturation; and the attitude as the angle of each body axis from
the orbit normal, which tumbles through 0–180° at first and settles as the body slows.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tumble.viz._figure import new_figure, save

if TYPE_CHECKING:
    from tumble.rigid.trajectory import Trajectory

_AXES = ("x", "y", "z")


def detumble_figure(
    trajectory: Trajectory,
    dipoles: np.ndarray,
    path: str | Path,
    *,
    threshold: float,
    max_dipole: float,
    orbit_normal: np.ndarray,
    period: float,
    title: str,
) -> None:
    """``|ω|``, the commanded dipole and the attitude of a detumbling run (module docstring).

    Parameters
    ----------
    trajectory : Trajectory
        The run; a terminal event's time (``t_events[0]``) is marked.
    dipoles : ndarray, shape (n, 3)
        The commanded dipole at each sample (A m², body axes).
    path : str or Path
        Where the PNG goes.
    threshold : float
        The rate that ends the run (rad/s).
    max_dipole : float
        Each magnetorquer's saturation (A m²).
    orbit_normal : ndarray, shape (3,)
        The orbit's unit normal (inertial axes).
    period : float
        The orbit's period (s): the time axis is in orbits.
    title : str
        The figure's title.
    """
    orbits = trajectory.t / period
    fig, (rate, dipole, attitude) = new_figure(3, 1, figsize=(10.0, 9.0), sharex=True,
                                               layout="constrained")  # fmt: skip
    rate.semilogy(orbits, np.linalg.norm(trajectory.omega_body, axis=1), color="C0", lw=1.2,
                  label="|ω|")  # fmt: skip
    rate.axhline(threshold, color="C3", ls="--", lw=1.0, label=f"threshold {threshold:g} rad/s")
    rate.axhline(4.0 * np.pi / period, color="0.4", ls=":", lw=1.0,
                 label="twice the orbit rate")  # fmt: skip
    events = trajectory.t_events[0] if trajectory.t_events else np.empty(0)
    for when in events[:1]:
        rate.axvline(when / period, color="C3", lw=0.8)
        rate.annotate(f"detumbled: t = {when:.0f} s\n({when / period:.2f} orbits)",
                      (when / period, threshold), textcoords="offset points", xytext=(-110, 30),
                      fontsize=9, arrowprops={"arrowstyle": "->"})  # fmt: skip
    rate.set_ylabel("|ω| (rad/s)")
    rate.legend(loc="upper right", fontsize=8)
    rate.grid(alpha=0.3, which="both")
    for k in range(3):
        dipole.plot(orbits, dipoles[:, k], color=f"C{k}", lw=0.6, alpha=0.8,
                    label=f"m_{_AXES[k]}")  # fmt: skip
    for bound in (-max_dipole, max_dipole):
        dipole.axhline(bound, color="0.3", ls="--", lw=0.9)
    dipole.set_ylim(-1.25 * max_dipole, 1.25 * max_dipole)
    dipole.set_ylabel("commanded dipole (A m²)\nbody axes, ±saturation dashed")
    dipole.legend(loc="upper right", fontsize=8, ncol=3)
    dipole.grid(alpha=0.3)
    cosines = np.einsum("nij,i->nj", trajectory.R, np.asarray(orbit_normal, dtype=float))
    for k in range(3):
        angle = np.degrees(np.arccos(np.clip(cosines[:, k], -1.0, 1.0)))
        attitude.plot(orbits, angle, color=f"C{k}", lw=0.6, label=f"body {_AXES[k]}")
    attitude.set_ylim(0.0, 180.0)
    attitude.set_yticks([0, 45, 90, 135, 180])
    attitude.set_ylabel("angle from the orbit normal (°)")
    attitude.set_xlabel("t (orbits)")
    attitude.legend(loc="upper right", fontsize=8, ncol=3)
    attitude.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    save(fig, path)
