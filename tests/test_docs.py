"""Every Python block of the README and of docs/*.md runs, and prints what the page says.

The convention: a ```python block is followed by a ```text block holding what it prints.
The blocks of one page run in order in one namespace (a page is one session), from a
temporary working folder (with ``examples/`` linked in), so nothing is written into the
checkout. Printed numbers are
compared to a relative tolerance of 1e-6 (:data:`RTOL`); numbers below 1e-9 in size are
round-off-level figures (an orthogonality error of 2e-14, say), which only have to agree
within a factor of 10 (:data:`ROUND_OFF`). Everything else must match word for word.
"""

import math
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PAGES = ["README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"```python\n(.*?)```(?:\s*```text\n(.*?)```)?", re.DOTALL)
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
RTOL = 1e-6
ROUND_OFF = 1e-9


def blocks(page: str) -> list[tuple[str, str | None]]:
    """``(code, expected output or None)`` for each Python block of ``page``."""
    return BLOCK.findall((ROOT / page).read_text(encoding="utf-8"))


def same_number(a: float, b: float) -> bool:
    if abs(a) < ROUND_OFF and abs(b) < ROUND_OFF:
        return a == b == 0 or (a * b > 0 and abs(math.log10(abs(a) / abs(b))) <= 1)
    return math.isclose(a, b, rel_tol=RTOL, abs_tol=0.0)


def same_output(printed: str, expected: str) -> bool:
    """Word for word, numbers to :data:`RTOL` (module docstring)."""
    if NUMBER.sub("#", printed).split() != NUMBER.sub("#", expected).split():
        return False
    pairs = zip(NUMBER.findall(printed), NUMBER.findall(expected), strict=True)
    return all(same_number(float(a), float(b)) for a, b in pairs)


def test_every_page_with_python_shows_its_output():
    for page in PAGES:
        for k, (_code, expected) in enumerate(blocks(page), start=1):
            assert expected, f"{page}, block {k}: no ```text block of its output follows it"


def test_the_comparison_can_fail():
    assert same_output("period 47.26145 s", "period 47.2614 s") is False
    assert same_output("error 2.1e-14", "error 3e-14") is True
    assert same_output("error 2.1e-14", "error 3e-12") is False
    assert same_output("72.080202 s", "72.080202 m") is False


@pytest.mark.parametrize("page", [p for p in PAGES if blocks(p)])
def test_page_prints_what_it_shows(page, tmp_path, monkeypatch, capsys):
    (tmp_path / "examples").symlink_to(ROOT / "examples")  # the pages read examples/*.toml
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__docs__"}
    for k, (code, expected) in enumerate(blocks(page), start=1):
        exec(compile(code, f"{page} block {k}", "exec"), namespace)
        printed = capsys.readouterr().out
        assert printed.strip(), f"{page}, block {k} prints nothing to check"
        assert same_output(printed, expected or ""), (
            f"{page}, block {k} printed:\n{printed}\nthe page says:\n{expected}"
        )
