"""The torque-free body's closed forms and the elliptic functions they need.

Private helpers of `tumble.exact`, which documents the formulas (and docs/exact.md derives
them). `classify` picks the case (constant, symmetric, elliptic, separatrix);
`EllipticMotion` holds the asymmetric solution in the sorted principal frame.

The elliptic functions take the elliptic parameter ``m = k²`` together with its complement
``m1 = 1 − m``, computed by the caller without cancellation. Near the separatrix of the free
body ``m → 1``, and ``1 − m`` formed from ``m`` would keep only a few digits; with ``m1`` given,
the Carlson forms and the arithmetic–geometric mean below stay accurate to round-off.

References
----------
.. [1] B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
   Numer. Algorithms 10 (1995) 13–26; DLMF §19.25.
.. [2] M. Abramowitz, I. A. Stegun, Handbook of Mathematical Functions, §16.4 (AGM).
.. [3] L. D. Landau, E. M. Lifshitz, Mechanics, 3rd ed., §37.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks

#: The arithmetic–geometric mean stops when ``c_n ≤ AGM_TOL * a_n`` (one ulp: a and b can
#: settle on neighbouring floats) or after AGM_MAX_STEPS (m1 = 1e-300 needs about 15).
AGM_TOL = float(np.finfo(float).eps)
AGM_MAX_STEPS = 64
#: Principal moments closer than this fraction of the largest count as equal (symmetric body).
SYMMETRY_RTOL = 1e-12
#: |Δ| below this fraction of its two terms counts as exactly on the separatrix.
SEPARATRIX_RTOL = 1e-12
#: 1 − m below this also counts as the separatrix (K = 347 there; Carlson's R_F overflows
#: for subnormal arguments).
M1_MIN = 1e-300
#: Largest |I − Iᵀ| accepted for a full inertia tensor, relative to max |I|.
SYMMETRIC_RTOL = 1e-10
#: Largest |RᵀR − Id| accepted for an initial attitude.
ROTATION_ATOL = 1e-10


def incomplete_first(phi: np.ndarray, m1: float) -> np.ndarray:
    """F(φ|m) = sin φ R_F(cos²φ, cos²φ + m1 sin²φ, 1) for |φ| ≤ π/2 (DLMF 19.25.5)."""
    from scipy.special import elliprf  # 0.18 s to import: only where it is needed

    s, c = np.sin(phi), np.cos(phi)
    return s * elliprf(c * c, c * c + m1 * s * s, 1.0)


def incomplete_third(n: float, phi: np.ndarray, m1: float) -> np.ndarray:
    """Π(n; φ|m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ)) for |φ| ≤ π/2 (DLMF 19.25.14)."""
    from scipy.special import elliprf, elliprj

    s, c = np.sin(phi), np.cos(phi)
    y = c * c + m1 * s * s
    return s * elliprf(c * c, y, 1.0) + n / 3.0 * s**3 * elliprj(c * c, y, 1.0, 1.0 - n * s * s)


def complete_first(m1: float) -> float:
    """K(m) = R_F(0, m1, 1)."""
    from scipy.special import elliprf

    return float(elliprf(0.0, m1, 1.0))


def complete_third(n: float, m1: float) -> float:
    """Π(n|m) = R_F(0, m1, 1) + (n/3) R_J(0, m1, 1, 1 − n)."""
    from scipy.special import elliprf, elliprj

    return float(elliprf(0.0, m1, 1.0) + n / 3.0 * elliprj(0.0, m1, 1.0, 1.0 - n))


def jacobi(u: np.ndarray, m: float, m1: float) -> tuple[np.ndarray, ...]:
    """sn, cn, dn and am of u by the arithmetic–geometric mean (A&S 16.4).

    Accurate for |u| ≤ K(m); ``dn = √(cn² + m1 sn²)`` avoids the cancellation in 1 − m sn².
    """
    a, b, c = 1.0, np.sqrt(m1), np.sqrt(m)
    ratios: list[float] = []
    while c > AGM_TOL * a and len(ratios) < AGM_MAX_STEPS:
        a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.5 * (a - b)
        ratios.append(c / a)
    phi = 2.0 ** len(ratios) * a * np.asarray(u, dtype=float)
    for ratio in reversed(ratios):
        phi = 0.5 * (phi + np.arcsin(ratio * np.sin(phi)))
    sn, cn = np.sin(phi), np.cos(phi)
    return sn, cn, np.sqrt(cn * cn + m1 * sn * sn), phi


@dataclass(frozen=True)
class EllipticMotion:
    """ω(t) of an asymmetric body, A < B < C, in its sorted principal frame.

    Regime "C" (|L|² > 2EB, spin nearer the largest axis) and regime "A" (|L|² < 2EB):
    ``ω_other = a cn(u)``, ``ω_B = σ a_B sn(u)``, ``ω_pole = σ a_pole dn(u)``, with
    ``u = u0 + λ t``, pole = C, other = A in regime C and the reverse in regime A, and
    σ = sign ω_pole(0) (Landau & Lifshitz §37, signs fixed by substituting in Euler's equations).
    """

    moments: np.ndarray  # (3,) sorted A < B < C
    amplitudes: np.ndarray  # (3,) a_A, a_B, a_C
    pole: int  # 2 in regime C, 0 in regime A
    sign: float  # σ
    rate: float  # λ, rad/s
    m: float
    m1: float
    u0: float

    @property
    def quarter(self) -> float:
        """K(m), a quarter period of the argument u."""
        return complete_first(self.m1)

    @property
    def period(self) -> float:
        """Period of ω(t): 4K(m)/λ."""
        return 4.0 * self.quarter / self.rate

    def reduce(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """u(t) = 2K j + r with r in [−K, K); returns (r, j)."""
        k = self.quarter
        u = self.u0 + self.rate * t
        j = np.floor((u + k) / (2.0 * k))
        return u - 2.0 * k * j, j

    def omega(self, t: np.ndarray) -> np.ndarray:
        """ω(t) in the sorted principal frame, shape (n, 3)."""
        r, j = self.reduce(t)
        sn, cn, dn, _ = jacobi(r, self.m, self.m1)
        flip = 1.0 - 2.0 * np.mod(j, 2.0)  # sn, cn change sign every 2K; dn does not
        out = np.empty((t.size, 3))
        out[:, 2 - self.pole] = self.amplitudes[2 - self.pole] * flip * cn
        out[:, 1] = self.sign * self.amplitudes[1] * flip * sn
        out[:, self.pole] = self.sign * self.amplitudes[self.pole] * dn
        return out

    def precession(self, t: np.ndarray, momentum: float) -> np.ndarray:
        """Angle φ(t) − φ(0) about L of the pole frame, rad (Landau & Lifshitz §37).

        φ̇ = |L| / I_pole ± |L| (C − A)/(A C) / (1 + ν sn²u), integrated with
        ∫ du / (1 + ν sn²u) = Π(−ν; am u | m); + and ν = C(B − A)/(A(C − B)) in regime C,
        − and ν = A(C − B)/(C(B − A)) in regime A.
        """
        a, b, c = self.moments
        if self.pole == 2:
            nu, weight = c * (b - a) / (a * (c - b)), 1.0
        else:
            nu, weight = a * (c - b) / (c * (b - a)), -1.0
        r, j = self.reduce(t)
        r0, j0 = self.reduce(np.zeros(1))
        am, am0 = jacobi(r, self.m, self.m1)[3], jacobi(r0, self.m, self.m1)[3]
        full = 2.0 * complete_third(-nu, self.m1)
        pi_t = incomplete_third(-nu, am, self.m1) + j * full
        pi_0 = incomplete_third(-nu, am0, self.m1) + j0 * full
        scale = weight * momentum * (c - a) / (a * c * self.rate)
        return momentum * t / self.moments[self.pole] + scale * (pi_t - pi_0)


def elliptic_motion(moments: np.ndarray, omega0: np.ndarray) -> EllipticMotion | None:
    """Build the elliptic solution for sorted A < B < C and ω(0) in that frame.

    Returns None on the separatrix (|L|² = 2EB to `SEPARATRIX_RTOL`, or 1 − m < `M1_MIN`). With
    P = 2EC − |L|² and Q = |L|² − 2EA written as sums of squares (no cancellation) and
    Δ = |L|² − 2EB = x² − y², x = √(C(C − B)) |ω_C|, y = √(A(B − A)) |ω_A|.
    """
    a, b, c = moments
    w_a, w_b, w_c = omega0
    s_p = np.hypot(np.sqrt(a * (c - a)) * w_a, np.sqrt(b * (c - b)) * w_b)  # √P
    s_q = np.hypot(np.sqrt(b * (b - a)) * w_b, np.sqrt(c * (c - a)) * w_c)  # √Q
    x, y = np.sqrt(c * (c - b)) * abs(w_c), np.sqrt(a * (b - a)) * abs(w_a)
    if abs(x - y) <= SEPARATRIX_RTOL * (x + y):
        return None
    a_a, a_c = s_p / np.sqrt(a * (c - a)), s_q / np.sqrt(c * (c - a))
    if x > y:  # regime C: pole C, Δ > 0
        pole, a_b = 2, s_p / np.sqrt(b * (c - b))
        rate = s_q * np.sqrt((c - b) / (a * b * c))
        m = (b - a) / (c - b) * (s_p / s_q) ** 2
        m1 = (c - a) / (c - b) * ((x - y) / s_q) * ((x + y) / s_q)
    else:  # regime A: pole A, Δ < 0
        pole, a_b = 0, s_q / np.sqrt(b * (b - a))
        rate = s_p * np.sqrt((b - a) / (a * b * c))
        m = (c - b) / (b - a) * (s_q / s_p) ** 2
        m1 = (c - a) / (b - a) * ((y - x) / s_p) * ((y + x) / s_p)
    if not m1 >= M1_MIN:  # the separatrix to double precision
        return None
    amplitudes = np.array([a_a, a_b, a_c])
    sign = 1.0 if omega0[pole] > 0 else -1.0
    other = 2 - pole
    cn0 = omega0[other] / amplitudes[other] if amplitudes[other] > 0 else 1.0
    sn0 = sign * w_b / a_b if a_b > 0 else 0.0
    return EllipticMotion(moments, amplitudes, pole, sign, rate, m, m1, _phase(cn0, sn0, m1))


def _phase(cn0: float, sn0: float, m1: float) -> float:
    """u0 with cn u0 = cn0, sn u0 = sn0, by u0 = F(am u0 | m) (+2K when cn0 < 0)."""
    if cn0 >= 0.0:
        return float(incomplete_first(np.arctan2(sn0, cn0), m1))
    shift = 2.0 * complete_first(m1) * (1.0 if sn0 >= 0.0 else -1.0)
    return float(incomplete_first(np.arctan2(-sn0, -cn0), m1)) + shift


@dataclass(frozen=True)
class SeparatrixMotion:
    """ω(t) on the separatrix ``|L|² = 2EB`` (``m = 1``), in the sorted principal frame.

    The limit of regime C as ``m → 1``: ``sn → tanh``, ``cn, dn → sech`` and the period goes
    to infinity, so ``ω_A = s a_A sech u``, ``ω_B = s σ a_B tanh u``, ``ω_C = σ a_C sech u``
    with ``u = u0 + λ t`` (``s`` = sign ω_A(0), the half period the elliptic form would shift
    by). The body approaches the middle axis as ``t → ±∞``. The precession integral is
    elementary, ``∫₀ᵘ du/(1 + ν tanh²u) = (u + √ν arctan(√ν tanh u))/(1 + ν)``.
    """

    moments: np.ndarray
    amplitudes: np.ndarray
    sign: float  # σ = sign ω_C(0)
    side: float  # s = sign ω_A(0)
    rate: float
    u0: float
    pole: int = 2

    def omega(self, t: np.ndarray) -> np.ndarray:
        u = self.u0 + self.rate * np.asarray(t, dtype=float)
        sech, tanh = 1.0 / np.cosh(u), np.tanh(u)
        a_a, a_b, a_c = self.amplitudes
        return np.stack(
            [self.side * a_a * sech, self.side * self.sign * a_b * tanh, self.sign * a_c * sech],
            axis=-1,
        )

    def precession(self, t: np.ndarray, momentum: float) -> np.ndarray:
        a, b, c = self.moments
        nu = c * (b - a) / (a * (c - b))
        root = np.sqrt(nu)

        def integral(u):
            return (u + root * np.arctan(root * np.tanh(u))) / (1.0 + nu)

        u = self.u0 + self.rate * np.asarray(t, dtype=float)
        scale = momentum * (c - a) / (a * c * self.rate)
        return momentum * t / c + scale * (integral(u) - integral(self.u0))


def separatrix_motion(moments: np.ndarray, omega0: np.ndarray) -> SeparatrixMotion:
    """The motion from ω(0) on the separatrix (regime C's formulas at ``m = 1``)."""
    a, b, c = moments
    w_a, w_b, w_c = omega0
    s_p = np.hypot(np.sqrt(a * (c - a)) * w_a, np.sqrt(b * (c - b)) * w_b)
    s_q = np.hypot(np.sqrt(b * (b - a)) * w_b, np.sqrt(c * (c - a)) * w_c)
    amplitudes = np.array([s_p / np.sqrt(a * (c - a)), s_p / np.sqrt(b * (c - b)),
                           s_q / np.sqrt(c * (c - a))])  # fmt: skip
    sign = 1.0 if w_c >= 0.0 else -1.0
    side = 1.0 if w_a >= 0.0 else -1.0
    rate = s_q * np.sqrt((c - b) / (a * b * c))
    tanh0 = np.clip(side * sign * w_b / amplitudes[1], -1.0, 1.0) if amplitudes[1] > 0 else 0.0
    return SeparatrixMotion(moments, amplitudes, sign, side, rate, float(np.arctanh(tanh0)))


def flow_rotation(moments: np.ndarray, omega: np.ndarray, R0: np.ndarray, h: float) -> np.ndarray:
    """R(h) from ``R(0) = R0``, ω(0) = ``omega``, in the sorted principal frame (one step of
    the exact flow): every case of :func:`classify`, and on the separatrix (to
    ``SEPARATRIX_RTOL``, where the elliptic form refuses) its ``m = 1`` limit."""
    t = np.array([float(h)])
    eye = np.eye(3)
    try:
        return body_rotation(moments, eye, omega, R0, t)[0]
    except ValueError:
        if classify(moments, eye, omega, for_period=True)[0] != "separatrix":
            raise
    return elliptic_rotation(separatrix_motion(moments, omega), moments, eye, R0, t, omega)[0]


def classify(
    moments: np.ndarray, axes: np.ndarray, omega0: np.ndarray, for_period: bool = False
) -> tuple:
    """Which closed form applies, with its data.

    ('constant', None); ('symmetric', (e_s in body axes, Ω, I⊥)); ('elliptic', EllipticMotion);
    ('separatrix', None) only when `for_period`, else a ValueError.
    """
    a, b, c = moments
    w = axes.T @ omega0
    low, high = b - a <= SYMMETRY_RTOL * c, c - b <= SYMMETRY_RTOL * c
    if low and high:
        return "constant", None
    if low or high:
        s = 0 if high else 2  # the odd moment out is the symmetry axis
        transverse = 0.5 * (b + (c if high else a))
        return "symmetric", (axes[:, s], (transverse - moments[s]) * w[s] / transverse, transverse)
    if np.count_nonzero(w) <= 1 and not (for_period and w[1] == 0.0 and np.any(w)):
        return "constant", None
    motion = elliptic_motion(moments, w)
    if motion is None:
        if for_period:
            return "separatrix", None
        raise _checks.fail(
            "omega0", omega0.tolist(), "off the separatrix |L|^2 = 2 E I_mid",
            remedy=f"with inertia moments {moments.tolist()} the body approaches the middle "
            "axis forever and the period is infinite; perturb omega0",
        )  # fmt: skip
    return "elliptic", motion


def body_omega(
    moments: np.ndarray, axes: np.ndarray, omega0: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """ω(t) in body axes, shape (n, 3), for every case of `classify`."""
    kind, data = classify(moments, axes, omega0)
    if kind == "constant":
        return np.tile(omega0, (t.size, 1))
    if kind == "symmetric":
        axis, rate, _ = data
        return rodrigues(-rate * axis, t) @ omega0
    return data.omega(t) @ axes.T


def body_period(moments: np.ndarray, axes: np.ndarray, omega0: np.ndarray) -> float:
    """Period of ω(t), s, with the limits described in `tumble.exact.free_body_period`."""
    kind, data = classify(moments, axes, omega0, for_period=True)
    if kind == "symmetric":
        rate = data[1]
        return float(2.0 * np.pi / abs(rate)) if rate != 0.0 else float("inf")
    if kind == "elliptic":
        return float(data.period)
    return float("inf")


def body_rotation(
    moments: np.ndarray, axes: np.ndarray, omega0: np.ndarray, R0: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """R(t), body to world, shape (n, 3, 3), for every case of `classify`."""
    kind, data = classify(moments, axes, omega0)
    if kind == "constant":
        return R0 @ rodrigues(omega0, t)
    if kind == "symmetric":
        axis, rate, transverse = data
        momentum = R0 @ axes @ (moments * (axes.T @ omega0))
        return rodrigues(momentum / transverse, t) @ R0 @ rodrigues(rate * axis, t)
    return elliptic_rotation(data, moments, axes, R0, t, axes.T @ omega0)


def elliptic_rotation(
    motion: EllipticMotion | SeparatrixMotion,
    moments: np.ndarray,
    axes: np.ndarray,
    R0: np.ndarray,
    t: np.ndarray,
    omega0: np.ndarray,
) -> np.ndarray:
    """R(t) = W Rz(φ) M(l) Pᵀ of `free_body_rotation` for the asymmetric body; ``omega0``
    is ω(0) in the sorted principal frame (l(0) is taken from it, not from the formulas)."""
    order = [0, 1, 2] if motion.pole == 2 else [1, 2, 0]  # (q, r, p), cyclic: P is proper
    pole_axes = axes[:, order]
    momenta = moments[order] * np.vstack([omega0, motion.omega(t)])[:, order]
    norm = np.linalg.norm(momenta[0])
    frames = pole_frames(momenta / np.linalg.norm(momenta, axis=1, keepdims=True))
    phi = motion.precession(t, float(norm))
    c, s = np.cos(phi), np.sin(phi)
    spin = np.zeros((t.size, 3, 3))
    spin[:, 0, 0], spin[:, 0, 1], spin[:, 1, 0], spin[:, 1, 1], spin[:, 2, 2] = c, -s, s, c, 1.0
    W = R0 @ pole_axes @ frames[0].T
    return W @ spin @ frames[1:] @ pole_axes.T


def pole_frames(l: np.ndarray) -> np.ndarray:
    """M(l) = Rx(θ) Rz(ψ) with last row l: shape (n, 3) → (n, 3, 3); needs l ≠ ±e3."""
    q, r, p = l[:, 0], l[:, 1], l[:, 2]
    rho = np.hypot(q, r)
    zero = np.zeros_like(q)
    rows = [
        np.stack([r / rho, -q / rho, zero], axis=-1),
        np.stack([p * q / rho, p * r / rho, -rho], axis=-1),
        l,
    ]
    return np.stack(rows, axis=1)


def rodrigues(omega: np.ndarray, t: np.ndarray) -> np.ndarray:
    """exp(t ω̃) by Rodrigues: Id + sin θ k̃ + (1 − cos θ) k̃², θ = |ω| t; shape (n, 3, 3)."""
    speed = np.linalg.norm(omega)
    k = omega / speed if speed > 0 else np.zeros(3)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    angle = speed * t[:, None, None]
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def principal_axes(inertia: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Sorted moments A ≤ B ≤ C and a proper rotation whose columns are the principal axes."""
    I = np.asarray(inertia, dtype=float)
    if I.shape == (3,) or (I.shape == (3, 3) and np.all(I == np.diag(np.diag(I)))):
        diagonal = np.diag(I) if I.ndim == 2 else I
        check_moments(diagonal, inertia)
        order = np.argsort(diagonal, kind="stable")
        moments, axes = diagonal[order], np.eye(3)[:, order]
    elif I.shape == (3, 3):
        if not np.all(np.isfinite(I)) or np.abs(I - I.T).max() > SYMMETRIC_RTOL * np.abs(I).max():
            raise _checks.fail("inertia", I.tolist(), "a finite symmetric 3x3 matrix", "kg m^2")
        moments, axes = np.linalg.eigh(0.5 * (I + I.T))
        check_moments(moments, inertia)
    else:
        raise _checks.fail("inertia.shape", I.shape, "(3,) moments or a (3, 3) tensor")
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    return moments, axes


def check_moments(moments: np.ndarray, inertia: ArrayLike) -> None:
    """ValueError naming `inertia` unless every principal moment is finite and > 0."""
    if not (np.all(np.isfinite(moments)) and np.all(moments > 0)):
        raise _checks.fail(
            "inertia", np.asarray(inertia).tolist(),
            f"principal moments all finite and > 0 (these are {moments.tolist()})", "kg m^2",
        )  # fmt: skip


def check_rotation(name: str, value: ArrayLike | None) -> np.ndarray:
    """`value` as a rotation matrix (identity for None), or a ValueError naming `name`."""
    if value is None:
        return np.eye(3)
    R = np.asarray(value, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise _checks.fail(name, R.tolist(), "a finite 3x3 rotation matrix")
    if np.abs(R.T @ R - np.eye(3)).max() > ROTATION_ATOL or np.linalg.det(R) < 0:
        raise _checks.fail(name, R.round(6).tolist(), "a rotation: R^T R = I and det R = +1")
    return R
