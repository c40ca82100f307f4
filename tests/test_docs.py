"""The Python examples in the README and the docs run as written (no exception)."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PAGES = ["README.md", "docs/command-line.md", "docs/scenario-files.md"]
BLOCK = re.compile(r"```python\n(.*?)```", re.DOTALL)
BLOCKS = [
    pytest.param(code, id=f"{page}#{k}")
    for page in PAGES
    for k, code in enumerate(BLOCK.findall((ROOT / page).read_text(encoding="utf-8")), start=1)
]


def test_the_pages_have_examples():
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("code", BLOCKS)
def test_example_runs(code, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    exec(compile(code, "<docs>", "exec"), {"__name__": "__docs__"})
    assert capsys.readouterr().out  # every example prints what it shows
