"""Work–precision: what each rigid-body method's accuracy costs, on a torque-free body.

Each fixed-step method runs with several step counts and the adaptive ones (``rkmk45``,
``rkmk-dopri5``) with several tolerances; every run is timed and compared at the end with the
exact attitude (:func:`tumble.exact.free_body_rotation`). The result is a list of
:class:`WorkPrecisionPoint`; :func:`table` makes rows for printing and
:func:`tumble.viz.work_precision.work_precision_figure` draws them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from functools import partial

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks
from tumble.exact import free_body_rotation, study
from tumble.rigid.body import RigidBody
from tumble.rigid.methods import Method, get_method
from tumble.rigid.simulation import simulate
from tumble.rigid.trajectory import Trajectory

STEPS = (50, 100, 200, 400, 800)
"""Default step counts of the fixed-step methods over ``[0, t_end]``."""
TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10)
"""Default ``rtol`` (= ``atol``) of the adaptive method."""
_KEEP_ENDS = 2**62
"""``record_every`` so large that a run records only its first and last state."""


@dataclass(frozen=True)
class WorkPrecisionPoint:
    """One timed run of one method.

    Attributes
    ----------
    method : str
        The method's name (:data:`tumble.rigid.METHODS`).
    setting : float
        The step ``h`` (s) of a fixed-step method, or ``rtol`` (= ``atol``) of an adaptive one.
    steps : int
        Accepted steps.
    rejected : int
        Rejected steps (adaptive methods; 0 otherwise).
    seconds : float
        Wall time of ``simulate``, the best of ``repeat`` runs (s).
    error : float
        ``‖R(T) − R_exact(T)‖_F``; ``inf`` if the run stopped on a non-finite state.
    """

    method: str
    setting: float
    steps: int
    rejected: int
    seconds: float
    error: float

    @property
    def setting_name(self) -> str:
        """``"rtol"`` for an adaptive method, ``"h"`` otherwise."""
        return "rtol" if get_method(self.method).adaptive else "h"


def work_precision(
    body: RigidBody,
    t_end: float,
    methods: Sequence[str],
    *,
    omega0: ArrayLike,
    steps: Sequence[int] = STEPS,
    tolerances: Sequence[float] = TOLERANCES,
    repeat: int = 3,
) -> list[WorkPrecisionPoint]:
    """Time each method at several accuracies and measure its error at ``t_end``.

    A fixed-step method runs ``simulate(body, t_end, method=m, h=t_end/n, omega0=omega0)``
    for each ``n`` in ``steps``; an adaptive one runs with ``rtol = tol`` for each ``tol`` in
    ``tolerances`` (the attitude error the run may accumulate, in radians; ``atol`` scales
    with it, :func:`tumble.rigid.simulate`). Each run records only its ends. Its error is

    .. math::

        e = \\lVert R(T) - R_{\\text{exact}}(T) \\rVert_F

    with ``R_exact`` from :func:`tumble.exact.free_body_rotation` (``R(0) = I``). The runs
    go through :func:`tumble.exact.study`: before any timing each method runs once over two
    tiny steps, so numba's compilation (the fixed-step methods run in the compiled kernels)
    is not counted; the time of a run is the best of ``repeat`` (``time.perf_counter``), the
    least disturbed by other work.
    Every method runs compiled (the adaptive ones in the compiled adaptive loop), so the
    times compare methods; so do the step counts.

    Parameters
    ----------
    body : RigidBody
        The body, free of loads.
    t_end : float
        End time (s), > 0.
    methods : sequence of str
        Names from :data:`tumble.rigid.METHODS`.
    omega0 : array_like, shape (3,)
        Initial body angular velocity (rad/s).
    steps : sequence of int
        Step counts of the fixed-step methods.
    tolerances : sequence of float
        Tolerances of the adaptive methods.
    repeat : int
        Timed runs per point.

    Returns
    -------
    list of WorkPrecisionPoint
        In the order of ``methods``, then of ``steps`` or ``tolerances``.

    Raises
    ------
    ValueError
        Empty or unknown ``methods``; empty or non-positive ``steps`` or ``tolerances``
        where a method needs them; ``t_end`` or ``repeat`` not positive.

    Examples
    --------
    >>> body = RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)
    >>> points = work_precision(body, 1.0, ["rkmk4"], omega0=(0.2, 0.0, 1.3),
    ...                         steps=(10, 20), repeat=1)
    >>> [point.steps for point in points], bool(points[0].error > points[1].error)
    ([10, 20], True)
    """
    specs, t_end, repeat = _check(methods, t_end, repeat)
    reference = free_body_rotation(body.inertia, omega0, t_end)
    points = []
    for spec in specs:
        if spec.adaptive:
            settings = _checks.values("tolerances", tolerances, positive=True).tolist()
        else:
            settings = [t_end / n for n in _step_counts(steps)]

        trials = study(partial(_run, body, t_end, spec, omega0), settings,
                       partial(_error, reference), repeat=repeat,
                       warm_up=partial(_warm_up, body, spec, omega0))  # fmt: skip
        points += [
            WorkPrecisionPoint(spec.name, trial.setting, trial.result.n_steps,
                               trial.result.n_rejected, trial.seconds, trial.error)
            for trial in trials
        ]  # fmt: skip
    return points


def _run(
    body: RigidBody, t_end: float, spec: Method, omega0: ArrayLike, setting: float
) -> Trajectory:
    """One run recording only its ends: ``h = setting``, or ``rtol = setting`` (adaptive)."""
    return simulate(body, t_end, method=spec.name, omega0=omega0, record_every=_KEEP_ENDS,
                    h=None if spec.adaptive else setting,
                    rtol=setting if spec.adaptive else None)  # fmt: skip


def _warm_up(body: RigidBody, spec: Method, omega0: ArrayLike) -> None:
    """Two tiny steps: numba compiles the method's kernels before any timing."""
    step = {"rtol": 1e-3, "h": None} if spec.adaptive else {"rtol": None, "h": 1e-3}
    simulate(body, 2e-3, method=spec.name, omega0=omega0, h=step["h"], rtol=step["rtol"])


def _error(reference: np.ndarray, run: Trajectory) -> float:
    """``‖R(T) − R_exact(T)‖_F``; inf for a run that stopped on a non-finite state."""
    return float(np.linalg.norm(run.R[-1] - reference)) if run.status == 0 else np.inf


def _check(methods, t_end, repeat):
    methods = (methods,) if isinstance(methods, str) else tuple(methods)
    if not methods:
        raise _checks.fail("methods", methods, "at least one name from tumble.rigid.METHODS")
    specs = [get_method(name) for name in methods]
    return specs, _checks.positive("t_end", t_end, "s"), _checks.count("repeat", repeat)


def _step_counts(steps) -> list[int]:
    steps = tuple(steps)
    if not steps:
        raise _checks.fail("steps", steps, "at least one number of steps")
    return [_checks.count(f"steps[{i}]", n) for i, n in enumerate(steps)]


def table(points: Sequence[WorkPrecisionPoint]) -> list[dict]:
    """One dict per point, for printing: the fields plus ``setting_name`` (``h`` or ``rtol``).

    Examples
    --------
    >>> table([WorkPrecisionPoint("rkmk4", 0.1, 10, 0, 0.002, 3e-7)])[0]["setting_name"]
    'h'
    """
    return [{**asdict(point), "setting_name": point.setting_name} for point in points]
