"""Scenario files: TOML that names a scenario and its options, validated with pydantic.

A file has one required key and four optional ones::

    scenario = "t-handle"          # a name from `tumble list`
    description = "..."            # free text, shown nowhere but kept
    [options]                      # keyword arguments of the scenario's run()
    h = 0.01
    [outputs]                      # what `tumble run` writes
    animation = true
    [sweep.grid]                   # what `tumble sweep` runs (docs/sweeps.md)
    omega0.1 = "0.001:0.1:50"

``[options]`` holds exactly what :func:`tumble.scenarios.get(scenario).run(**options)
<tumble.scenarios.get>` takes, so a file that sets every option to its default gives the same
numbers as ``tumble run NAME``. The user's own body is the scenario ``"rigid-body"``
(:mod:`tumble.scenarios.rigid_body`), whose options are tables: ``[options.body]``,
``[options.initial]``, ``[[options.loads]]``. The format, key by key with units, is in
``docs/scenario-files.md``.

Options are checked by one pydantic model per scenario, declared as ``OPTIONS`` or derived
from the signature of its ``run`` and the rules its module declares as ``OPTION_RULES``
(:mod:`tumble.scenarios.option_models`). The value types, the base of every
table (:class:`Section`) and the messages are in :mod:`tumble.scenarios.schema`; this module
reads the file and checks it.

Every mistake is a :class:`ValueError` whose message names the key path, the bad value and
what is allowed, e.g. ``options.h = -0.01: must be > 0``.

Examples
--------
>>> check_options("t-handle", {"h": 0.005, "t_end": 20})
{'h': 0.005, 't_end': 20.0}
>>> check_options("t-handle", {"h": -0.01})
Traceback (most recent call last):
...
ValueError: options.h = -0.01: must be > 0
"""

from __future__ import annotations

import inspect
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from tumble.scenarios import registry
from tumble.scenarios.option_models import options_model
from tumble.scenarios.schema import Flag, PositiveInteger, Section, Text, short_repr, validate

if TYPE_CHECKING:
    from tumble.io import ScenarioResult


def check_options(
    scenario: str, options: Mapping[str, Any], *, folder: str | Path | None = None
) -> dict[str, Any]:
    """Validate the options of ``scenario``; return them ready for ``run(**options)``.

    Parameters
    ----------
    scenario : str
        A name of :func:`tumble.scenarios.names`.
    options : mapping
        Keyword arguments of the scenario's ``run``; missing ones keep run's defaults.
    folder : str or Path, optional
        The folder relative file names in the options (mesh files) are relative to; default
        the working folder.

    Returns
    -------
    dict
        The options given, checked and converted (integers to floats where a number is
        expected, relative file names to absolute ones); options not given are left out.

    Raises
    ------
    ValueError
        One line per mistake: the key path (``options.h``), the bad value and what is
        allowed; an unknown option lists the allowed ones.

    Examples
    --------
    >>> check_options("t-handle", {"spinz": []})
    Traceback (most recent call last):
    ...
    ValueError: options.spinz is not an option of scenario 't-handle'; allowed: h, method, rtol, spins, t_end
    """  # noqa: E501 - the doctest's message is one line
    model = options_model(scenario)
    if not isinstance(options, Mapping):
        raise ValueError(f"options = {short_repr(options)}: must be a table of option = value")
    where = None if folder is None else Path(folder)
    checked = validate(model, dict(options), prefix="options", folder=where)
    return checked.model_dump(mode="json", exclude_unset=True)


# ---------------------------------------------------------------------------------------
# The file.


class Outputs(Section):
    """``[outputs]``: what ``tumble run`` writes besides the figures, data and summary."""

    what: ClassVar[str] = "a key of [outputs]"
    animation: Flag = True
    """Write ``animation.gif`` and ``view.html`` (``--no-animation`` overrides)."""


class Sweep(Section):
    """``[sweep]``: what ``tumble sweep FILE`` runs when no ``--grid`` is given.

    ``[sweep.grid]`` maps option paths to values (``omega0.1 = "0.001:0.1:50"`` or a list;
    :mod:`tumble.sweeps.plan`); ``chunk`` is the members per task.
    """

    what: ClassVar[str] = "a key of [sweep]"
    grid: dict[str, Any] = {}
    chunk: PositiveInteger | None = None


class _File(Section):
    what: ClassVar[str] = "a top-level key of a scenario file"
    hint: ClassVar[str] = " (a scenario's options go under [options])"
    scenario: Text
    description: Text = ""
    options: dict[str, Any] = {}
    outputs: Outputs = Outputs()
    sweep: Sweep = Sweep()


@dataclass(frozen=True)
class ScenarioFile:
    """A scenario file, read and checked.

    Attributes
    ----------
    scenario : str
        The scenario's name (:func:`tumble.scenarios.get`).
    options : dict
        Checked options for ``run(**options)`` (:func:`check_options`).
    outputs : Outputs
        ``outputs.animation``: whether to write ``animation.gif`` and ``view.html``.
    source : Path
        The file, absolute.
    description : str
        The file's free-text ``description``.
    sweep : Sweep
        ``[sweep]``: the grid ``tumble sweep`` runs by default.
    """

    scenario: str
    options: dict[str, Any]
    outputs: Outputs
    source: Path
    description: str = field(default="")
    sweep: Sweep = field(default_factory=Sweep)


def _load_toml(path: Path) -> dict[str, Any]:
    if not path.is_file():
        reason = "it is a folder" if path.is_dir() else "no such file"
        raise ValueError(f"scenario file {str(path)!r} cannot be read: {reason}")
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"{path}: not valid TOML: {error}") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"scenario file {str(path)!r} cannot be read: {error}") from None


def read(path: str | Path) -> ScenarioFile:
    """Read and check a scenario file.

    Relative file names inside it (a body's ``mesh``) are relative to the file's folder.

    Parameters
    ----------
    path : str or Path
        A TOML file (format: module docstring and ``docs/scenario-files.md``).

    Returns
    -------
    ScenarioFile

    Raises
    ------
    ValueError
        If the file is missing or unreadable, is not TOML (the message gives the line and
        column), names an unknown scenario or key, or has a bad value; the message starts
        with the file name and names the key path.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "spin.toml"
    ...     _ = path.write_text('scenario = "t-handle"\\n[options]\\nt_end = 20.0\\n')
    ...     spin = read(path)
    >>> spin.scenario, spin.options, spin.outputs.animation
    ('t-handle', {'t_end': 20.0}, True)
    """
    path = Path(path)
    data = _load_toml(path)
    try:
        top = validate(_File, data)
        options = check_options(top.scenario, top.options, folder=path.parent)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    return ScenarioFile(
        scenario=top.scenario,
        options=options,
        outputs=top.outputs,
        source=path.resolve(),
        description=top.description,
        sweep=top.sweep,
    )


# ---------------------------------------------------------------------------------------
# What `tumble run NAME|FILE.toml` runs.


@dataclass(frozen=True)
class Target:
    """A scenario to run, from a built-in's name or a file, its options checked.

    Attributes
    ----------
    scenario : str
        The scenario's name.
    options : dict
        Its checked options (:func:`check_options`), the overrides applied.
    animation : bool
        The file's ``[outputs].animation`` (True for a built-in's name).
    folder : str
        The run folder's default name: the file's stem, or the scenario's name.
    source : str or None
        The file as given; None for a built-in's name.
    """

    scenario: str
    options: dict[str, Any]
    animation: bool
    folder: str
    source: str | None

    def run(self) -> ScenarioResult:
        """Run the scenario; a bad value found only by the scenario names the file."""
        try:
            return registry.get(self.scenario).run(**self.options)
        except ValueError as error:
            if self.source is None:
                raise
            raise ValueError(f"{self.source}: [options] {error}") from None


def read_target(
    target: str,
    *,
    method: str | None = None,
    h: float | None = None,
    t_end: float | None = None,
) -> Target:
    """``tumble run TARGET``: a built-in scenario's name or a scenario file, with overrides.

    Parameters
    ----------
    target : str
        A name of :func:`tumble.scenarios.names`, or a scenario file (``.toml``).
    method, h, t_end : optional
        ``--method``, ``--h`` (s), ``--t-end`` (s): set where the scenario takes them
        (:func:`with_overrides`).

    Raises
    ------
    ValueError
        For an unknown name, a bad file, an override the scenario does not take, a bad
        value, or ``rigid-body`` by name (its body comes from a file).

    Examples
    --------
    >>> found = read_target("t-handle", t_end=20.0)
    >>> found.scenario, found.options, found.folder, found.source
    ('t-handle', {'t_end': 20.0}, 't-handle', None)
    """
    if target.endswith(".toml") or Path(target).is_file():
        spec = read(target)
        name, options, animation = spec.scenario, dict(spec.options), bool(spec.outputs.animation)
        folder = Path(target).stem
    else:
        registry.get(target)  # unknown names fail here, listing the known ones
        name, options, animation, folder = target, {}, True, target
    if name == "rigid-body" and not options:
        raise ValueError(
            "scenario 'rigid-body' describes your own body: run it from a TOML file "
            "(tumble run FILE.toml; see examples/t-handle-parts.toml)"
        )
    options = with_overrides(name, options, method=method, h=h, t_end=t_end)
    return Target(name, check_options(name, options), animation, folder,
                  None if target == name else target)  # fmt: skip


def with_overrides(scenario: str, options: Mapping[str, Any], **overrides: Any) -> dict:
    """``options`` with each override (not None) set where ``scenario``'s ``run`` takes it.

    ``method`` goes to ``methods`` (as a list of one) when the scenario takes several.

    Raises
    ------
    ValueError
        For an override the scenario does not take, naming it as its command-line flag.

    Examples
    --------
    >>> with_overrides("torus-spin", {}, method="rkmk4", h=None)
    {'methods': ['rkmk4']}
    """
    parameters = inspect.signature(registry.get(scenario).run).parameters
    options = dict(options)
    for option, value in overrides.items():
        if value is None:
            continue
        if option == "method" and "method" not in parameters and "methods" in parameters:
            options["methods"] = [value]
        elif option in parameters:
            options[option] = value
        else:
            flag = "--" + option.replace("_", "-")
            raise ValueError(
                f"{flag}={value!r} does not apply to scenario {scenario!r}; "
                f"its options are {sorted(parameters)}"
            )
    return options


__all__ = [
    "Outputs",
    "ScenarioFile",
    "Section",
    "Sweep",
    "Target",
    "check_options",
    "options_model",
    "read",
    "read_target",
    "validate",
    "with_overrides",
]
