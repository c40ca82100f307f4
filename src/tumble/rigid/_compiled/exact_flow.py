"""The exact free-body flow (Jacobi's elliptic functions, Carlson's integrals), compiled:
the twin of :func:`tumble.rigid.geometric.exact_flow` and :mod:`tumble._elliptic`, which
derive the constants below (tests check they agree).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tumble.rigid._compiled.base import (
    _INLINE,
    _JIT,
    _apply_transpose,
    _rotate,
    _times_matrix,
    _turn,
)
from tumble.rigid._compiled.charts import _exp_coefficients

_EPS = 2.220446049250313e-16
_RF_Q = (3.0 * _EPS) ** (-1.0 / 6.0)
_RJ_Q = (0.25 * _EPS) ** (-1.0 / 6.0)
_HALF_PI = 0.5 * math.pi
SYMMETRY_RTOL, SEPARATRIX_RTOL, M1_MIN, M1_SERIES = 1e-12, 2.0 * _EPS, 1e-300, 1.0 / 9.0
NU_SPLIT = 1.0
NOME_SERIES = (1.0, 2.0, 15.0, 150.0, 1707.0, 20910.0, 268616.0)
"""As :mod:`tumble._elliptic`, which derives them (a test checks they agree)."""
AGM_MAX_STEPS = 64
"""As :data:`tumble._elliptic.AGM_MAX_STEPS`: the most terms the hyperbolic series takes."""
WORK_SIZE = 1
"""A flow's work array, in the flows' common signature: the exact flow no longer needs one
(it held the AGM's ratios, which the nome's θ-series replaced)."""


@njit(**_JIT)
def _carlson_rf(x, y, z):
    """``R_F(x, y, z)`` by duplication (Carlson 1995, Algorithm 1; DLMF 19.36.1)."""
    a0 = (x + y + z) / 3.0
    a, scale = a0, 1.0
    q = _RF_Q * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    x0, y0 = x, y
    while scale * q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        x, y, z, a = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (a + lam)
        scale *= 0.25
    X, Y = (a0 - x0) * scale / a, (a0 - y0) * scale / a
    Z = -X - Y
    e2, e3 = X * Y - Z * Z, X * Y * Z
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


@njit(**_JIT)
def _rc_one(e):
    """``R_C(1, 1 + e)``: ``atan(√e)/√e``, ``atanh(√−e)/√−e``, or its series near 0."""
    if abs(e) < 1e-4:
        return 1.0 - e / 3.0 + e * e / 5.0 - e * e * e / 7.0 + e * e * e * e / 9.0
    if e > 0.0:
        root = math.sqrt(e)
        return math.atan(root) / root
    root = math.sqrt(-e)
    return math.atanh(root) / root


@njit(**_JIT)
def _carlson_rj(x, y, z, p):
    """``R_J(x, y, z, p)`` for ``p > 0`` by duplication (Carlson 1995, Algorithm 3)."""
    a0 = (x + y + z + 2.0 * p) / 5.0
    a, scale, total = a0, 1.0, 0.0
    delta = (p - x) * (p - y) * (p - z)
    q = _RJ_Q * max(abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p))
    x0, y0, z0 = x, y, z
    while scale * q >= abs(a):
        sx, sy, sz, sp = math.sqrt(x), math.sqrt(y), math.sqrt(z), math.sqrt(p)
        lam = sx * sy + sx * sz + sy * sz
        d = (sp + sx) * (sp + sy) * (sp + sz)
        total += scale / d * _rc_one(scale * scale * scale * delta / (d * d))
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
        p, a = 0.25 * (p + lam), 0.25 * (a + lam)
        scale *= 0.25
    X, Y, Z = (a0 - x0) * scale / a, (a0 - y0) * scale / a, (a0 - z0) * scale / a
    P = -0.5 * (X + Y + Z)
    e2 = X * Y + X * Z + Y * Z - 3.0 * P * P
    e3 = X * Y * Z + 2.0 * e2 * P + 4.0 * P * P * P
    e4 = (2.0 * X * Y * Z + e2 * P + 3.0 * P * P * P) * P
    e5 = X * Y * Z * P * P
    series = (1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
              - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0)  # fmt: skip
    return scale * series / (a * math.sqrt(a)) + 6.0 * total


@njit(**_JIT)
def _carlson_rf_rj(x, y, z, p):
    """``(R_F(x, y, z), R_J(x, y, z, p))`` by one duplication: R_J's x, y, z steps are R_F's,
    so the two share their square roots, and the loop runs until both have converged
    (:func:`_carlson_rf`, :func:`_carlson_rj`)."""
    a0_f, a0_j = (x + y + z) / 3.0, (x + y + z + 2.0 * p) / 5.0
    a_f, a_j, scale, total = a0_f, a0_j, 1.0, 0.0
    delta = (p - x) * (p - y) * (p - z)
    q_f = _RF_Q * max(abs(a0_f - x), abs(a0_f - y), abs(a0_f - z))
    q_j = _RJ_Q * max(abs(a0_j - x), abs(a0_j - y), abs(a0_j - z), abs(a0_j - p))
    x0, y0, z0 = x, y, z
    while scale * q_f >= abs(a_f) or scale * q_j >= abs(a_j):
        sx, sy, sz, sp = math.sqrt(x), math.sqrt(y), math.sqrt(z), math.sqrt(p)
        lam = sx * sy + sx * sz + sy * sz
        d = (sp + sx) * (sp + sy) * (sp + sz)
        total += scale / d * _rc_one(scale * scale * scale * delta / (d * d))
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
        p, a_f, a_j = 0.25 * (p + lam), 0.25 * (a_f + lam), 0.25 * (a_j + lam)
        scale *= 0.25
    X, Y = (a0_f - x0) * scale / a_f, (a0_f - y0) * scale / a_f
    Z = -X - Y
    e2, e3 = X * Y - Z * Z, X * Y * Z
    first = (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a_f)
    X, Y, Z = (a0_j - x0) * scale / a_j, (a0_j - y0) * scale / a_j, (a0_j - z0) * scale / a_j
    P = -0.5 * (X + Y + Z)
    e2 = X * Y + X * Z + Y * Z - 3.0 * P * P
    e3 = X * Y * Z + 2.0 * e2 * P + 4.0 * P * P * P
    e4 = (2.0 * X * Y * Z + e2 * P + 3.0 * P * P * P) * P
    e5 = X * Y * Z * P * P
    series = (1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
              - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0)  # fmt: skip
    return first, scale * series / (a_j * math.sqrt(a_j)) + 6.0 * total


@njit(**_JIT)
def _nome(m, m1):
    """The nome ``q = exp(−πK'/K)`` of ``m ≤ 8/9`` by its series in ``λ``
    (``tumble._elliptic.nome``)."""
    root = math.sqrt(m1)
    lam = 0.5 * m / ((1.0 + root) * (1.0 + math.sqrt(root)) ** 2)
    l4 = lam * lam
    l4 *= l4
    total = 0.0
    for k in range(len(NOME_SERIES) - 1, -1, -1):
        total = total * l4 + NOME_SERIES[k]
    return lam * total


@njit(**_JIT)
def _theta_excess(q):
    """``θ₃(0|q)² − 1`` (``tumble._elliptic.theta_excess``)."""
    q2 = q * q
    q4 = q2 * q2
    total = ((q4 * q4 * q4 * q4 + q4 * q4 * q) + q4) + q
    return 4.0 * total * (1.0 + total)


@njit(**_JIT)
def _quarter_periods(m, m1):
    """``(K, K')`` from the nome of the smaller of m and m1 (``tumble._elliptic.
    quarter_periods``); ``K' = inf`` from ``m1 = M1_SERIES`` up, where nothing needs it."""
    if m1 >= M1_SERIES:
        return _HALF_PI + _HALF_PI * _theta_excess(_nome(m, m1)), math.inf
    q = _nome(m1, m)
    excess, log = _theta_excess(q), -0.5 * math.log(q)
    return log + log * excess, _HALF_PI + _HALF_PI * excess


@njit(**_JIT)
def _jacobi_theta(w, m, m1, quarter):
    """``(sn, cn)`` of ``0 ≤ w ≤ K/2`` up to one factor, for ``1 − m ≥ M1_SERIES``, by the
    θ-series in the nome (``tumble._elliptic.jacobi_theta``)."""
    q = _nome(m, m1)
    v = _HALF_PI * w / quarter
    s, c = math.sin(v), math.cos(v)
    two = 2.0 - 4.0 * s * s  # 2 cos 2v
    s3, c3 = s * (two + 1.0), c * (two - 1.0)
    s5, c5 = two * s3 - s, two * c3 - c
    s7, c7 = two * s5 - s3, two * c5 - c3
    q2 = q * q
    q4 = q2 * q2
    q6 = q4 * q2
    odd = s - q2 * (s3 - q4 * (s5 - q6 * s7))
    even = c + q2 * (c3 + q4 * (c5 + q6 * c7))
    return odd, math.sqrt(math.sqrt(m1)) * even


@njit(**_JIT)
def _jacobi_series(w, m, quarter, co_quarter):
    """``(sn, cn)`` of ``0 ≤ w ≤ K/2`` by their hyperbolic series
    (``tumble._elliptic.jacobi_series``)."""
    c = 0.5 * math.pi / co_quarter
    sech, tanh, twice = 1.0 / math.cosh(c * w), math.tanh(c * w), math.sinh(2.0 * c * w)
    cn, sn = sech, tanh
    for n in range(1, AGM_MAX_STEPS):
        near, far = math.cosh(c * (2 * n * quarter - w)), math.cosh(c * (2 * n * quarter + w))
        sign = -1.0 if n % 2 else 1.0
        cn += sign * (1.0 / near + 1.0 / far)
        sn += sign * twice / (near * far)
        if 1.0 / near <= 0.25 * _EPS * sech:
            break
    return c / math.sqrt(m) * sn, c / math.sqrt(m) * cn


@njit(**_JIT)
def _jacobi_reduced(r, m, m1, quarter, co_quarter, work):
    """``(sn, cn, dn)`` of ``|r| ≤ K``, each to a few ε relative and together on both
    identities (``tumble._elliptic.jacobi_reduced``: beyond K/2 by the reflection about K).
    ``co_quarter`` is K' (the hyperbolic series'); ``work`` is not used."""
    w = abs(r)
    reflect = w > 0.5 * quarter
    if reflect:
        w = quarter - w
    if m1 >= M1_SERIES:
        s, c = _jacobi_theta(w, m, m1, quarter)
    else:
        s, c = _jacobi_series(w, m, quarter, co_quarter)
    size = math.hypot(s, c)
    s, c = s / size, c / size
    d = math.sqrt(c * c + m1 * s * s)
    if reflect:
        root = math.sqrt(m1)
        s, c, d = c / d, root * s / d, root / d
    return math.copysign(s, r), c, d


@njit(**_JIT)
def _legendre_integrals(s, c2, d2, nu, m):
    """``(F(φ|m), P)`` from ``s, cn², dn²``: ``Π(−ν; φ|m) = F + P`` for ``ν < 1``, ``= P``
    from 1 up (``tumble._elliptic.legendre_integrals``)."""
    r2 = s * s + c2
    if nu < NU_SPLIT:
        first, third = _carlson_rf_rj(c2, d2, r2, r2 + nu * s * s)
        return s * first, -nu / 3.0 * s * s * s * third
    n = m / nu
    g = math.sqrt((1.0 + nu) * (1.0 + n))
    turn = math.atan2(g * s * math.sqrt(r2), math.sqrt(c2 * d2)) / g
    first, third = _carlson_rf_rj(c2, d2, r2, r2 + n * s * s)
    return s * first, n / 3.0 * s * s * s * third + turn


@njit(**_JIT)
def _legendre_part(s, c2, d2, nu, m):
    """The part P of :func:`_legendre_integrals` alone (no R_F)."""
    r2 = s * s + c2
    if nu < NU_SPLIT:
        return -nu / 3.0 * s * s * s * _carlson_rj(c2, d2, r2, r2 + nu * s * s)
    n = m / nu
    g = math.sqrt((1.0 + nu) * (1.0 + n))
    turn = math.atan2(g * s * math.sqrt(r2), math.sqrt(c2 * d2)) / g
    return n / 3.0 * s * s * s * _carlson_rj(c2, d2, r2, r2 + n * s * s) + turn


@njit(**_JIT)
def _complete_part(nu, m, m_1):
    """P of the complete ``Π(−ν|m)`` (``tumble._elliptic.complete_part``)."""
    if nu < NU_SPLIT:
        return -nu / 3.0 * _carlson_rj(0.0, m_1, 1.0, 1.0 + nu)
    n = m / nu
    g = math.sqrt((1.0 + nu) * (1.0 + n))
    return n / 3.0 * _carlson_rj(0.0, m_1, 1.0, 1.0 + n) + 0.5 * math.pi / g


@njit(**_JIT)
def _elliptic_step(wb, other_w, pole_w, amplitudes, rate, m, m_1, nu, h, work):
    """The elliptic motion from ω over ``h``: ``(ω_other, ω_B, ω_pole)`` at ``h`` and the
    difference over the step of the precession integral's part P (``Π(−ν; am u) = F + P``
    for ``ν < 1``, ``= P`` from 1 up; ``tumble._elliptic``'s ``elliptic_motion``,
    ``start_phase``, ``EllipticMotion.omega`` and ``precession``). The start's
    ``u0 = F + 2K·half`` and ``P + 2P(π/2)·half`` (``half`` = ±1 when ``cn u0 < 0``) and the
    end's ``2Kj + r``: the complete P enters as ``(j − half)·2P(π/2)``, computed only when a
    step passes a half period (``j ≠ half``)."""
    amp_other, amp_b, amp_pole = amplitudes
    sign = 1.0 if pole_w > 0.0 else -1.0
    cn0 = other_w / amp_other if amp_other > 0.0 else 1.0
    sn0 = sign * wb / amp_b if amp_b > 0.0 else 0.0
    quarter, co_quarter = _quarter_periods(m, m_1)
    half = 0.0 if cn0 >= 0.0 else (1.0 if sn0 >= 0.0 else -1.0)
    s, c = (sn0, cn0) if cn0 >= 0.0 else (-sn0, -cn0)
    u0, start = _legendre_integrals(s, c * c, c * c + m_1 * s * s, nu, m)
    u = u0 + 2.0 * half * quarter + rate * h
    j = math.floor((u + quarter) / (2.0 * quarter))
    sn, cn, dn = _jacobi_reduced(u - 2.0 * quarter * j, m, m_1, quarter, co_quarter, work)
    flip = 1.0 - 2.0 * (j - 2.0 * math.floor(0.5 * j))
    part = _legendre_part(sn, cn * cn, dn * dn, nu, m) - start
    if j != half:  # the half periods passed: P of 2Π(−ν|m) each
        part += (j - half) * 2.0 * _complete_part(nu, m, m_1)
    return amp_other * flip * cn, sign * amp_b * flip * sn, sign * amp_pole * dn, part


@njit(**_JIT)
def _separatrix_step(wa, wb, wc, amp_a, amp_b, amp_c, rate, nu, h):
    """The motion at ``m = 1`` over ``h`` (``tumble._elliptic.SeparatrixMotion``):
    ``(ω_A, ω_B, ω_C)`` at ``h`` and ``∫ du/(1 + ν tanh²u)`` over the step."""
    sign, side = (1.0 if wc >= 0.0 else -1.0), (1.0 if wa >= 0.0 else -1.0)
    cn0 = abs(wa) / amp_a if amp_a > 0.0 else 0.0
    dn0 = abs(wc) / amp_c if amp_c > 0.0 else 0.0
    tanh0 = side * sign * wb / amp_b if amp_b > 0.0 else 0.0
    sech0 = math.sqrt(0.5 * (cn0 * cn0 + dn0 * dn0))
    u0 = math.asinh(tanh0 / sech0) if sech0 > 0.0 else math.copysign(math.inf, tanh0)
    u = u0 + rate * h
    sech, tanh, root = 1.0 / math.cosh(u), math.tanh(u), math.sqrt(nu)
    turn = root * (math.atan(root * tanh) - math.atan(root * math.tanh(u0)))
    return (side * amp_a * sech, side * sign * amp_b * tanh, sign * amp_c * sech,
            (rate * h + turn) / (1.0 + nu))  # fmt: skip


@njit(**_JIT)
def _pole_frame_product(l0, l1, l2, phi, k0, k1, k2):
    """``M(l)ᵀ Rz(φ) M(k)`` (``tumble._elliptic.pole_frames``: M has rows ``(r, −q, 0)/ρ``,
    ``(pq, pr, −ρ²)/ρ``, ``l``), as nine numbers."""
    rho = math.hypot(l0, l1)
    a00, a01, a02 = l1 / rho, -l0 / rho, 0.0
    a10, a11, a12 = l2 * l0 / rho, l2 * l1 / rho, -rho
    sigma = math.hypot(k0, k1)
    b00, b01, b02 = k1 / sigma, -k0 / sigma, 0.0
    b10, b11, b12 = k2 * k0 / sigma, k2 * k1 / sigma, -sigma
    c, s = math.cos(phi), math.sin(phi)
    # Rz(φ) M(k): rows c b0 − s b1, s b0 + c b1, k
    r00, r01, r02 = c * b00 - s * b10, c * b01 - s * b11, c * b02 - s * b12
    r10, r11, r12 = s * b00 + c * b10, s * b01 + c * b11, s * b02 + c * b12
    # M(l)ᵀ (…): column j of the product is Σ_i M(l)[i, :] (…)[i, j]
    return (
        a00 * r00 + a10 * r10 + l0 * k0, a00 * r01 + a10 * r11 + l0 * k1,
        a00 * r02 + a10 * r12 + l0 * k2,
        a01 * r00 + a11 * r10 + l1 * k0, a01 * r01 + a11 * r11 + l1 * k1,
        a01 * r02 + a11 * r12 + l1 * k2,
        a02 * r00 + a12 * r10 + l2 * k0, a02 * r01 + a12 * r11 + l2 * k1,
        a02 * r02 + a12 * r12 + l2 * k2,
    )  # fmt: skip


@njit(**_JIT)
def _times_permuted(Rp, pole, x00, x01, x02, x10, x11, x12, x20, x21, x22):
    """``R_p ← R_p P X Pᵀ`` with ``P`` the pole frame's axes (identity when ``pole = 2``,
    the cyclic ``(1, 2, 0)`` when ``pole = 0``): ``(P X Pᵀ)[o_i, o_j] = X[i, j]``."""
    if pole == 2:
        _times_matrix(Rp, x00, x01, x02, x10, x11, x12, x20, x21, x22)
    else:  # order (1, 2, 0): entry [o_i, o_j] = X[i, j]
        _times_matrix(Rp, x22, x20, x21, x02, x00, x01, x12, x10, x11)


@njit(**_JIT)
def _rotate_axis_angle(Rp, w0, w1, w2, h):
    """``R_p ← R_p exp(h ŵ)`` (Rodrigues)."""
    a, b = _exp_coefficients(h * h * (w0 * w0 + w1 * w1 + w2 * w2))
    for r in range(3):
        Rp[r, 0], Rp[r, 1], Rp[r, 2] = _rotate(-h * a, h * h * b, w0, w1, w2,
                                               Rp[r, 0], Rp[r, 1], Rp[r, 2])  # fmt: skip


@njit(**_JIT)
def _orthonormalise(Rp):
    """``R ← R (3 − RᵀR)/2``: one Newton step to the polar factor, removing the O(ε)
    departure from SO(3) a step leaves (without it the exact flow's R grows by 1.6e-16 a
    step, and its energy with it)."""
    S = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            S[i, j] = -0.5 * (Rp[0, i] * Rp[0, j] + Rp[1, i] * Rp[1, j] + Rp[2, i] * Rp[2, j])
        S[i, i] += 1.5
    _times_matrix(Rp, S[0, 0], S[0, 1], S[0, 2], S[1, 0], S[1, 1], S[1, 2], S[2, 0], S[2, 1],
                  S[2, 2])  # fmt: skip


@njit(**_INLINE)
def _exact_flow(Rp, L0, L1, L2, moments, h, work, head, tail):
    """The exact free-body flow over ``h`` (``tumble.rigid.geometric.exact_flow``)."""
    A, B, C = moments[0], moments[1], moments[2]
    m0, m1, m2 = _apply_transpose(Rp, L0, L1, L2)
    wa, wb, wc = m0 / A, m1 / B, m2 / C
    low, high = B - A <= SYMMETRY_RTOL * C, C - B <= SYMMETRY_RTOL * C
    nonzero = (wa != 0.0) + (wb != 0.0) + (wc != 0.0)
    if (low and high) or (not (low or high) and nonzero <= 1):
        _rotate_axis_angle(Rp, wa, wb, wc, h)  # ω constant: R exp(h ω̂)
        return True
    if low or high:  # symmetric: R(h) = exp(h L̂/I⊥) R exp(Ω h ê_s)
        s = 0 if high else 2
        transverse = 0.5 * (B + (C if high else A))
        ws = wa if s == 0 else wc
        rate = (transverse - moments[s]) * ws / transverse
        n0, n1, n2 = L0 / transverse, L1 / transverse, L2 / transverse
        a, b = _exp_coefficients(h * h * (n0 * n0 + n1 * n1 + n2 * n2))
        for c in range(3):  # column c of exp(h n̂) R
            Rp[0, c], Rp[1, c], Rp[2, c] = _rotate(h * a, h * h * b, n0, n1, n2,
                                                   Rp[0, c], Rp[1, c], Rp[2, c])  # fmt: skip
        _turn(Rp, 0.0, 0.0, 0.0, s, rate * h)
        return True
    # the asymmetric body (tumble._elliptic.elliptic_motion; SEPARATRIX_RTOL says the test)
    s_p = math.hypot(math.sqrt(A * (C - A)) * wa, math.sqrt(B * (C - B)) * wb)
    s_q = math.hypot(math.sqrt(B * (B - A)) * wb, math.sqrt(C * (C - A)) * wc)
    x, y = math.sqrt(C * (C - B)) * abs(wc), math.sqrt(A * (B - A)) * abs(wa)
    amp_a, amp_c = s_p / math.sqrt(A * (C - A)), s_q / math.sqrt(C * (C - A))
    separatrix = abs(x - y) <= SEPARATRIX_RTOL * (x + y)
    if x > y or separatrix:
        pole, amp_b = 2, s_p / math.sqrt(B * (C - B))
        rate = s_q * math.sqrt((C - B) / (A * B * C))
        m = (B - A) / (C - B) * (s_p / s_q) ** 2
        m_1 = (C - A) / (C - B) * ((x - y) / s_q) * ((x + y) / s_q)
    else:
        pole, amp_b = 0, s_q / math.sqrt(B * (B - A))
        rate = s_p * math.sqrt((B - A) / (A * B * C))
        m = (C - B) / (B - A) * (s_q / s_p) ** 2
        m_1 = (C - A) / (B - A) * ((y - x) / s_p) * ((y + x) / s_p)
    if not (separatrix or m_1 >= M1_MIN):  # m = 1 in double precision: regime C's limit
        separatrix, pole, amp_b = True, 2, s_p / math.sqrt(B * (C - B))
        rate = s_q * math.sqrt((C - B) / (A * B * C))
    if pole == 2:
        nu, weight = C * (B - A) / (A * (C - B)), 1.0
    else:
        nu, weight = A * (C - B) / (C * (B - A)), -1.0
    if separatrix:  # tumble._elliptic.SeparatrixMotion (regime C at m = 1)
        e0, e1, e2, integral = _separatrix_step(wa, wb, wc, amp_a, amp_b, amp_c, rate, nu, h)
    elif pole == 2:
        e0, e1, e2, integral = _elliptic_step(
            wb, wa, wc, (amp_a, amp_b, amp_c), rate, m, m_1, nu, h, work
        )
    else:
        e2, e1, e0, integral = _elliptic_step(
            wb, wc, wa, (amp_c, amp_b, amp_a), rate, m, m_1, nu, h, work
        )
    norm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    scale = weight * norm * (C - A) / (A * C * rate)
    if separatrix:
        phi = norm * h / moments[pole] + scale * integral
    elif nu < NU_SPLIT:  # Π = F + P, F's part λh: |L|/I_pole ± |L|(C − A)/(AC) = |L|/I_other
        phi = norm * h / moments[2 - pole] + scale * integral
    else:  # Π = P
        phi = norm * h / moments[pole] + scale * integral
    # l = I ω / |L| in the pole frame's order (q, r, p)
    if pole == 2:
        i0, i1, i2 = 0, 1, 2
    else:
        i0, i1, i2 = 1, 2, 0
    e = (e0, e1, e2)  # ω at h
    p0, p1, p2 = (m0, m1, m2)[i0], (m0, m1, m2)[i1], (m0, m1, m2)[i2]  # the state's own m
    q0, q1, q2 = moments[i0] * e[i0], moments[i1] * e[i1], moments[i2] * e[i2]
    size_p = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)  # unit l: M(l) orthogonal to round-off
    size_q = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
    _times_permuted(
        Rp, pole,
        *_pole_frame_product(p0 / size_p, p1 / size_p, p2 / size_p, phi,
                             q0 / size_q, q1 / size_q, q2 / size_q),
    )  # fmt: skip
    _orthonormalise(Rp)
    return True
