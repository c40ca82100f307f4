"""Butcher tableaux as data: every Runge–Kutta method tumble knows.

A method is a :class:`ButcherTableau` constant; one stepper (:func:`tumble.ode.stepper.rk_step`)
runs them all, on vector spaces, and the Runge–Kutta–Munthe-Kaas stepper of
:mod:`tumble.rigid` runs the same data on SO(3). Adding a method costs a constant here and an
entry in :data:`TABLEAUX`.

For a tableau with stages ``s``, the step from ``(t, y)`` with step ``h`` is

.. math::

    k_i = f\\Bigl(t + c_i h,\\; y + h \\sum_{j<i} a_{ij} k_j\\Bigr), \\qquad
    y_{n+1} = y + h \\sum_i b_i k_i,

and, for an embedded pair, the error estimate is :math:`h \\sum_i (b_i - \\hat b_i) k_i`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

_TOL = 1e-14


Coefficients = Any
"""array_like when a tableau is written, a read-only float ndarray once it is constructed."""


def _frozen(values, ndim: int) -> np.ndarray:
    array = np.array(values, dtype=float, ndmin=ndim)
    array.setflags(write=False)
    return array


def _strictly_lower(rows) -> list[list[float]]:
    """The square stage matrix whose row ``i`` starts with ``rows[i]`` (``i`` entries)."""
    s = len(rows)
    return [list(row) + [0.0] * (s - len(row)) for row in rows]


@dataclass(frozen=True, eq=False)
class ButcherTableau:
    """An explicit Runge–Kutta method, checked on construction.

    Parameters
    ----------
    name : str
        The method's name in :func:`tumble.solve` (``method=name``).
    c : array_like, shape (s,)
        Nodes.
    A : array_like, shape (s, s)
        Strictly lower-triangular stage matrix.
    b : array_like, shape (s,)
        Weights of the propagated solution.
    order : int
        Classical order of the propagated solution.
    b_hat : array_like, shape (s,), optional
        Weights of the embedded solution; makes the method adaptive.
    order_hat : int, optional
        Order of the embedded solution.
    fsal : bool
        First same as last: the last stage is ``f(t + h, y_{n+1})`` (its row of ``A`` is ``b``).
    dense : array_like, shape (s, q), (s + 1, q) or (s + 1 + m, q), optional
        The method's own continuous extension: ``y(t + θh) = y + h Σ_i k_i Σ_j P_ij θ^(j+1)``.
        With ``s + 1`` rows the last stage is ``k_{s+1} = f(t + h, y_{n+1})``, which the next
        step needs anyway (Fehlberg's pair). Without it, dense output is the cubic Hermite
        interpolant.
    dense_c, dense_A : array_like, shapes (m,) and (m, s + 1 + m), optional
        Extra stages that only the continuous extension uses, computed after an accepted step
        when dense output is asked for. The stages are extended as
        ``k_{s+1} = f(t + h, y_{n+1})`` (known already) then
        ``k_{s+1+j} = f(t + c_j h, y + h Σ_i a_ji k_i)``; ``dense`` then has ``s + 1 + m`` rows.
    dense_order : int, optional
        Order ``q`` of the continuous extension (required with ``dense``), in the sense of
        Hairer, Nørsett & Wanner §II.6: its local error at any ``θ`` is ``O(h^(q+1))``, so the
        dense output's global error is ``O(h^min(p, q+1))``.
    reference : str
        Where the coefficients come from.

    Raises
    ------
    ValueError
        If a row of ``A`` does not sum to its node, the weights do not sum to 1, the error
        weights ``b - b_hat`` do not sum to 0, ``A`` is not strictly lower-triangular, or a
        FSAL tableau's last row is not ``b``.
    """

    name: str
    c: Coefficients
    A: Coefficients
    b: Coefficients
    order: int
    b_hat: Coefficients | None = None
    order_hat: int | None = None
    fsal: bool = False
    dense: Coefficients | None = None
    dense_c: Coefficients | None = None
    dense_A: Coefficients | None = None
    dense_order: int | None = None
    reference: str = ""
    e: np.ndarray | None = field(init=False, default=None)
    rows: tuple = field(init=False, default=(), repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "c", _frozen(self.c, 1))
        set_(self, "A", _frozen(self.A, 2))
        set_(self, "b", _frozen(self.b, 1))
        if self.b_hat is not None:
            set_(self, "b_hat", _frozen(self.b_hat, 1))
            set_(self, "e", _frozen(self.b - self.b_hat, 1))
        for name, ndim in (("dense", 2), ("dense_c", 1), ("dense_A", 2)):
            if getattr(self, name) is not None:
                set_(self, name, _frozen(getattr(self, name), ndim))
        self._check()
        rows = tuple((self.A[i, :i].copy(), float(self.c[i])) for i in range(1, self.stages))
        set_(self, "rows", rows)  # stage rows pre-sliced for the stepper's inner loop

    def _check(self) -> None:
        s = self.stages
        if self.A.shape != (s, s) or self.b.shape != (s,):
            raise ValueError(f"{self.name}: A must be ({s}, {s}) and b ({s},)")
        if np.any(np.triu(self.A) != 0):
            raise ValueError(f"{self.name}: A must be strictly lower-triangular (explicit)")
        if not np.allclose(self.A.sum(axis=1), self.c, rtol=0, atol=_TOL):
            raise ValueError(f"{self.name}: the rows of A must sum to c")
        if abs(self.b.sum() - 1.0) > _TOL:
            raise ValueError(f"{self.name}: the weights b must sum to 1, not {self.b.sum()!r}")
        if self.e is not None and abs(self.e.sum()) > _TOL:
            raise ValueError(f"{self.name}: the error weights b - b_hat must sum to 0")
        if self.fsal and not (np.array_equal(self.A[-1], self.b) and self.c[-1] == 1.0):
            raise ValueError(f"{self.name}: a FSAL tableau's last row of A must equal b")
        if self.dense is not None:
            self._check_dense(self.dense)

    def _check_dense(self, dense: np.ndarray) -> None:
        s, m = self.stages, self.extra_stages
        rows = s if m == 0 and self.dense_A is None else s + 1 + m
        if self.dense_order is None:
            raise ValueError(f"{self.name}: a continuous extension must declare dense_order")
        if m == 0 and self.dense_A is None and dense.shape[0] == s + 1:
            rows = s + 1  # the stages and f(t + h, y_{n+1})
        if dense.shape[0] != rows:
            raise ValueError(f"{self.name}: dense must have {rows} rows, one per stage")
        if self.dense_A is not None and (
            self.dense_c is None or self.dense_A.shape != (m, s + 1 + m)
        ):
            raise ValueError(f"{self.name}: dense_A must be ({m}, {s + 1 + m}) with dense_c")
        weights = np.zeros(rows)
        weights[:s] = self.b
        scale = np.maximum(1.0, np.abs(dense).sum(axis=1))  # large terms cancel at θ = 1
        if np.any(np.abs(dense.sum(axis=1) - weights) > _TOL * scale):
            raise ValueError(f"{self.name}: the continuous extension must equal b at θ = 1")

    @property
    def stages(self) -> int:
        """Number of stages ``s``."""
        return self.c.shape[0]

    @property
    def extra_stages(self) -> int:
        """Number ``m`` of stages that only the continuous extension uses."""
        return 0 if self.dense_c is None else self.dense_c.shape[0]

    @property
    def interpolant_order(self) -> int:
        """Order ``q`` of the dense output: the extension's, or the cubic Hermite's ``min(p, 3)``.

        The local error between the nodes is ``O(h^(q+1))``; the global error of the dense
        output is ``O(h^min(p, q+1))``.
        """
        if self.dense_order is not None:
            return self.dense_order
        return min(self.order, 3)

    @property
    def adaptive(self) -> bool:
        """Whether the tableau carries an embedded pair for error control."""
        return self.e is not None

    @property
    def error_order(self) -> int:
        """Order ``min(p, p̂)`` of the local error estimate, used by the step controller."""
        if self.order_hat is None:
            return self.order
        return min(self.order, self.order_hat)

    @property
    def evaluations_per_step(self) -> int:
        """Right-hand-side evaluations a step costs (FSAL saves one)."""
        return self.stages - 1 if self.fsal else self.stages


EULER = ButcherTableau(
    name="euler", c=[0.0], A=[[0.0]], b=[1.0], order=1, reference="Euler (1768)."
)

HEUN = ButcherTableau(
    name="heun",
    c=[0.0, 1.0],
    A=[[0.0, 0.0], [1.0, 0.0]],
    b=[0.5, 0.5],
    order=2,
    reference="Heun (1900); the explicit trapezoidal rule.",
)

MIDPOINT = ButcherTableau(
    name="midpoint",
    c=[0.0, 0.5],
    A=[[0.0, 0.0], [0.5, 0.0]],
    b=[0.0, 1.0],
    order=2,
    reference="Runge (1895); the explicit midpoint rule.",
)

RK4 = ButcherTableau(
    name="rk4",
    c=[0.0, 0.5, 0.5, 1.0],
    A=[[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]],
    b=[1 / 6, 1 / 3, 1 / 3, 1 / 6],
    order=4,
    reference="Kutta (1901); the classical fourth-order method.",
)

FEHLBERG45 = ButcherTableau(
    name="rkf45",
    c=[0, 1 / 4, 3 / 8, 12 / 13, 1, 1 / 2],
    A=[
        [0, 0, 0, 0, 0, 0],
        [1 / 4, 0, 0, 0, 0, 0],
        [3 / 32, 9 / 32, 0, 0, 0, 0],
        [1932 / 2197, -7200 / 2197, 7296 / 2197, 0, 0, 0],
        [439 / 216, -8, 3680 / 513, -845 / 4104, 0, 0],
        [-8 / 27, 2, -3544 / 2565, 1859 / 4104, -11 / 40, 0],
    ],
    b=[16 / 135, 0, 6656 / 12825, 28561 / 56430, -9 / 50, 2 / 55],
    order=5,
    b_hat=[25 / 216, 0, 1408 / 2565, 2197 / 4104, -1 / 5, 0],
    order_hat=4,
    # A fourth-order continuous extension from the six stages and k_7 = f(t + h, y_{n+1}):
    # the order-4 conditions Σ b_i(θ) Φ_i(τ) = θ^|τ|/γ(τ) of the eight trees up to order 4
    # (Hairer, Nørsett & Wanner, §II.6, Theorem 6.1) as identities in θ, plus b(1) = b and
    # C¹ continuity (y' = f at θ = 0 and 1), leave one free coefficient: the θ⁴ term of k_6,
    # set to 0. Solved exactly (rational arithmetic); tests/ode measures its order.
    dense=[
        [1, -71 / 30, 298 / 135, -13 / 18],
        [0, 0, 0, 0],
        [0, 1664 / 475, -3328 / 675, 1664 / 855],
        [0, -15379 / 3135, 17576 / 1485, -2197 / 342],
        [0, 54 / 25, -126 / 25, 27 / 10],
        [0, 6 / 55, -4 / 55, 0],
        [0, 3 / 2, -4, 5 / 2],
    ],
    dense_order=4,
    reference=(
        "Fehlberg, E. (1969). Low-order classical Runge-Kutta formulas with stepsize control "
        "and their application to some heat transfer problems. NASA TR R-315. The fifth-order "
        "solution is propagated (local extrapolation, as GSL's rkf45 and every modern pair do); "
        "the fourth-order one only measures the error. Its fourth-order, C¹ dense output is "
        "derived here (the comment above the coefficients)."
    ),
)

DORMAND_PRINCE54 = ButcherTableau(
    name="dopri5",
    c=[0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1],
    A=[
        [0, 0, 0, 0, 0, 0, 0],
        [1 / 5, 0, 0, 0, 0, 0, 0],
        [3 / 40, 9 / 40, 0, 0, 0, 0, 0],
        [44 / 45, -56 / 15, 32 / 9, 0, 0, 0, 0],
        [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0, 0],
        [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0, 0],
        [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0],
    ],
    b=[35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0],
    order=5,
    b_hat=[5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40],
    order_hat=4,
    fsal=True,
    dense=[
        [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
        [0, 0, 0, 0],
        [0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
        [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
        [
            0,
            127303824393 / 49829197408,
            -318862633887 / 49829197408,
            701980252875 / 199316789632,
        ],
        [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
        [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
    ],
    dense_order=4,
    reference=(
        "Dormand, J. R. & Prince, P. J. (1980). A family of embedded Runge-Kutta formulae. "
        "J. Comp. Appl. Math. 6(1), 19-26; dense output of Shampine (1986), as in scipy's RK45."
    ),
)

_DOP853_B = [
    5.42937341165687622380535766363e-2,
    0,
    0,
    0,
    0,
    4.45031289275240888144113950566,
    1.89151789931450038304281599044,
    -5.8012039600105847814672114227,
    3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
]

# DOP853's dense output (dop853.f, CONTD8): three extra stages after k_13 = f(t + h, y_{n+1}),
# each row over the 16 extended stages, and the rows D of the interpolant's last four terms.
_DOP853_EXTRA_A = [
    [
        5.61675022830479523392909219681e-2, 0, 0, 0, 0, 0,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3, 0, 0, 0,
    ],
    [
        3.18346481635021405060768473261e-2, 0, 0, 0, 0,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0, 0,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
        0, 0,
    ],
    [
        -4.28896301583791923408573538692e-1, 0, 0, 0, 0,
        -4.69762141536116384314449447206,
        7.68342119606259904184240953878,
        4.06898981839711007970213554331,
        3.56727187455281109270669543021e-1,
        0, 0, 0,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149,
        -9.15095847217987001081870187138,
        0,
    ],
]  # fmt: skip
_DOP853_D = [
    [
        -0.84289382761090128651353491142e1, 0, 0, 0, 0,
        0.56671495351937776962531783590, -0.30689499459498916912797304727e1,
        0.23846676565120698287728149680e1, 0.21170345824450282767155149946e1,
        -0.87139158377797299206789907490, 0.22404374302607882758541771650e1,
        0.63157877876946881815570249290, -0.88990336451333310820698117400e-1,
        0.18148505520854727256656404962e2, -0.91946323924783554000451984436e1,
        -0.44360363875948939664310572000e1,
    ],
    [
        0.10427508642579134603413151009e2, 0, 0, 0, 0,
        0.24228349177525818288430175319e3, 0.16520045171727028198505394887e3,
        -0.37454675472269020279518312152e3, -0.22113666853125306036270938578e2,
        0.77334326684722638389603898808e1, -0.30674084731089398182061213626e2,
        -0.93321305264302278729567221706e1, 0.15697238121770843886131091075e2,
        -0.31139403219565177677282850411e2, -0.93529243588444783865713862664e1,
        0.35816841486394083752465898540e2,
    ],
    [
        0.19985053242002433820987653617e2, 0, 0, 0, 0,
        -0.38703730874935176555105901742e3, -0.18917813819516756882830838328e3,
        0.52780815920542364900561016686e3, -0.11573902539959630126141871134e2,
        0.68812326946963000169666922661e1, -0.10006050966910838403183860980e1,
        0.77771377980534432092869265740, -0.27782057523535084065932004339e1,
        -0.60196695231264120758267380846e2, 0.84320405506677161018159903784e2,
        0.11992291136182789328035130030e2,
    ],
    [
        -0.25693933462703749003312586129e2, 0, 0, 0, 0,
        -0.15418974869023643374053993627e3, -0.23152937917604549567536039109e3,
        0.35763911791061412378285349910e3, 0.93405324183624310003907691704e2,
        -0.37458323136451633156875139351e2, 0.10409964950896230045147246184e3,
        0.29840293426660503123344363579e2, -0.43533456590011143754432175058e2,
        0.96324553959188282948394950600e2, -0.39177261675615439165231486172e2,
        -0.14972683625798562581422125276e3,
    ],
]  # fmt: skip


def _dop853_extension() -> np.ndarray:
    """DOP853's interpolant in this module's form ``P`` (16 stages × θ¹…θ⁷).

    dop853.f writes ``y(t + θh) = y + Σ_k F_k w_k(θ)`` with ``w = θ, θ(1-θ), θ²(1-θ),
    θ²(1-θ)², θ³(1-θ)², θ³(1-θ)³, θ⁴(1-θ)³`` and ``F_k = h G_k · k``: ``G_0 = b``,
    ``G_1 = e_1 - b``, ``G_2 = 2b - e_1 - e_13``, ``G_3…6 = D``. Then ``P = Gᵀ W``, with ``W``
    the power coefficients of ``w``.
    """
    b = np.zeros(16)
    b[:12] = _DOP853_B
    first, new = np.eye(16)[0], np.eye(16)[12]
    G = np.vstack([b, first - b, 2 * b - first - new, np.array(_DOP853_D)])
    theta, one_minus = np.polynomial.Polynomial([0, 1]), np.polynomial.Polynomial([1, -1])
    powers = [(1, 0), (1, 1), (2, 1), (2, 2), (3, 2), (3, 3), (4, 3)]
    W = np.zeros((7, 7))
    for k, (i, j) in enumerate(powers):
        W[k, : i + j] = (theta**i * one_minus**j).coef[1:]
    return G.T @ W


# dop853.f's digits (30 significant); as doubles they equal scipy's arrays bit for bit.
DORMAND_PRINCE8 = ButcherTableau(
    name="rk8",
    c=[
        0.0,
        0.526001519587677318785587544488e-01,
        0.789002279381515978178381316732e-01,
        0.118350341907227396726757197510,
        0.281649658092772603273242802490,
        0.333333333333333333333333333333,
        0.25,
        0.307692307692307692307692307692,
        0.651282051282051282051282051282,
        0.6,
        0.857142857142857142857142857142,
        1.0,
    ],
    A=_strictly_lower(
        [
            [],
            [5.26001519587677318785587544488e-2],
            [1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2],
            [2.95875854768068491816892993775e-2, 0, 8.87627564304205475450678981324e-2],
            [
                2.41365134159266685502369798665e-1,
                0,
                -8.84549479328286085344864962717e-1,
                9.24834003261792003115737966543e-1,
            ],
            [
                3.7037037037037037037037037037e-2,
                0,
                0,
                1.70828608729473871279604482173e-1,
                1.25467687566822425016691814123e-1,
            ],
            [
                3.7109375e-2,
                0,
                0,
                1.70252211019544039314978060272e-1,
                6.02165389804559606850219397283e-2,
                -1.7578125e-2,
            ],
            [
                3.70920001185047927108779319836e-2,
                0,
                0,
                1.70383925712239993810214054705e-1,
                1.07262030446373284651809199168e-1,
                -1.53194377486244017527936158236e-2,
                8.27378916381402288758473766002e-3,
            ],
            [
                6.24110958716075717114429577812e-1,
                0,
                0,
                -3.36089262944694129406857109825,
                -8.68219346841726006818189891453e-1,
                2.75920996994467083049415600797e1,
                2.01540675504778934086186788979e1,
                -4.34898841810699588477366255144e1,
            ],
            [
                4.77662536438264365890433908527e-1,
                0,
                0,
                -2.48811461997166764192642586468,
                -5.90290826836842996371446475743e-1,
                2.12300514481811942347288949897e1,
                1.52792336328824235832596922938e1,
                -3.32882109689848629194453265587e1,
                -2.03312017085086261358222928593e-2,
            ],
            [
                -9.3714243008598732571704021658e-1,
                0,
                0,
                5.18637242884406370830023853209,
                1.09143734899672957818500254654,
                -8.14978701074692612513997267357,
                -1.85200656599969598641566180701e1,
                2.27394870993505042818970056734e1,
                2.49360555267965238987089396762,
                -3.0467644718982195003823669022,
            ],
            [
                2.27331014751653820792359768449,
                0,
                0,
                -1.05344954667372501984066689879e1,
                -2.00087205822486249909675718444,
                -1.79589318631187989172765950534e1,
                2.79488845294199600508499808837e1,
                -2.85899827713502369474065508674,
                -8.87285693353062954433549289258,
                1.23605671757943030647266201528e1,
                6.43392746015763530355970484046e-1,
            ],
        ]
    ),
    b=_DOP853_B,
    order=8,
    dense_c=[0.1, 0.2, 0.777777777777777777777777777778],
    dense_A=_DOP853_EXTRA_A,
    dense=_dop853_extension(),
    dense_order=7,
    reference=(
        "Hairer, E., Nørsett, S. P. & Wanner, G. (1993). Solving Ordinary Differential "
        "Equations I, 2nd ed., §II.10: the 12 stages and eighth-order weights of Dormand and "
        "Prince's DOP853 (the coefficients of Hairer's dop853.f, as in scipy's "
        "integrate/_ivp/dop853_coefficients.py), and DOP853's seventh-order dense output "
        "(three extra stages, dop853.f's CONTD8). Fixed step: DOP853's error estimators of "
        "orders 5 and 3 are left out."
    ),
)

TABLEAUX: dict[str, ButcherTableau] = {
    tableau.name: tableau
    for tableau in (EULER, HEUN, MIDPOINT, RK4, DORMAND_PRINCE8, FEHLBERG45, DORMAND_PRINCE54)
}
"""Every tableau by its method name."""
