"""The ODE core: Butcher tableaux as data, one stepper, a step controller, dense output.

========================  ===========================================================
:func:`solve`             integrate ``y' = f(t, y)``, shaped like ``solve_ivp``
:class:`OdeResult`        what ``solve`` returns
:class:`ButcherTableau`   a Runge–Kutta method as data, checked on construction
:data:`TABLEAUX`          every method by name
:func:`rk_step`           one explicit Runge–Kutta step, for any tableau
:class:`StepController`   accept/reject and the next step size
:class:`DenseOutput`      the continuous solution of a run
:func:`march`             the one stepping driver every time loop of tumble runs on
:class:`Status`           how a run ended (``SUCCESS``, ``TERMINAL_EVENT``, ``FAILED``)
========================  ===========================================================
"""

from tumble.ode.control import StepController, error_norm
from tumble.ode.dense import DenseOutput
from tumble.ode.driver import Status, Stepper, march
from tumble.ode.ivp import OdeResult, solve
from tumble.ode.stepper import rk_step
from tumble.ode.tableaux import TABLEAUX, ButcherTableau

__all__ = [
    "TABLEAUX",
    "ButcherTableau",
    "DenseOutput",
    "OdeResult",
    "Status",
    "StepController",
    "Stepper",
    "error_norm",
    "march",
    "rk_step",
    "solve",
]
