"""Detumbling a small satellite: a B-dot magnetorquer law on a 3U cubesat in low Earth orbit.

A 3U cubesat (a uniform 4 kg box, 10 × 10 × 34.05 cm, the CubeSat Design Specification's
3U envelope) leaves its deployer tumbling at about 15 °/s. Three magnetorquers, one per body
axis, each saturating at ``max_dipole``, command the B-dot law

.. math:: m = -k\\,\\dot B_b, \\qquad \\tau = m \\times B_b \\ \\text{(body axes)},

which takes out rotational energy while the body turns fast beside the field's own rate:
with the field fixed in space ``Ḃ_b = −ω × B_b`` and ``dT/dt = ω·τ = m·Ḃ_b ≤ 0`` however
each axis saturates (Stickler & Alfriend 1976; Avanzini & Giulietti 2012). The run ends when
``|ω|`` falls below ``threshold``, found by a terminal event.

The physics, and what is left out:

* **Orbit.** Integrated with the attitude, not prescribed: the centre of mass starts on a
  circular orbit (``altitude`` above the equatorial radius, ``inclination``, at the
  ascending node on the x axis of an Earth-centred inertial frame) and moves under
  :class:`~tumble.rigid.GravityGradient` — the Earth as a point mass, ``μ = GM`` of WGS 84 —
  which also gives the gravity-gradient torque. No J2, drag or third bodies.
* **Field.** The Earth's centred dipole of IGRF-13 at epoch 2020 (Alken et al. 2021):
  ``g₁⁰, g₁¹, h₁¹`` give the moment's direction (tilted 9.41° from the rotation axis, towards
  geographic south) and its strength, ``B₀ = 29 806 nT`` at ``a = 6371.2 km``;
  ``B(r) = B₀ a³ (3 (m̂·r̂) r̂ − m̂)/r³``, the dipole ``μ₀ M/(4π) = B₀ a³``. With
  ``tilted = false`` the same strength along the rotation axis; with ``earth_rotation``
  the tilted moment turns with the Earth (7.292115e-5 rad/s, the inertial frame and the
  Earth-fixed one aligned at t = 0).
* **Controller.** ``Ḃ_b`` is the analytic rate of the body-frame field,
  ``Ḃ_b = Rᵀ Ḃ_w − ω × B_b`` with ``Ḃ_w`` the field's change along the orbit and with the
  Earth's turn, where a flight computer differentiates its magnetometer's samples (a filtered
  difference): an ideal, continuous B-dot. It is one function of ``(t, state)``
  (:func:`bdot_controller`), a :class:`~tumble.rigid.Torque`, that runs as it is or
  compiled by ``@numba.njit`` (``controller = "numba"``) with the same numbers.

References
----------
.. [1] A. C. Stickler, K. T. Alfriend, "Elementary magnetic attitude control system",
   J. Spacecraft Rockets 13(5) (1976) 282–287.
.. [2] G. Avanzini, F. Giulietti, "Magnetic detumbling of a rigid spacecraft", J. Guid.
   Control Dyn. 35(4) (2012) 1326–1334.
.. [3] P. Alken et al., "International Geomagnetic Reference Field: the thirteenth
   generation", Earth Planets Space 73 (2021) 49.
.. [4] The CubeSat Program, *CubeSat Design Specification*, rev. 13, Cal Poly 2014.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from tumble import _checks, mass
from tumble.io import ScenarioResult
from tumble.rigid import METHODS, GravityGradient, RigidBody, State, Torque, simulate
from tumble.rigid.forces import GM_EARTH
from tumble.scenarios._base import rigid_attrs, rigid_outputs
from tumble.scenarios._common import json_number
from tumble.scenarios.option_models import OptionRules

NAME = "detumble"
SUMMARY = "A 3U cubesat detumbled by a B-dot magnetorquer law in the Earth's dipole field."

LOADED_METHODS = [name for name, method in METHODS.items() if not method.adaptive
                  and not method.exact]  # fmt: skip
"""The methods ``method`` may name: every fixed-step method that takes loads."""
OPTION_RULES = OptionRules(
    positive=["altitude", "gain", "max_dipole", "threshold", "t_end", "h", "record_every"],
    three_vectors=["omega0"],
    methods=LOADED_METHODS,
)
"""What :func:`run`'s options must be beyond its signature."""
CONTROLLERS = ("python", "numba")
"""How the B-dot law runs: as Python, or compiled by ``numba.njit``."""

EARTH_RADIUS = 6378137.0
"""The Earth's equatorial radius (m), WGS 84: altitudes are above it."""
EARTH_RATE = 7.2921150e-5
"""The Earth's rotation rate (rad/s), IERS."""
IGRF_RADIUS = 6371200.0
"""IGRF's reference radius ``a`` (m)."""
IGRF13_DIPOLE = (-29404.8e-9, -1450.9e-9, 4652.5e-9)
"""IGRF-13's degree-1 coefficients at epoch 2020, ``(g₁⁰, g₁¹, h₁¹)`` in T (Alken et al. 2021):
the centred dipole's moment is along ``(g₁¹, h₁¹, g₁⁰)`` (Earth-fixed axes), its strength
``B₀ = |(g₁⁰, g₁¹, h₁¹)|`` at ``a``."""
CUBESAT_SIZE = (0.1, 0.1, 0.3405)
"""A 3U cubesat's envelope (m), its long axis body z."""
CUBESAT_MASS = 4.0
"""Its mass (kg): the 3U limit of the CubeSat Design Specification, rev. 13."""


@dataclass(frozen=True)
class DipoleField:
    """A centred magnetic dipole turning with the Earth: ``B(t, r)`` and its rate.

    Attributes
    ----------
    axis : ndarray, shape (3,)
        The moment's direction at t = 0 (unit, inertial axes).
    strength : float
        ``μ₀ M/(4π) = B₀ a³`` (T m³).
    rate : float
        The moment's turn about the inertial z axis (rad/s); 0 for a field fixed in space.
    """

    axis: np.ndarray
    strength: float
    rate: float

    @classmethod
    def igrf(cls, *, tilted: bool = True, earth_rotation: bool = True) -> DipoleField:
        """IGRF-13's centred dipole at 2020 (module docstring); untilted: along −z."""
        g10, g11, h11 = IGRF13_DIPOLE
        b0 = float(np.sqrt(g10**2 + g11**2 + h11**2))
        axis = np.array([g11, h11, g10]) / b0 if tilted else np.array([0.0, 0.0, -1.0])
        return cls(axis, b0 * IGRF_RADIUS**3, EARTH_RATE if earth_rotation and tilted else 0.0)

    def at(self, t, r, v) -> tuple[np.ndarray, np.ndarray]:
        """``(B, dB/dt)`` (T, T/s; inertial) at times ``t`` (n,), positions ``r`` and
        velocities ``v`` (n, 3): the dipole field and its rate along the path and with the
        moment's turn.

        .. math:: B = \\frac{C}{r^3}\\bigl(3 (\\hat m\\cdot\\hat r)\\hat r - \\hat m\\bigr),
                  \\quad
                  \\dot B = \\frac{3C}{r^5}\\bigl[(\\hat m\\cdot v) r + (\\hat m\\cdot r) v
                  + (r\\cdot v)\\hat m + (\\dot{\\hat m}\\cdot r) r\\bigr]
                  - \\frac{15 C}{r^7}(\\hat m\\cdot r)(r\\cdot v)\\, r
                  - \\frac{C}{r^3}\\dot{\\hat m}.
        """
        t, r, v = np.asarray(t), np.asarray(r), np.asarray(v)
        c, s = np.cos(self.rate * t), np.sin(self.rate * t)
        a = self.axis
        m = np.stack([c * a[0] - s * a[1], s * a[0] + c * a[1], np.broadcast_to(a[2], c.shape)],
                     axis=-1)  # fmt: skip
        m_dot = self.rate * np.stack([-m[..., 1], m[..., 0], np.zeros_like(c)], axis=-1)
        r2 = np.sum(r * r, axis=-1, keepdims=True)
        inv_r3 = 1.0 / (r2 * np.sqrt(r2))
        inv_r5 = inv_r3 / r2

        def dot(p, q):
            return np.sum(p * q, axis=-1, keepdims=True)

        mr, rv = dot(m, r), dot(r, v)
        B = self.strength * (3.0 * mr * inv_r5 * r - inv_r3 * m)
        B_dot = self.strength * (
            3.0 * inv_r5 * (dot(m, v) * r + mr * v + rv * m + dot(m_dot, r) * r)
            - 15.0 * mr * rv * inv_r5 / r2 * r
            - inv_r3 * m_dot
        )
        return B, B_dot


def bdot_controller(
    field: DipoleField, body: RigidBody, *, gain: float, max_dipole: float
) -> Callable[[float, State], np.ndarray]:
    """The B-dot law as a torque ``τ(t, state)`` (N m, inertial axes) for a
    :class:`~tumble.rigid.Torque`.

    ``m = −k Ḃ_b`` in body axes, each component clipped to ``±max_dipole``, with
    ``Ḃ_b = Rᵀ Ḃ_w − ω × B_b``, ``ω = I⁻¹ Rᵀ L``; ``τ = R (m × B_b) = (R m) × B_w``. The
    function reads ``state.x``, ``state.p``, ``state.R`` and ``state.L`` and the constants
    it closes over, in NumPy that numba compiles: ``numba.njit(bdot_controller(...))`` is
    the same law, compiled.

    Parameters
    ----------
    field : DipoleField
        The field the magnetorquers act in.
    body : RigidBody
        The satellite (its mass turns ``p`` into ``v``, its inertia ``L`` into ``ω``).
    gain : float
        ``k`` (A m² s/T).
    max_dipole : float
        Each magnetorquer's largest dipole (A m²).
    """
    k, cap, satellite_mass = float(gain), float(max_dipole), float(body.mass)
    inverse = np.array(body.inertia_inverse)
    axis, strength, rate = np.array(field.axis, dtype=float), float(field.strength), field.rate

    def bdot(t, state):
        r, v, R = state.x, state.p / satellite_mass, state.R
        c, s = math.cos(rate * t), math.sin(rate * t)
        m = np.array([c * axis[0] - s * axis[1], s * axis[0] + c * axis[1], axis[2]])
        m_dot = np.array([-rate * m[1], rate * m[0], 0.0])
        r2 = r @ r
        inv_r3 = 1.0 / (r2 * math.sqrt(r2))
        inv_r5 = inv_r3 / r2
        mr, rv = m @ r, r @ v
        B = strength * (3.0 * mr * inv_r5 * r - inv_r3 * m)
        B_dot = strength * (
            (3.0 * inv_r5 * (m @ v + m_dot @ r) - 15.0 * mr * rv * inv_r5 / r2) * r
            + 3.0 * inv_r5 * (mr * v + rv * m)
            - inv_r3 * m_dot
        )
        B_body = R.T @ B
        w = inverse @ (R.T @ state.L)  # ω, body axes
        spin = np.array([w[1] * B_body[2] - w[2] * B_body[1], w[2] * B_body[0] - w[0] * B_body[2],
                         w[0] * B_body[1] - w[1] * B_body[0]])  # ω × B_b  # fmt: skip
        dipole = np.minimum(np.maximum(-k * (R.T @ B_dot - spin), -cap), cap)
        m = R @ dipole  # the dipole in world axes: τ = (R m) × B
        return np.array([m[1] * B[2] - m[2] * B[1], m[2] * B[0] - m[0] * B[2],
                         m[0] * B[1] - m[1] * B[0]])  # fmt: skip

    return bdot


def commanded_dipoles(run, field: DipoleField, *, gain: float, max_dipole: float) -> np.ndarray:
    """The dipole ``m`` (A m², body axes; (n, 3)) the law commands at each sample of ``run``:
    :func:`bdot_controller`'s, vectorised over the samples."""
    B, B_dot = field.at(run.t, run.x, run.v)
    B_body = np.einsum("nji,nj->ni", run.R, B)
    B_dot_body = np.einsum("nji,nj->ni", run.R, B_dot) - np.cross(run.omega_body, B_body)
    return np.clip(-gain * B_dot_body, -max_dipole, max_dipole)


def cubesat() -> tuple[RigidBody, object]:
    """The 3U cubesat: its body (a uniform box, :data:`CUBESAT_SIZE`, :data:`CUBESAT_MASS`)
    and its surface."""
    from tumble import meshes

    body = RigidBody.from_mass_properties(mass.box(CUBESAT_SIZE, mass=CUBESAT_MASS))
    return body, meshes.box(CUBESAT_SIZE)


def circular_orbit(altitude: float, inclination: float) -> tuple[np.ndarray, np.ndarray, float]:
    """``(x0, v0, period)`` on the circular orbit ``altitude`` (km) above the equator's radius,
    ``inclination`` (degrees), at its ascending node on the inertial x axis."""
    radius = EARTH_RADIUS + 1000.0 * altitude
    speed = np.sqrt(GM_EARTH / radius)
    tilt = np.radians(inclination)
    period = 2.0 * np.pi * radius / speed
    v0 = speed * np.array([0.0, np.cos(tilt), np.sin(tilt)])
    return np.array([radius, 0.0, 0.0]), v0, period


def slow_enough(threshold: float) -> Callable[[float, State], float]:
    """The terminal event ``|ω| − threshold``, falling."""

    def slow(t: float, state: State) -> float:
        assert state.omega is not None  # events are given ω
        return float(np.linalg.norm(state.omega)) - threshold

    slow.terminal, slow.direction = True, -1  # type: ignore[attr-defined]
    return slow


def run(
    *,
    altitude: float = 400.0,
    inclination: float = 51.6,
    omega0: tuple[float, float, float] = (0.1, -0.15, 0.2),
    gain: float = 3.0e4,
    max_dipole: float = 0.1,
    threshold: float = 0.01,
    tilted: bool = True,
    earth_rotation: bool = True,
    controller: str = "python",
    method: str = "rkmk4",
    h: float = 1.0,
    t_end: float = 30000.0,
    record_every: int = 1,
) -> ScenarioResult:
    """Detumble the cubesat until ``|ω| < threshold`` or ``t_end``.

    Parameters
    ----------
    altitude : float
        Of the circular orbit, above the equatorial radius (km).
    inclination : float
        Of the orbit (degrees; 51.6: deployed from the ISS).
    omega0 : sequence of 3 floats
        Initial body rates (rad/s); the default is 15.4 °/s.
    gain : float
        The B-dot gain ``k`` (A m² s/T): near Avanzini and Giulietti's best,
        ``2n (1 + sin i) I_min/B²``, for the default orbit.
    max_dipole : float
        Each magnetorquer's saturation (A m²).
    threshold : float
        The rate (rad/s) below which the satellite counts as detumbled: the run ends there.
    tilted : bool
        IGRF-13's tilted dipole (True) or the same along the rotation axis.
    earth_rotation : bool
        The tilted dipole turns with the Earth.
    controller : str
        ``"python"``: the law runs as Python; ``"numba"``: compiled by ``numba.njit`` (the
        same numbers; today both are called from Python at each stage).
    method : str
        A fixed-step method of :data:`tumble.rigid.METHODS` that takes loads.
    h : float
        Step (s).
    t_end : float
        The longest run (s), if ``|ω|`` stays above the threshold.
    record_every : int
        Keep every k-th step (and the last).

    Returns
    -------
    ScenarioResult
        ``summary``: ``detumbled``, ``time_to_detumble`` (s; None if not reached),
        ``orbits_to_detumble``, ``initial_rate`` and ``final_rate`` (rad/s),
        ``largest_dipole`` (A m²), ``saturated_fraction`` (of the samples, any axis at its
        limit), the body, the orbit and the settings. Figure ``detumble.png`` (|ω| on a log
        scale, the commanded dipole, the attitude against the orbit normal); ``data.nc``
        with the run (group ``orbit``, the commanded dipole beside it) and the same run about
        its centre of mass (group ``attitude``: x = v = 0), which ``animation.gif`` and
        ``view.html`` show.

    Examples
    --------
    Down to 0.1 rad/s, in steps of 2 s (the independent integration of
    ``tests/scenarios/test_scenario_detumble.py``: 1007.477 s):

    >>> result = run(threshold=0.1, h=2.0, record_every=100)
    >>> result.summary["detumbled"], round(result.summary["time_to_detumble"], 2)
    (True, 1006.82)
    """
    _checks.choice("controller", controller, CONTROLLERS)
    if not -180.0 <= _checks.finite("inclination", inclination, "degrees") <= 180.0:
        raise _checks.fail("inclination", inclination, "within [-180, 180]", "degrees")
    _checks.positive("threshold", threshold, "rad/s")
    body, mesh = cubesat()
    field = DipoleField.igrf(tilted=tilted, earth_rotation=earth_rotation)
    law = bdot_controller(field, body, gain=gain, max_dipole=max_dipole)
    if controller == "numba":
        import numba

        law = numba.njit(law)
    x0, v0, period = circular_orbit(_checks.positive("altitude", altitude, "km"), inclination)
    trajectory = simulate(
        body, t_end, method=method, h=h, x0=x0, v0=v0, omega0=omega0,
        forces=[GravityGradient(), Torque(law)], events=[slow_enough(threshold)],
        record_every=record_every,
    )  # fmt: skip
    settings = dict(altitude=altitude, inclination=inclination, omega0=list(omega0), gain=gain,
                    max_dipole=max_dipole, threshold=threshold, tilted=tilted,
                    earth_rotation=earth_rotation, controller=controller, method=method, h=h,
                    t_end=t_end, record_every=record_every)  # fmt: skip
    return _result(trajectory, body, mesh, field, period, (x0, v0), settings)


def _result(trajectory, body, mesh, field, period, start, settings) -> ScenarioResult:
    """The run's summary, figure, datasets and moving-body outputs."""
    gain, max_dipole = settings["gain"], settings["max_dipole"]
    dipoles = commanded_dipoles(trajectory, field, gain=gain, max_dipole=max_dipole)
    summary = _summary(trajectory, dipoles, body, period, settings)
    title = (f"{NAME} — 3U cubesat, {settings['altitude']:g} km, {settings['inclination']:g}°, "
             f"k = {gain:g} A m² s/T, |m| ≤ {max_dipole:g} A m², {settings['method']}, "
             f"h = {settings['h']:g} s")  # fmt: skip
    # The animation and view.html show the attitude: the run seen from its centre of mass
    # (a 34 cm body on a 6800 km orbit is a point at the orbit's scale)
    zeros = np.zeros_like(trajectory.x)
    about_centre = dataclasses.replace(trajectory, x=zeros, v=zeros,
                                       potential_energy=np.zeros(len(trajectory.t)))  # fmt: skip
    runs = {"orbit": trajectory, "attitude": about_centre}
    outputs = rigid_outputs(runs, mesh, shown="attitude",
                            title=f"{title}\nabout its centre of mass")  # fmt: skip
    outputs["datasets"]["orbit"] = _with_dipoles(outputs["datasets"]["orbit"], dipoles)
    attrs = {key: int(value) if isinstance(value, bool) else value
             for key, value in settings.items()}  # fmt: skip
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectory": trajectory, "dipoles": dipoles, "body": body, "field": field},
        figures=[("detumble.png", partial(_figure, trajectory, dipoles, summary, start, title))],
        attrs=rigid_attrs(body, **attrs),
        **outputs,
    )


def _summary(trajectory, dipoles, body, period, settings) -> dict:
    rates = np.linalg.norm(trajectory.omega_body, axis=1)
    detumbled = bool(trajectory.t_events[0].size)
    when = float(trajectory.t_events[0][0]) if detumbled else None
    saturated = np.any(np.abs(dipoles) >= settings["max_dipole"], axis=1)
    return {
        "scenario": NAME,
        **settings,
        "mass": body.mass,
        "inertia": np.diag(body.inertia).tolist(),
        "orbit_period": period,
        "detumbled": detumbled,
        "time_to_detumble": when,
        "orbits_to_detumble": when / period if detumbled else None,
        "initial_rate": float(rates[0]),
        "final_rate": json_number(rates[-1]),
        "largest_dipole": json_number(np.abs(dipoles).max()),
        "saturated_fraction": float(saturated.mean()),
        "n_steps": trajectory.n_steps,
        "status": trajectory.status.name,
    }


def _with_dipoles(dataset, dipoles: np.ndarray):
    """``data.nc``'s trajectory with the commanded dipole beside it."""
    return dataset.assign(
        dipole=(("time", "axis"), dipoles,
                {"units": "A m2", "long_name": "commanded magnetic dipole, body axes"}),
    )  # fmt: skip


def _figure(trajectory, dipoles, summary, start, title, path) -> None:
    from tumble.viz.detumble import detumble_figure

    normal = np.cross(*start)  # x0 × v0
    detumble_figure(trajectory, dipoles, path, threshold=summary["threshold"],
                    max_dipole=summary["max_dipole"], orbit_normal=normal / np.linalg.norm(normal),
                    period=summary["orbit_period"], title=title)  # fmt: skip
