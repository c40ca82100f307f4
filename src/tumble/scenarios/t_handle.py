"""Seed 002, tasks 5–6: the T-handle spun about each principal axis; the middle one flips.

The T-handle of :func:`tumble.mass.t_handle` has the principal moments
diag(9.82271303e-05, 7.22671030e-05, 1.57865031e-04) kg m², so x is the *intermediate* axis,
y the smallest and z the largest. Seed 002 spun it from ω(0) = (1, 0.05, 0), (0, 1, 0.05) and
(0.05, 0, 1) rad/s for 100 s at h = 0.01 and plotted the nine entries of R(t) and the ZYX
Euler angles. The spin about x is unstable: ω_x reverses again and again (the tennis-racket or
Dzhanibekov effect), while the spins about y and z only wobble.

Both motions are periodic in the body frame, with the period ``4K(m)/λ`` of the Jacobi
elliptic solution (:func:`tumble.exact.free_body_period`). This scenario measures it from the
simulation: two components of ω_body change sign, and every other zero crossing of one of them
(crossings in the same direction) is one period apart. The handle flips twice per period.

The flips of the intermediate-axis spin are also located by an event
(:func:`tumble.rigid.flip_event`) on the dense output of ``rkmk-dopri5`` at
:data:`FLIP_RTOL` (:func:`flip_times`), each reported beside the exact half period.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np

from tumble import _checks, exact, mass, meshes
from tumble.io import ScenarioResult
from tumble.rigid import RigidBody, Trajectory, flip_event, simulate
from tumble.rigid.forces import State
from tumble.scenarios._base import rigid_attrs, rigid_outputs
from tumble.scenarios.option_models import OptionRules
from tumble.viz import rigid

NAME = "t-handle"
SUMMARY = (
    "Seed 002 tasks 5–6: the T-handle's three spins; the middle axis flips (measured period)."
)

SPINS = ((1.0, 0.05, 0.0), (0.0, 1.0, 0.05), (0.05, 0.0, 1.0))
"""Seed 002's initial body angular velocities (rad/s)."""
OPTION_RULES = OptionRules(positive=["h", "t_end", "rtol"], three_vectors=["spins"])
"""What :func:`run`'s options must be beyond its signature: each spin is a 3-vector."""
FLIP_METHOD, FLIP_RTOL = "rkmk-dopri5", 1e-10
"""How :func:`flip_times` integrates: the error it leaves in a flip time is about 1e-11 of
the half period per flip (measured)."""
_AXES = "xyz"
_ROLES = ("smallest (stable)", "intermediate (unstable)", "largest (stable)")


def zero_crossings(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Times at which ``values`` changes sign, by linear interpolation between samples.

    A zero counts as positive, so the crossings alternate in direction.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s).
    values : ndarray, shape (n,)
        Samples of a function of time.

    Returns
    -------
    ndarray, shape (k,)
        The crossing times (s), increasing.

    Examples
    --------
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> np.round(zero_crossings(t, np.cos(t)), 4)
    array([1.5708, 4.7124, 7.854 ])
    """
    positive = values >= 0
    k = np.nonzero(positive[:-1] != positive[1:])[0]
    return t[k] - values[k] * (t[k + 1] - t[k]) / (values[k + 1] - values[k])


def measured_periods(t: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The period of each run's ω_body(t), from the zero crossings of its most-crossing component.

    Every other crossing is in the same direction, one period later; the period is the mean
    of ``c[k + 2] − c[k]`` over the crossings ``c`` (:func:`zero_crossings`: a zero counts
    as positive, linear interpolation between samples). That mean telescopes to
    ``(c[-1] + c[-2] − c[0] − c[1]) / (len(c) − 2)``, so only the first two and last two
    crossings of each run are located: many runs at once cost a few array passes (a sweep's
    ``flip_period``, :mod:`tumble.sweeps.variables`).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s), shared by every run.
    omega : ndarray, shape (m, n, 3)
        Body angular velocities (rad/s); NaN after a run that stopped.

    Returns
    -------
    ndarray, shape (m,)
        The periods (s); NaN where fewer than three crossings were seen (run longer).

    Examples
    --------
    >>> t = np.linspace(0.0, 20.0, 2001)
    >>> spins = np.stack([np.cos(t), np.sin(t), np.ones_like(t)], axis=1)
    >>> np.round(measured_periods(t, np.stack([spins, spins[:, [2, 0, 1]]])), 5)
    array([6.28319, 6.28319])
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        positive = omega >= 0
        changes = positive[:, :-1] != positive[:, 1:]  # (m, n - 1, 3)
        component = np.argmax(changes.sum(axis=1), axis=1)
        rows = np.arange(len(omega))
        values = omega[rows, :, component]  # (m, n)
        crossing = changes[rows, :, component]
        count = crossing.sum(axis=1)
        dt = t[1:] - t[:-1]
        times = t[:-1] - values[:, :-1] * dt / (values[:, 1:] - values[:, :-1])
        order = np.cumsum(crossing, axis=1)
        first = _crossing(times, order, crossing, 1)
        second = _crossing(times, order, crossing, 2)
        last = _crossing(times, order, crossing, count)
        before_last = _crossing(times, order, crossing, count - 1)
        period = (last + before_last - first - second) / (count - 2)
    return np.where(count >= 3, period, np.nan)


def _crossing(times: np.ndarray, order: np.ndarray, crossing: np.ndarray, k) -> np.ndarray:
    """The time of each run's ``k``-th crossing (1-based; NaN where there is none)."""
    hit = crossing & (order == np.reshape(k, (-1, 1)))
    index = np.argmax(hit, axis=1)
    return np.where(hit.any(axis=1), times[np.arange(len(times)), index], np.nan)


def measured_period(t: np.ndarray, omega: np.ndarray) -> tuple[float | None, int, np.ndarray]:
    """One run's :func:`measured_periods`, with the component and the crossings it used.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s).
    omega : ndarray, shape (n, 3)
        Body angular velocity (rad/s).

    Returns
    -------
    period : float or None
        The period (s), or None when fewer than three crossings were seen (run longer).
    component : int
        Which component (0, 1, 2 for x, y, z) it was measured from.
    crossings : ndarray
        Its crossing times (s).
    """
    crossings = [zero_crossings(t, omega[:, k]) for k in range(3)]
    component = int(np.argmax([len(c) for c in crossings]))
    period = float(measured_periods(t, omega[None])[0])
    return (None if np.isnan(period) else period), component, crossings[component]


def flip_times(body: RigidBody, omega0, t_end: float) -> np.ndarray:
    """The times at which a spin near the intermediate axis turns over, by event.

    A compiled ``rkmk-dopri5`` run at rtol :data:`FLIP_RTOL` records every step; each step
    across which :func:`~tumble.rigid.flip_event` changes sign is taken again, from its
    recorded start and with the same step, in the Python stepper, whose event search locates
    the zero by root finding on the step's dense output. So the event costs a few Python
    steps, not a Python run.

    Parameters
    ----------
    body : RigidBody
        The body.
    omega0 : array_like, shape (3,)
        Initial body angular velocity (rad/s).
    t_end : float
        End time (s).

    Returns
    -------
    ndarray, shape (k,)
        The flip times (s), half a period of ω apart.

    Examples
    --------
    >>> body = RigidBody.from_mass_properties(mass.t_handle())
    >>> flips = flip_times(body, (1.0, 0.05, 0.0), 60.0)
    >>> half = exact.free_body_period(body.inertia, (1.0, 0.05, 0.0)) / 2
    >>> len(flips), bool(np.abs(np.diff(flips) / half - 1).max() < 1e-9)
    (3, True)
    """
    event = flip_event(body)
    run = simulate(body, t_end, method=FLIP_METHOD, rtol=FLIP_RTOL, omega0=omega0)
    zero = np.zeros(3)
    samples = zip(run.t, run.R, run.L_world, strict=True)
    g = np.array([event(t, State(zero, R, zero, L)) for t, R, L in samples])
    flips = []
    for k in np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0):
        step = simulate(body, run.t[k + 1], t0=run.t[k], R0=run.R[k], L0=run.L_world[k],
                        method=FLIP_METHOD, rtol=FLIP_RTOL, h=run.t[k + 1] - run.t[k],
                        events=[event])  # fmt: skip
        flips.extend(step.t_events[0])
    return np.array(flips)


def run(
    *,
    method: str = "rkmk4",
    h: float | None = 0.01,
    t_end: float = 100.0,
    spins: Sequence[Sequence[float]] = SPINS,
    rtol: float | None = None,
) -> ScenarioResult:
    """Spin the T-handle from each initial ω and compare the period with the closed form.

    Parameters
    ----------
    method : str
        A :data:`tumble.rigid.METHODS` name.
    h : float or None
        Step (s); the first step (or None) for ``rkmk45``.
    t_end : float
        End time (s). A period is measured once a component has crossed zero three times:
        about one period (47 s for the unstable spin, 17 s and 7.4 s for the others).
    spins : sequence of array_like, shape (3,)
        Initial body angular velocities (rad/s).
    rtol : float, optional
        Tolerance for ``rkmk45``.

    Returns
    -------
    ScenarioResult
        ``summary["spins"]``: per spin ``omega0``, ``axis`` and ``axis_role``, the run's
        ``status`` and ``message`` (:class:`~tumble.rigid.Trajectory`'s),
        ``period_closed_form`` and ``period_measured`` (s; None if the run saw fewer than
        three crossings), ``period_relative_difference``, ``measured_from``, for the
        intermediate-axis spin ``flip_times`` (s, by event: :func:`flip_times`),
        ``half_period_exact`` and ``flip_relative_differences`` (each interval between
        flips against the exact half period; the others have None),
        ``max_orthogonality_error``, ``energy_drift`` (largest ``|E/E₀ − 1|``),
        ``momentum_drift`` (largest ``|L − L₀|/|L₀|``) and ``error_vs_exact``
        (``‖R − R_exact‖_F`` at the end). A spin that stopped before ``t_end`` (``status``
        < 0: its state overflowed) has None for all the measured numbers. Figures:
        ``rotation_grid_spin<k>.png``, ``euler_angles_spin<k>.png`` for k = 1, 2, …,
        ``angular_velocity.png``, ``drift.png``; datasets ``spin<k>``; ``animation.gif`` and
        ``view.html`` of the intermediate-axis spin (the flip).

    Examples
    --------
    >>> result = run(t_end=20.0, spins=[(0.05, 0.0, 1.0)])
    >>> spin = result.summary["spins"][0]
    >>> abs(spin["period_measured"] / spin["period_closed_form"] - 1) < 1e-6
    True
    """
    omegas = [np.asarray(spin, dtype=float) for spin in spins]
    if not omegas:
        raise _checks.fail("spins", spins, "at least one initial ω", "rad/s")
    body = RigidBody.from_mass_properties(mass.t_handle())
    runs = [simulate(body, t_end, method=method, h=h, rtol=rtol, omega0=spin) for spin in omegas]
    results = [
        _spin_result(body, spin, trajectory) for spin, trajectory in zip(omegas, runs, strict=True)
    ]
    summary = {
        "scenario": NAME,
        "method": method,
        "h": h,
        "t_end": t_end,
        "inertia": np.diag(body.inertia).tolist(),
        "spins": [result for result, _ in results],
    }
    crossings = [marks for _, marks in results]
    shown, mesh = _showcase(summary["spins"]), meshes.t_handle()
    setting = f"{method}, h = {h} s" if h is not None else method
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectories": runs, "body": body, "crossings": crossings},
        figures=_figures(summary, runs, crossings),
        attrs=rigid_attrs(body, method=method, h=h, rtol=rtol, t_end=t_end),
        **rigid_outputs(
            {f"spin{k}": run for k, run in enumerate(runs, start=1)},
            mesh,
            shown=f"spin{shown + 1}",
            title=f"{NAME} — {_label(summary['spins'][shown])}\n{setting}",
        ),  # fmt: skip
    )


def _showcase(spins: list[dict]) -> int:
    """The spin to animate: the first about the intermediate axis (it flips), else the first."""
    roles = [spin["axis_role"] for spin in spins]
    return next((k for k, role in enumerate(roles) if role.startswith("intermediate")), 0)


def _role(inertia: np.ndarray, omega0: np.ndarray) -> tuple[str, str]:
    """The principal axis the spin is nearest, and whether it is the smallest/middle/largest."""
    axis = int(np.argmax(np.abs(omega0)))
    rank = int(np.argsort(np.argsort(np.diag(inertia)))[axis])
    return _AXES[axis], _ROLES[rank]


_MEASURED = (
    "period_measured",
    "period_relative_difference",
    "max_orthogonality_error",
    "energy_drift",
    "momentum_drift",
    "error_vs_exact",
)
"""The numbers of a spin measured from its run: None when the run stopped before ``t_end``."""


def _flips(body: RigidBody, omega0: np.ndarray, t_end: float, role: str) -> dict:
    """The flip times by event, for the intermediate-axis spin (None for the others)."""
    if not role.startswith("intermediate"):
        return dict.fromkeys(("flip_times", "half_period_exact", "flip_relative_differences"))
    flips = flip_times(body, omega0, t_end)
    half = exact.free_body_period(body.inertia, omega0) / 2
    return {
        "flip_times": flips.tolist(),
        "half_period_exact": half,
        "flip_relative_differences": (np.diff(flips) / half - 1).tolist(),
    }


def _spin_result(body: RigidBody, omega0: np.ndarray, run: Trajectory) -> tuple[dict, np.ndarray]:
    closed_form = exact.free_body_period(body.inertia, omega0)
    axis, role = _role(body.inertia, omega0)
    with np.errstate(all="ignore"):  # a diverged run: inf or nan, reported by its status
        period, component, crossings = measured_period(run.t, run.omega_body)
        result = {
            "omega0": omega0.tolist(),
            "axis": axis,
            "axis_role": role,
            "status": run.status,
            "message": run.message,
            "period_closed_form": closed_form,
            "period_measured": period,
            "period_relative_difference": None if period is None else period / closed_form - 1,
            "measured_from": f"omega_{_AXES[component]}",
            **_drifts(body, omega0, run),
            **_flips(body, omega0, float(run.t[-1]), role),
        }
    if run.status < 0:
        result.update(dict.fromkeys(_MEASURED))
    return result, crossings


def _drifts(body: RigidBody, omega0: np.ndarray, run: Trajectory) -> dict:
    """Orthogonality, energy and momentum drift, and the final error against the exact R."""
    R_exact = exact.free_body_rotation(body.inertia, omega0, run.t[-1])
    return {
        "max_orthogonality_error": run.orthogonality_drift,
        "energy_drift": run.energy_drift,
        "momentum_drift": run.momentum_drift,
        "error_vs_exact": float(np.linalg.norm(run.R[-1] - R_exact)),
    }


def _label(spin: dict) -> str:
    omega = ", ".join(f"{w:g}" for w in spin["omega0"])
    return f"ω₀ = ({omega}) rad/s, about {spin['axis']}: {spin['axis_role']}"


def _period_note(spin: dict) -> str:
    measured = spin["period_measured"]
    if spin["status"] < 0:
        shown = "not measured (the run stopped early: its state overflowed)"
    elif measured is None:
        shown = "not measured (run longer)"
    else:
        shown = f"{measured:.4f} s"
    closed = spin["period_closed_form"]
    note = f"period from {spin['measured_from']}: {shown} (closed form {closed:.4f} s)"
    if spin.get("flip_times"):
        flips = ", ".join(f"{t:.4f}" for t in spin["flip_times"])
        note += (
            f"\nflips by event at {flips} s (exact half period {spin['half_period_exact']:.4f} s)"
        )
    return note


def _figures(summary: dict, runs: list[Trajectory], crossings: list) -> list:
    method, h = summary["method"], summary["h"]
    setting = f"{method}, h = {h} s" if h is not None else method
    labels = [_label(spin) for spin in summary["spins"]]
    figures = []
    for k, (label, run) in enumerate(zip(labels, runs, strict=True), start=1):
        title = f"{NAME} — {label}\n{setting}"
        grid = [(method, run.t, run.R)]
        angles = [(method, run.t, run.euler_zyx())]
        figures.append(
            (f"rotation_grid_spin{k}.png", partial(rigid.rotation_grid, grid, title=title))
        )
        figures.append(
            (f"euler_angles_spin{k}.png", partial(rigid.euler_angles, angles, title=title))
        )
    rates = [
        (f"{label}; {_period_note(spin)}", run.t, run.omega_body)
        for label, spin, run in zip(labels, summary["spins"], runs, strict=True)
    ]
    figures.append(
        (
            "angular_velocity.png",
            partial(
                rigid.angular_velocity,
                rates,
                title=f"{NAME} — body angular velocity ({setting}); dotted: zero crossings",
                marks=crossings,
            ),
        )
    )
    drifts = [
        (f"spin {k}: about {spin['axis']}", run)
        for k, (spin, run) in enumerate(zip(summary["spins"], runs, strict=True), start=1)
    ]
    figures.append(("drift.png", partial(rigid.drift, drifts, title=f"{NAME} — {setting}")))
    return figures


def free_body() -> tuple[RigidBody, np.ndarray]:
    """The T-handle and its flipping spin, for ``tumble compare t-handle`` (work–precision)."""
    return RigidBody.from_mass_properties(mass.t_handle()), np.array(SPINS[0])
