"""References for the truth suite that share no code with tumble.

**The free body, in extended precision (mpmath).** Sort the principal moments A < B < C by a
rotation Q of the body axes (a permutation, negated when it is odd). With ``M = |L|`` and
``2E = ω·Iω``, Euler's equations ``I ω̇ = (I ω) × ω`` are solved by Jacobi's functions
(Landau & Lifshitz, *Mechanics*, §37, eqs. 37.10–37.12; Whittaker, *Analytical Dynamics*,
§69). When ``M² > 2EB`` (the spin goes round the C axis)::

    ω = (a₁ cn τ, s a₂ sn τ, s a₃ dn τ),   s = sign ω₃,
    a₁² = (2EC − M²)/(A(C−A)),  a₂² = (2EC − M²)/(B(C−B)),  a₃² = (M² − 2EA)/(C(C−A)),
    dτ/dt = r = √((C−B)(M² − 2EA)/(ABC)),   m = k² = (B−A)(2EC − M²)/((C−B)(M² − 2EA)),

and when ``M² < 2EB`` (round the A axis), with ``s = sign ω₁``::

    ω = (s a₁ dn τ, s a₂ sn τ, a₃ cn τ),
    a₂² = (M² − 2EA)/(B(B−A)),   r = √((B−A)(2EC − M²)/(ABC)),
    m = (C−B)(M² − 2EA)/((B−A)(2EC − M²))    (a₁, a₃ as above).

The signs follow from putting the forms into Euler's equations (``cn' = −sn dn`` etc.);
``τ₀`` is ``F(θ₀|m)`` with ``θ₀ = atan2(sn τ₀, cn τ₀)`` read from ω(0).

The attitude, derived here and checked against quadrature and DOP853 by
``test_truth_reference.py``: let ``l = m/M`` be the body momentum's direction and ``N(l)`` the
rotation with rows ``n₁ = (l₂, −l₁, 0)/ρ``, ``n₂ = l × n₁``, ``l`` (``ρ² = l₁² + l₂²``, never 0
off the pure C spin). Since ``Rᵀ L`` is the body momentum, ``P = N(l(0)) R N(l(t))ᵀ`` fixes
the z axis, so it is ``Rz(φ)``: ``R(t) = N(l(0))ᵀ Rz(φ(t)) N(l(t))`` solves ``Ṙ = R ω̂``,
``R(0) = 1`` exactly when ``φ̇ ẑ = N ω + (N Ṅᵀ)ᵛ``, whose z part is ``φ̇ = l·ω + n₂·ṅ₁``;
with ``l̇ = l × ω`` this is::

    φ̇ = (l₁ω₁ + l₂ω₂)/ρ² = M (Aω₁² + Bω₂²)/(A²ω₁² + B²ω₂²)
       = M/C + M (2EC − M²) / (C (M² − C²ω₃²))                     (Landau eq. 37.15)

and ``M² − C²ω₃² = α + β sn²τ`` (``α = M² − C²a₃²``, ``β = C²a₃² m`` round C, ``β = C²a₃²``
round A), so ``φ(t) = M t/C + M(2EC − M²)/(C α r) [Π(n; am τ|m) − Π(n; am τ₀|m)]`` with
``n = −β/α``: mpmath's ``ellippi``, continued past ``|am| = π/2`` by
``Π(n; θ + jπ|m) = Π(n; θ|m) + 2jΠ(n|m)``.

The inputs are the float64 numbers tumble is given, converted exactly; at 40 digits the
invariants ``M²`` and ``2E`` (sums of products of doubles, ~110 bits) are exact, so the
distance to the separatrix ``M² − 2EB`` keeps 25 digits even at 1e-14 of ``M²``.

**Forced bodies**: :func:`forced_rotation`, scipy's DOP853 at ``rtol = 1e-13`` on Euler's
equations in the body frame with a quaternion, a formulation tumble does not use (it steps
the world ``L`` on SO(3)); ``test_truth_reference.py`` holds it to mpmath's Taylor
integrator (``mpmath.odefun``) at 20 digits, and to the closed form above without loads.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import mpmath as mp
import numpy as np

DPS = 40
"""Digits of the free-body reference: the invariants of float64 inputs are exact at 34."""

ULP = 2.0**-52
"""The spacing of doubles at 1 (2.2e-16): the unit of the round-off floors."""


def _mp(x) -> mp.mpf:
    return mp.mpf(float(x))


def sorting_rotation(moments: tuple[float, float, float]) -> np.ndarray:
    """The rotation Q with ``Q diag(moments) Qᵀ = diag(sorted)``: rows are ± the body axes
    in increasing moment, the last negated when the permutation is odd (so det Q = 1)."""
    order = np.argsort(moments, kind="stable")
    Q = np.eye(3)[order]
    if np.linalg.det(Q) < 0:
        Q[2] = -Q[2]
    return Q


class Orbit:
    """The torque-free motion in the sorted principal frame from a body momentum ``m0``
    (mpmath numbers, A < B < C), with ``R(0) = 1``."""

    def __init__(self, moments, m0):
        A, B, C = moments
        self.moments = moments
        self.m0 = m0
        M2 = m0[0] ** 2 + m0[1] ** 2 + m0[2] ** 2
        E2 = m0[0] ** 2 / A + m0[1] ** 2 / B + m0[2] ** 2 / C  # 2E
        self.M, self.E2 = mp.sqrt(M2), E2
        self.distance = (M2 - E2 * B) / M2  # (M² − 2EB)/M²: > 0 round C, < 0 round A
        up, low = E2 * C - M2, M2 - E2 * A  # 2EC − M², M² − 2EA: both > 0
        if up <= 0 or low <= 0 or self.distance == 0:
            raise ValueError("a spin about a principal axis or on the separatrix")
        self.a = [mp.sqrt(up / (A * (C - A))), None, mp.sqrt(low / (C * (C - A)))]
        w0 = [m0[i] / moments[i] for i in range(3)]
        if self.distance > 0:  # round C
            self.pole = 2
            self.a[1] = mp.sqrt(up / (B * (C - B)))
            self.rate = mp.sqrt((C - B) * low / (A * B * C))
            self.m = (B - A) * up / ((C - B) * low)
            self.sign = mp.sign(w0[2])
            cn0, sn0 = w0[0] / self.a[0], self.sign * w0[1] / self.a[1]
            beta_scale = self.m
        else:  # round A
            self.pole = 0
            self.a[1] = mp.sqrt(low / (B * (B - A)))
            self.rate = mp.sqrt((B - A) * up / (A * B * C))
            self.m = (C - B) * low / ((B - A) * up)
            self.sign = mp.sign(w0[0])
            cn0, sn0 = w0[2] / self.a[2], self.sign * w0[1] / self.a[1]
            beta_scale = mp.mpf(1)
        self.K = mp.ellipk(self.m)
        self.tau0 = self._tau_of_amplitude(mp.atan2(sn0, cn0))
        alpha = M2 - C**2 * self.a[2] ** 2
        beta = C**2 * self.a[2] ** 2 * beta_scale
        self.n = -beta / alpha
        self.pi_scale = self.M * up / (C * alpha * self.rate)
        self.N0 = self._frame([m0[0] / self.M, m0[1] / self.M, m0[2] / self.M])

    @functools.cached_property
    def Pi_complete(self):
        return mp.ellippi(self.n, self.m)

    @functools.cached_property
    def Pi0(self):
        return self._Pi_of_tau(self.tau0)

    def _tau_of_amplitude(self, theta):
        """``F(θ|m)`` for θ in (−π, π]: ``F(θ ± π) = F(θ) ± 2K``."""
        if theta > mp.pi / 2:
            return mp.ellipf(theta - mp.pi, self.m) + 2 * self.K
        if theta < -mp.pi / 2:
            return mp.ellipf(theta + mp.pi, self.m) - 2 * self.K
        return mp.ellipf(theta, self.m)

    def _jacobi(self, tau):
        """``(sn, cn, dn, am)`` at τ, reduced by half periods: ``sn, cn`` change sign over
        2K, ``dn`` does not, ``am`` gains π."""
        j = mp.nint(tau / (2 * self.K))
        rest = tau - 2 * self.K * j
        sn, cn, dn = (mp.ellipfun(kind, rest, m=self.m) for kind in ("sn", "cn", "dn"))
        flip = -1 if int(j) % 2 else 1
        return flip * sn, flip * cn, dn, mp.atan2(sn, cn) + j * mp.pi

    def _Pi_of_tau(self, tau):
        j = mp.nint(tau / (2 * self.K))
        rest = tau - 2 * self.K * j
        theta = mp.atan2(mp.ellipfun("sn", rest, m=self.m), mp.ellipfun("cn", rest, m=self.m))
        return mp.ellippi(self.n, theta, self.m) + 2 * j * self.Pi_complete

    def omega(self, t):
        """Body angular velocity at ``t`` (mpmath, sorted frame)."""
        sn, cn, dn, _ = self._jacobi(self.tau0 + self.rate * t)
        a, s = self.a, self.sign
        if self.pole == 2:
            return [a[0] * cn, s * a[1] * sn, s * a[2] * dn]
        return [s * a[0] * dn, s * a[1] * sn, a[2] * cn]

    def momentum(self, t):
        w = self.omega(t)
        return [self.moments[i] * w[i] for i in range(3)]

    @staticmethod
    def _frame(l):
        rho = mp.sqrt(l[0] ** 2 + l[1] ** 2)
        n1 = [l[1] / rho, -l[0] / rho, mp.mpf(0)]
        n2 = [l[2] * l[0] / rho, l[2] * l[1] / rho, -rho]
        return mp.matrix([n1, n2, list(l)])

    def precession(self, t):
        """φ(t), with φ(0) = 0."""
        tau = self.tau0 + self.rate * t
        return self.M * t / self.moments[2] + self.pi_scale * (self._Pi_of_tau(tau) - self.Pi0)

    def rotation(self, t):
        """``R(t)`` (mpmath 3×3, sorted frame, ``R(0) = 1``)."""
        w = self.omega(t)
        l = [self.moments[i] * w[i] / self.M for i in range(3)]
        phi = self.precession(t)
        c, s = mp.cos(phi), mp.sin(phi)
        Rz = mp.matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        return self.N0.T * Rz * self._frame(l)

    def zero_near(self, t):
        """The zero of ω₂ nearest to ``t``."""
        j = mp.nint((self.tau0 + self.rate * t) / (2 * self.K))
        return (2 * self.K * j - self.tau0) / self.rate

    def zeros_of_middle(self, t_end):
        """Times in (0, t_end] where the middle-axis rate ω₂ changes sign (the flips):
        ``sn τ = 0`` at ``τ = 2Kj``."""
        first = int(mp.floor(self.tau0 / (2 * self.K))) + 1
        times = []
        j = first
        while True:
            t = (2 * self.K * j - self.tau0) / self.rate
            if t > t_end:
                return times
            if t > 0:
                times.append(t)
            j += 1


def _to_numpy(matrix) -> np.ndarray:
    return np.array([[float(matrix[i, j]) for j in range(3)] for i in range(3)])


@dataclass(frozen=True)
class FreeBodyTruth:
    """What the reference says about one free-body problem, as floats.

    Attributes
    ----------
    R : ndarray, shape (3, 3)
        The attitude at ``t_end``.
    omega : ndarray, shape (3,)
        The body angular velocity at ``t_end``.
    distance : float
        ``(M² − 2EB)/M²``: > 0 round the largest axis, < 0 round the smallest.
    period : float
        The period of ω (s): ``4K/r``.
    sensitivity : float
        How far ``R(t_end)`` moves (Frobenius) for a perturbation of the body momentum by
        one unit of ``ULP·|L|``, anywhere on the orbit: the largest over perturbations along
        each body axis, made at t = 0 and at the first crossing of the middle axis's zero
        (mid-flip, where an ulp changes the distance to the separatrix the most), times √3
        (three directions bound the worst one).
    """

    R: np.ndarray
    omega: np.ndarray
    distance: float
    period: float
    sensitivity: float


def _body_frame(moments, omega0):
    """The sorted frame's moments and momentum (mpmath) and Q, from float64 inputs."""
    Q = sorting_rotation(moments)
    sorted_moments = [_mp(x) for x in np.sort(moments)]
    m_body = [_mp(moments[i]) * _mp(omega0[i]) for i in range(3)]
    m0 = [sum(_mp(Q[i, j]) * m_body[j] for j in range(3)) for i in range(3)]
    return Q, sorted_moments, m0


def _perturbed_end(orbit: Orbit, t_start, t_end, delta):
    """R(t_end) when the momentum is moved by ``delta`` (mpmath vector) at ``t_start``:
    ``R(t_end) = R(t_start) R_{m'}(t_end − t_start)`` (the free body is left-invariant)."""
    R_start = orbit.rotation(t_start) if t_start != 0 else mp.eye(3)
    m = orbit.momentum(t_start) if t_start != 0 else orbit.m0
    moved = Orbit(orbit.moments, [m[i] + delta[i] for i in range(3)])
    return R_start * moved.rotation(t_end - t_start)


@functools.lru_cache(maxsize=256)
def free_body(moments: tuple, omega0: tuple, t_end: float, sensitivity: bool = True):
    """The :class:`FreeBodyTruth` of the body ``diag(moments)`` spun at ``omega0`` (body
    frame, rad/s) from ``R(0) = 1``, at ``t_end``. Cached: hypothesis draws the same
    problems for every method of a parametrised test."""
    with mp.workdps(DPS):
        Q, sorted_moments, m0 = _body_frame(moments, omega0)
        orbit = Orbit(sorted_moments, m0)
        T = _mp(t_end)
        Rs, ws = orbit.rotation(T), orbit.omega(T)
        R = Q.T @ _to_numpy(Rs) @ Q
        omega = Q.T @ np.array([float(w) for w in ws])
        period = float(4 * orbit.K / orbit.rate)
        worst = 0.0
        if sensitivity:
            delta = ULP * float(orbit.M)
            for start in [mp.mpf(0)] + orbit.zeros_of_middle(T)[:1]:
                base = _perturbed_end(orbit, start, T, [0, 0, 0])
                for axis in range(3):
                    step = [mp.mpf(delta) if i == axis else mp.mpf(0) for i in range(3)]
                    moved = _perturbed_end(orbit, start, T, step)
                    worst = max(worst, float(mp.mnorm(moved - base, "f")))
        return FreeBodyTruth(
            R=R,
            omega=omega,
            distance=float(orbit.distance),
            period=period,
            sensitivity=math.sqrt(3.0) * worst,
        )


@dataclass(frozen=True)
class RateTruth:
    """The body rate after a time ``t``, and how it answers an ulp.

    Attributes
    ----------
    omega : ndarray, shape (3,)
        ω(t), body frame (rad/s).
    floor : float
        The round-off ``|δω(t)|`` that one ulp of every term leaves in each flow: for each
        time a flow starts, ``ULP |ω|`` plus, for each body axis, the change of ω(t) when
        the momentum there is moved by ``ULP·|L|`` along it (rad/s).
    """

    omega: np.ndarray
    floor: float


@functools.lru_cache(maxsize=256)
def free_body_rate(moments: tuple, omega0: tuple, t: float, starts: tuple = (0.0,)):
    """ω(t) of the body ``diag(moments)`` spun at ``omega0``, and its :class:`RateTruth`
    floor for flows that start at the times ``starts`` (a composition such as Yoshida's
    passes through states beyond ``t`` and back, where an ulp may weigh more)."""
    with mp.workdps(DPS):
        Q, sorted_moments, m0 = _body_frame(moments, omega0)
        orbit = Orbit(sorted_moments, m0)
        T = _mp(t)
        base = orbit.omega(T)
        delta = ULP * float(orbit.M)
        floor = 0.0
        for start in (_mp(s) for s in starts):
            m = orbit.momentum(start) if start != 0 else m0
            floor += ULP * float(mp.sqrt(sum(w**2 for w in orbit.omega(start))))
            for axis in range(3):
                moved = [m[i] + (delta if i == axis else 0) for i in range(3)]
                other = Orbit(sorted_moments, moved).omega(T - start)
                floor += float(mp.sqrt(sum((other[i] - base[i]) ** 2 for i in range(3))))
        omega = Q.T @ np.array([float(w) for w in base])
        return RateTruth(omega=omega, floor=floor)


def orbit_period(moments: tuple, omega0: tuple) -> float:
    """The period of ω (s), ``4K/r``: to choose spans and steps before asking for the rest."""
    with mp.workdps(DPS):
        _, sorted_moments, m0 = _body_frame(moments, omega0)
        orbit = Orbit(sorted_moments, m0)
        return float(4 * orbit.K / orbit.rate)


@dataclass(frozen=True)
class FlipTruth:
    """The flips of the middle-axis rate in (0, t_end] and how far an ulp moves them.

    Attributes
    ----------
    times : ndarray
        The times where ω₂ changes sign (s).
    nearest : float
        The flip nearest to ``t_end``, before or after it (s).
    shift : float
        How far the flip nearest ``t_end`` moves (s) when the momentum is moved by
        ``ULP·|L|`` along any body axis (√3 times the largest of the three), at t = 0 or at
        the first flip.
    """

    times: np.ndarray
    nearest: float
    shift: float


@functools.lru_cache(maxsize=256)
def free_body_flips(moments: tuple, omega0: tuple, t_end: float) -> FlipTruth:
    """The :class:`FlipTruth` of the body ``diag(moments)`` spun at ``omega0`` over
    ``(0, t_end]``: Jacobi's functions alone (no third integral), so it is cheap."""
    with mp.workdps(DPS):
        _, sorted_moments, m0 = _body_frame(moments, omega0)
        orbit = Orbit(sorted_moments, m0)
        T = _mp(t_end)
        flips = orbit.zeros_of_middle(T)
        last = orbit.zero_near(T)
        delta = ULP * float(orbit.M)
        shift = 0.0
        for start in [mp.mpf(0)] + flips[:1]:
            m = orbit.momentum(start) if start != 0 else orbit.m0
            for axis in range(3):
                moved = [m[i] + (delta if i == axis else 0) for i in range(3)]
                near = start + Orbit(sorted_moments, moved).zero_near(last - start)
                shift = max(shift, float(abs(near - last)))
        times = np.array([float(t) for t in flips])
        return FlipTruth(times, float(last), math.sqrt(3.0) * shift)


@dataclass(frozen=True)
class Loads:
    """Constant loads on a body of unit mass, in the terms both tumble and the reference
    take: a world torque (N m), a body-fixed dipole ``moment`` (A m², body) in a world
    ``field`` (T), a world ``force`` (N) at a body ``point`` (m, from the centre of mass),
    and gravity ``g`` (m/s², world) about a body ``pivot`` (m, from the centre of mass).
    Zero vectors (and ``pivot=None``) are absent loads."""

    torque: tuple = (0.0, 0.0, 0.0)
    moment: tuple = (0.0, 0.0, 0.0)
    field: tuple = (0.0, 0.0, 0.0)
    force: tuple = (0.0, 0.0, 0.0)
    point: tuple = (0.0, 0.0, 0.0)
    g: tuple = (0.0, 0.0, 0.0)
    pivot: tuple | None = None

    def inertia(self, moments: tuple) -> np.ndarray:
        """The inertia the body turns with: about the pivot (parallel axis) if there is one."""
        inertia = np.diag(moments)
        if self.pivot is None:
            return inertia
        p = np.array(self.pivot)
        return inertia + (p @ p) * np.eye(3) - np.outer(p, p)

    def body_torque(self, R: np.ndarray) -> np.ndarray:
        """The torque in body axes at the attitude ``R``, about the centre of mass or the
        pivot ``p``: ``Rᵀτ + μ × RᵀB + (r − p) × RᵀF`` and gravity's ``(−p) × Rᵀg`` (unit
        mass; the pivot's reaction acts at the pivot, with no torque about it)."""
        origin = np.zeros(3) if self.pivot is None else np.array(self.pivot)
        torque = R.T @ np.array(self.torque)
        torque += np.cross(self.moment, R.T @ np.array(self.field))
        torque += np.cross(np.array(self.point) - origin, R.T @ np.array(self.force))
        torque += np.cross(-origin, R.T @ np.array(self.g))
        return torque


def _quaternion_rotation(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def _quaternion(R: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def _euler_field(inertia: np.ndarray, loads: Loads):
    """Euler's equations in the body frame with a quaternion:
    ``I ω̇ = (Iω) × ω + τ_body(R)``, ``q̇ = ½ q ⊗ (0, ω)``."""
    inverse = np.linalg.inv(inertia)

    def field(t, y):
        q, w = y[:4], y[4:]
        R = _quaternion_rotation(q)
        dw = inverse @ (np.cross(inertia @ w, w) + loads.body_torque(R))
        q0, q1, q2, q3 = q
        dq = 0.5 * np.array([
            -q1 * w[0] - q2 * w[1] - q3 * w[2],
            q0 * w[0] + q2 * w[2] - q3 * w[1],
            q0 * w[1] + q3 * w[0] - q1 * w[2],
            q0 * w[2] + q1 * w[1] - q2 * w[0],
        ])  # fmt: skip
        return np.concatenate([dq, dw])

    return field


REFERENCE_RTOL = 1e-13
"""DOP853's tolerance for the forced reference (its error measured in the tests: 1e-12 …
1e-11 relative over a few turns)."""


def forced_rotation(moments: tuple, omega0: tuple, R0: np.ndarray, loads: Loads,
                    t_end: float, rtol: float = REFERENCE_RTOL,
                    method: str = "DOP853") -> np.ndarray:  # fmt: skip
    """``R(t_end)`` of a forced body by scipy's DOP853 (Hairer, Nørsett & Wanner §II.10), or
    another of ``solve_ivp``'s methods, on Euler's equations in the body frame with a
    quaternion; ``atol = rtol·1e-3`` in units of the state (1 and |ω₀|)."""
    from scipy.integrate import solve_ivp

    y0 = np.concatenate([_quaternion(R0), omega0])
    field = _euler_field(loads.inertia(moments), loads)
    scale = float(np.linalg.norm(omega0))
    atol = rtol * 1e-3 * np.array([1, 1, 1, 1, scale, scale, scale])
    solution = solve_ivp(field, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol)
    assert solution.success, solution.message
    return _quaternion_rotation(solution.y[:4, -1])


@dataclass(frozen=True)
class ForcedTruth:
    """What DOP853 says about one forced problem.

    Attributes
    ----------
    R : ndarray, shape (3, 3)
        The attitude at ``t_end``, at rtol 1e-13.
    error : float
        A bound on its error: its change from rtol 1e-11 (DOP853's error falls with rtol).
    sensitivity : float
        How far ``R(t_end)`` moves per unit relative change of ω₀ (a finite difference of
        1e-7 along (1, −2, 3)/√14 at rtol 1e-11, times √3 for the other directions).
    """

    R: np.ndarray
    error: float
    sensitivity: float


@functools.lru_cache(maxsize=256)
def forced_body(moments: tuple, omega0: tuple, R0: tuple, loads: Loads, t_end: float):
    """The :class:`ForcedTruth` of ``diag(moments)`` spun at ``omega0`` from ``R0`` under
    ``loads`` (unit mass), at ``t_end``."""
    R0 = np.array(R0)
    omega0 = np.array(omega0)
    R = forced_rotation(moments, omega0, R0, loads, t_end)
    rough = forced_rotation(moments, omega0, R0, loads, t_end, rtol=1e-11)
    nudge = 1e-7 * np.linalg.norm(omega0) * np.array([1.0, -2.0, 3.0]) / math.sqrt(14.0)
    moved = forced_rotation(moments, omega0 + nudge, R0, loads, t_end, rtol=1e-11)
    sensitivity = math.sqrt(3.0) * float(np.linalg.norm(moved - rough)) / 1e-7
    # the rtol 1e-11 run's distance bounds the rtol 1e-13 run's error; 16 ulps stand for
    # the quaternion's conversion to R, should the two runs agree by chance
    return ForcedTruth(R, float(np.linalg.norm(R - rough)) + 16 * ULP, sensitivity)
