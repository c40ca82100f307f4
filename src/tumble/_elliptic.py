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
.. [2] DLMF §20.2 (θ-functions), 22.2.4 and 22.2.9 (sn, cn of θ), 19.5.5 and OEIS A005797
   (the nome's series in λ).
.. [3] L. D. Landau, E. M. Lifshitz, Mechanics, 3rd ed., §37.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks

EPS = float(np.finfo(float).eps)
#: The most terms :func:`jacobi_series` takes (m1 = 1e-300 needs about 15; the name is the
#: arithmetic–geometric mean's, whose steps it capped before the θ-series replaced it).
AGM_MAX_STEPS = 64
#: The nome ``q = exp(−πK'/K)`` of ``m`` as a series in ``λ = ½ (1 − √k')/(1 + √k')``:
#: ``q = λ Σ cᵢ λ⁴ⁱ`` (DLMF 19.5.5's inverse; OEIS A005797). Up to ``m = 8/9`` (λ ≤ 0.134)
#: the next term, ``3567400 λ²⁹``, is below 1e-18 λ.
NOME_SERIES = (1.0, 2.0, 15.0, 150.0, 1707.0, 20910.0, 268616.0)
#: Principal moments closer than this fraction of the largest count as equal (symmetric body).
SYMMETRY_RTOL = 1e-12
#: The separatrix test, ``|x − y| ≤ SEPARATRIX_RTOL (x + y)`` with ``Δ = x² − y²``,
#: ``x = √(C(C − B)) |ω_C|``, ``y = √(A(B − A)) |ω_A|``. Each of x and y is computed from the
#: state with four roundings of at most u = ε/2 (the difference of moments, its product
#: with a moment and the root, whose errors the root halves to u; ω = m/I; the product):
#: ``|x̂ − x| ≤ 4u x = 2ε x``, and the same for y. So ``x̂ − ŷ`` is within ``2ε (x + y)`` of
#: ``x − y``: below that bound the state's own terms do not fix the sign of Δ, the side of
#: the separatrix it is on, and only there is its motion taken as the limit m = 1. Above
#: it, ``1 − m`` is known to better than 100 % and the elliptic form is the state's motion.
SEPARATRIX_RTOL = 2.0 * EPS
#: 1 − m below this also counts as the separatrix (K = 347 there; Carlson's R_F overflows
#: for subnormal arguments).
M1_MIN = 1e-300
#: Below this ``1 − m`` the Jacobi functions on [0, K/2] come from their hyperbolic series in
#: the complementary nome (at most 7.4e-3 there), and K, K' from that nome; above it from
#: the θ-series in the nome q itself (at most 0.134 there: its four terms reach ε), and K
#: from q. Either keeps every function to a few ε relative.
M1_SERIES = 1.0 / 9.0
#: The precession integral Π(−ν) is taken as F + P below this ν, as P alone from it up
#: (:func:`legendre_integrals`).
NU_SPLIT = 1.0
#: Largest |I − Iᵀ| accepted for a full inertia tensor, relative to max |I|.
SYMMETRIC_RTOL = 1e-10
#: Largest |RᵀR − Id| accepted for an initial attitude.
ROTATION_ATOL = 1e-10


def legendre_integrals(
    s: np.ndarray | float, c2: np.ndarray | float, d2: np.ndarray | float, nu: float, m: float
) -> tuple[np.ndarray, np.ndarray]:
    """``F(φ|m)`` and the part ``P`` of ``Π(−ν; φ|m)`` that is not F, for ``|φ| ≤ π/2`` from
    ``s ∝ sin φ``, ``c2 ∝ cos²φ`` and ``d2 ∝ 1 − m sin²φ``, all scaled by one factor
    (``s² + c2`` is its square): ``Π = F + P`` when ``ν < 1`` (:func:`keeps_first`), ``Π = P``
    from ``ν = 1`` up.

    DLMF 19.25.5 and 19.25.14 with R_F and R_J made homogeneous (``R_F(λx, λy, λz) =
    R_F(x, y, z)/√λ``, ``R_J`` as ``λ^{-3/2}``): ``F = s R_F(c2, d2, r2)``, ``Π(n) = F + (n/3)
    s³ R_J(c2, d2, r2, r2 − n s²)`` with ``r2 = s² + c2``. Taking cn² and dn² themselves, never
    an angle, keeps the relative accuracy of a small cn or dn: the integrals' derivatives in
    φ grow like 1/dn, those in cn² and dn² do not.

    The flow wants a difference of Π over a step, ``|L|(C − A)/(ACλ) [Π(u) − Π(u0)]``, and
    on a near-degenerate body (B − A or C − B small) λ is small while Π is of the size of
    ``u ≤ 3K``: Π's absolute round-off, ε K, became ε K/λ rad of precession a step. So F,
    whose difference is λh exactly (``F(am u) = u``), is kept out: for ``ν < 1``
    ``P = −(ν/3) s³ R_J(c2, d2, r2, r2 + ν s²)``, of the size ν u; for ``ν ≥ 1`` DLMF 19.7.9
    with ``n = −ν``, ``m/n = −m/ν`` (its R_C term made elementary, ``g = √((1 + ν)(1 + m/ν))``):
    ``Π(−ν) = (m/ν)/3 s³ R_J(c2, d2, r2, r2 + (m/ν) s²) + atan2(g s √r2, √(c2 d2))/g``, of the
    size ``u/ν + π/(2g)``.
    """
    from scipy.special import elliprf, elliprj  # 0.18 s to import: only where it is needed

    r2 = s * s + c2
    first = s * elliprf(c2, d2, r2)
    if keeps_first(nu):
        return first, -nu / 3.0 * s * s * s * elliprj(c2, d2, r2, r2 + nu * s * s)
    n = m / nu
    g = np.sqrt((1.0 + nu) * (1.0 + n))
    turn = np.arctan2(g * s * np.sqrt(r2), np.sqrt(c2 * d2)) / g
    return first, n / 3.0 * s * s * s * elliprj(c2, d2, r2, r2 + n * s * s) + turn


def keeps_first(nu: float) -> bool:
    """Whether ``Π(−ν) = F + P`` (ν < 1) or ``Π = P`` (:func:`legendre_integrals`)."""
    return nu < NU_SPLIT


def complete_first(m1: float) -> float:
    """K(m) = R_F(0, m1, 1), Carlson's form (the motions take K from :func:`quarter_periods`,
    which needs no R_F)."""
    from scipy.special import elliprf

    return float(elliprf(0.0, m1, 1.0))


def complete_part(nu: float, m: float, m1: float) -> float:
    """P of the complete ``Π(−ν|m)`` (:func:`legendre_integrals` at φ = π/2):
    ``−(ν/3) R_J(0, m1, 1, 1 + ν)`` for ν < 1, else ``(m/ν)/3 R_J(0, m1, 1, 1 + m/ν) + π/(2g)``."""
    from scipy.special import elliprj

    if keeps_first(nu):
        return float(-nu / 3.0 * elliprj(0.0, m1, 1.0, 1.0 + nu))
    n = m / nu
    g = np.sqrt((1.0 + nu) * (1.0 + n))
    return float(n / 3.0 * elliprj(0.0, m1, 1.0, 1.0 + n) + 0.5 * np.pi / g)


def nome(m: float, m1: float) -> float:
    """The nome ``q = exp(−πK'/K)`` of ``m ≤ 8/9``, by its series in
    ``λ = ½ (1 − √k')/(1 + √k') = ½ m/((1 + k')(1 + √k')²)`` (:data:`NOME_SERIES`); the second
    form keeps a small m's digits, which ``1 − √k'`` would cancel."""
    root = np.sqrt(m1)
    lam = 0.5 * m / ((1.0 + root) * (1.0 + np.sqrt(root)) ** 2)
    l4 = lam**4
    total = 0.0
    for coefficient in reversed(NOME_SERIES):
        total = total * l4 + coefficient
    return float(lam * total)


def theta_excess(q: float) -> float:
    """``θ₃(0|q)² − 1 = 4s(1 + s)``, ``s = q + q⁴ + q⁹ + q¹⁶`` (``θ₃(0|q)² = 2K/π``, DLMF 20.2.3
    and 20.9.2), for ``q ≤ 0.134`` (the next term, q²⁵, is below 1e-21). Kept apart from the
    1, so that ``K = (π/2)(1 + excess)`` rounds once."""
    total = ((q**16 + q**9) + q**4) + q
    return 4.0 * total * (1.0 + total)


def quarter_periods(m: float, m1: float) -> tuple[float, float]:
    """``(K, K')`` of m from the nome of the smaller of m and ``m1 = 1 − m``:
    ``K = (π/2) θ₃(0|q)²`` from ``m1 = M1_SERIES`` up (``K' = inf`` there: nothing needs it);
    below, ``K' = (π/2) θ₃(0|q')²`` with ``q' = exp(−πK/K')`` the nome of m1, and
    ``K = K' ln(1/q')/π = ½ θ₃(0|q')² ln(1/q')``. Each to about an ulp, without R_F."""
    if m1 >= M1_SERIES:
        return 0.5 * np.pi + 0.5 * np.pi * theta_excess(nome(m, m1)), np.inf
    q = nome(m1, m)
    excess, log = theta_excess(q), -0.5 * np.log(q)
    return log + log * excess, 0.5 * np.pi + 0.5 * np.pi * excess


def jacobi_theta(w: np.ndarray, m: float, m1: float, quarter: float) -> tuple:
    """sn and cn of ``0 ≤ w ≤ K/2`` up to one common factor, for ``1 − m ≥ M1_SERIES``.

    With ``v = πw/(2K)``, ``sn/cn = θ₁(v)/(√k' θ₂(v))`` (DLMF 22.2.4, 22.2.5 and
    ``√k' = θ₄(0)/θ₃(0)``), and by DLMF 20.2.1–2 without their common ``2q^¼``:
    ``θ₁ ∝ sin v − q² sin 3v + q⁶ sin 5v − q¹² sin 7v``,
    ``θ₂ ∝ cos v + q² cos 3v + q⁶ cos 5v + q¹² cos 7v`` (the next terms, ``q²⁰``, are below
    ε/9 for ``q ≤ 0.134``). The multiples come from ``sin v``, ``cos v`` by Chebyshev's
    recurrence; on ``v ≤ π/4`` neither sum cancels, so sn and cn keep a few ε relative.
    """
    q = nome(m, m1)
    v = 0.5 * np.pi * np.asarray(w, dtype=float) / quarter
    s, c = np.sin(v), np.cos(v)
    two = 2.0 - 4.0 * s * s  # 2 cos 2v
    s3, c3 = s * (two + 1.0), c * (two - 1.0)
    s5, c5 = two * s3 - s, two * c3 - c
    s7, c7 = two * s5 - s3, two * c5 - c3
    q2 = q * q
    q4 = q2 * q2
    q6 = q4 * q2
    odd = s - q2 * (s3 - q4 * (s5 - q6 * s7))
    even = c + q2 * (c3 + q4 * (c5 + q6 * c7))
    return odd, np.sqrt(np.sqrt(m1)) * even


def jacobi_series(w: np.ndarray, m: float, quarter: float, co_quarter: float) -> tuple:
    """sn and cn of ``0 ≤ w ≤ K/2`` by their series of hyperbolic functions, for m near 1.

    With ``c = π/(2K')``, ``K' = K(1 − m)`` (DLMF 22.11.1–2 for the complementary modulus,
    carried over by Jacobi's imaginary transformation, DLMF 22.6(iv)):
    ``sn = (c/k) Σ (−1)ⁿ tanh c(w − 2nK)`` and ``cn = (c/k) Σ (−1)ⁿ sech c(w − 2nK)``, n over
    all integers. Each pair ±n is summed as one term (``tanh(a − b) + tanh(a + b) =
    sinh 2a/(cosh(a − b) cosh(a + b))``), and on [0, K/2] the pairs fall by the complementary
    nome ``exp(−πK/K')`` at least (below 7.4e-3 for ``1 − m < M1_SERIES``): sn and cn keep
    a few ε relative.
    """
    c = 0.5 * np.pi / co_quarter
    w = np.asarray(w, dtype=float)
    sech, tanh, twice = 1.0 / np.cosh(c * w), np.tanh(c * w), np.sinh(2.0 * c * w)
    cn, sn = sech.copy(), tanh.copy()
    with np.errstate(over="ignore"):  # far terms overflow cosh to inf: they add 0
        for n in range(1, AGM_MAX_STEPS):
            near, far = np.cosh(c * (2 * n * quarter - w)), np.cosh(c * (2 * n * quarter + w))
            sign = -1.0 if n % 2 else 1.0
            cn += sign * (1.0 / near + 1.0 / far)
            sn += sign * twice / (near * far)
            if np.all(1.0 / near <= 0.25 * EPS * sech):
                break
    return c / np.sqrt(m) * sn, c / np.sqrt(m) * cn


def jacobi_reduced(
    r: np.ndarray, m: float, m1: float, quarter: float, co_quarter: float
) -> tuple[np.ndarray, ...]:
    """sn, cn, dn of ``|r| ≤ K``, each to a few ε *relative*: a small cn or dn keeps its
    digits (the exact flow takes them into :func:`legendre_integrals`).

    On ``|r| ≤ K/2`` directly, sn and cn by :func:`jacobi_theta` where ``1 − m ≥ M1_SERIES``
    (``co_quarter`` is not used there), else by :func:`jacobi_series`; beyond, at
    ``v = K − |r|`` with ``sn(K − v) = cn v/dn v``, ``cn(K − v) = k' sn v/dn v``,
    ``dn(K − v) = k'/dn v`` (DLMF 22.4.3), k' = √(1 − m). The pair is scaled to
    ``sn² + cn² = 1`` and ``dn = √(cn² + m1 sn²)``: the three then keep both identities to
    round-off, so the ω they give lies on the state's own energy and momentum surfaces
    (without, the energy drifted by about an ulp a step).
    """
    r = np.asarray(r, dtype=float)
    reflect = np.abs(r) > 0.5 * quarter
    w = np.where(reflect, quarter - np.abs(r), np.abs(r))
    if m1 >= M1_SERIES:
        s, c = jacobi_theta(w, m, m1, quarter)
    else:
        s, c = jacobi_series(w, m, quarter, co_quarter)
    size = np.hypot(s, c)
    s, c = s / size, c / size
    d = np.sqrt(c * c + m1 * s * s)
    root = np.sqrt(m1)
    sn = np.where(reflect, c / d, s)
    cn = np.where(reflect, root * s / d, c)
    dn = np.where(reflect, root / d, d)
    return np.copysign(sn, r), cn, dn


def precession_nu(moments: np.ndarray, pole: int) -> float:
    """ν of the precession integral: ``C(B − A)/(A(C − B))`` in regime C (pole 2),
    ``A(C − B)/(C(B − A))`` in regime A (pole 0)."""
    a, b, c = moments
    return c * (b - a) / (a * (c - b)) if pole == 2 else a * (c - b) / (c * (b - a))


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
    start: float  # P(am u0) of Π(−ν; am u0 | m) (legendre_integrals), u0 from ω(0) itself

    @property
    def quarter(self) -> float:
        """K(m), a quarter period of the argument u (:func:`quarter_periods`)."""
        return quarter_periods(self.m, self.m1)[0]

    @property
    def period(self) -> float:
        """Period of ω(t): 4K(m)/λ."""
        return 4.0 * self.quarter / self.rate

    def functions(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """sn, cn, dn of ``r`` and j, for u(t) = 2K j + r with r in [−K, K) (each function
        to a few ε relative, :func:`jacobi_reduced`)."""
        k, co_quarter = quarter_periods(self.m, self.m1)
        u = self.u0 + self.rate * t
        j = np.floor((u + k) / (2.0 * k))
        return (*jacobi_reduced(u - 2.0 * k * j, self.m, self.m1, k, co_quarter), j)

    def omega(self, t: np.ndarray) -> np.ndarray:
        """ω(t) in the sorted principal frame, shape (n, 3)."""
        sn, cn, dn, j = self.functions(t)
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
        − and ν = A(C − B)/(C(B − A)) in regime A (:func:`precession_nu`). Π is taken from
        sn, cn², dn² (:func:`legendre_integrals`), never from am, whose absolute error near
        π/2 would be amplified by 1/dn; and for ν < 1 its part F, whose difference is λt,
        is not taken at all (for ν ≥ 1 Π has no F part): the rest is of the size
        ``min(ν, 1/√ν) u``, so its round-off stays small when λ is (a near-degenerate body).
        """
        a, _, c = self.moments
        nu, weight = precession_nu(self.moments, self.pole), (1.0 if self.pole == 2 else -1.0)
        sn, cn, dn, j = self.functions(t)
        part = legendre_integrals(sn, cn * cn, dn * dn, nu, self.m)[1]
        part = part + j * 2.0 * complete_part(nu, self.m, self.m1)
        scale = weight * momentum * (c - a) / (a * c * self.rate)
        if keeps_first(nu):  # |L|/I_pole ± |L|(C − A)/(AC) = |L|/I_other
            return momentum * t / self.moments[2 - self.pole] + scale * (part - self.start)
        return momentum * t / self.moments[self.pole] + scale * (part - self.start)


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
    u0, start = start_phase(sn0, cn0, m, m1, precession_nu(moments, pole))
    return EllipticMotion(moments, amplitudes, pole, sign, rate, m, m1, u0, start)


def start_phase(sn0: float, cn0: float, m: float, m1: float, nu: float) -> tuple[float, float]:
    """``u0`` and P of ``Π(−ν; am u0 | m)`` (:func:`legendre_integrals`) for ``sn u0 = sn0``,
    ``cn u0 = cn0`` as read off ω(0).

    :func:`legendre_integrals` of ``(sn0, cn0², cn0² + m1 sn0²)``: the components themselves,
    so a small cn0 or dn0 (a spin near the middle axis) keeps its relative accuracy, where
    ``atan2`` then ``cos`` would keep only an absolute ε and lose a factor 1/dn0 in u0. When
    ``cn0 < 0`` the point is the half period on: ``u0 = ±2K + F``, ``P = ±2P(π/2) + P``.
    """
    half = 0.0 if cn0 >= 0.0 else (1.0 if sn0 >= 0.0 else -1.0)
    s, c = (sn0, cn0) if cn0 >= 0.0 else (-sn0, -cn0)
    first, part = legendre_integrals(s, c * c, c * c + m1 * s * s, nu, m)
    if half:
        first = first + 2.0 * half * quarter_periods(m, m1)[0]
        part = part + 2.0 * half * complete_part(nu, m, m1)
    return float(first), float(part)


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
        nu = precession_nu(self.moments, 2)
        root = np.sqrt(nu)
        t = np.asarray(t, dtype=float)
        u = self.u0 + self.rate * t
        turn = root * (np.arctan(root * np.tanh(u)) - np.arctan(root * np.tanh(self.u0)))
        scale = momentum * (c - a) / (a * c * self.rate)
        return momentum * t / c + scale * (self.rate * t + turn) / (1.0 + nu)


def separatrix_motion(moments: np.ndarray, omega0: np.ndarray) -> SeparatrixMotion:
    """The motion from ω(0) on the separatrix (regime C's formulas at ``m = 1``).

    ``u0 = asinh(tanh u0/sech u0)`` with ``sech u0`` from the small components themselves
    (the mean square of ``|ω_A|/a_A`` and ``|ω_C|/a_C``, equal on the separatrix), not
    ``atanh`` of a ``tanh u0`` near ±1, which would keep only its absolute ε.
    """
    a, b, c = moments
    w_a, w_b, w_c = omega0
    s_p = np.hypot(np.sqrt(a * (c - a)) * w_a, np.sqrt(b * (c - b)) * w_b)
    s_q = np.hypot(np.sqrt(b * (b - a)) * w_b, np.sqrt(c * (c - a)) * w_c)
    amplitudes = np.array([s_p / np.sqrt(a * (c - a)), s_p / np.sqrt(b * (c - b)),
                           s_q / np.sqrt(c * (c - a))])  # fmt: skip
    sign = 1.0 if w_c >= 0.0 else -1.0
    side = 1.0 if w_a >= 0.0 else -1.0
    rate = s_q * np.sqrt((c - b) / (a * b * c))
    return SeparatrixMotion(moments, amplitudes, sign, side, rate,
                            separatrix_phase(side * sign * w_b, w_a, w_c, amplitudes))  # fmt: skip


def separatrix_phase(w_b: float, w_a: float, w_c: float, amplitudes: np.ndarray) -> float:
    """``u0`` on the separatrix from ``tanh u0 = w_b/a_B`` and ``sech u0`` (see above)."""
    a_a, a_b, a_c = amplitudes
    cn0 = abs(w_a) / a_a if a_a > 0.0 else 0.0
    dn0 = abs(w_c) / a_c if a_c > 0.0 else 0.0
    tanh0 = w_b / a_b if a_b > 0.0 else 0.0
    sech0 = np.sqrt(0.5 * (cn0 * cn0 + dn0 * dn0))
    return float(np.arcsinh(tanh0 / sech0)) if sech0 > 0.0 else float(np.copysign(np.inf, tanh0))


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
