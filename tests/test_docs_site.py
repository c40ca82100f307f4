"""The documentation site (``make docs``): it builds with warnings as errors, and it reads right.

The sources (docs/, examples/, benchmarks/results.md) are copied to a temporary folder and
built there, so the build writes nothing into the checkout (sphinx-gallery writes its pages
beside the sources). The index, an API page and the gallery are opened in headless Chromium
(the ``browser`` fixture of tests/conftest.py); the API's completeness and the narrative's code
blocks are checked in the HTML files.
"""

import importlib
import importlib.util
import inspect
import pkgutil
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import tumble

ROOT = Path(__file__).parent.parent
WAIT_S = 20
EXAMPLES = sorted(path.stem for path in (ROOT / "examples").glob("*.py"))
PAGES = sorted(path.stem for path in (ROOT / "docs").glob("*.md"))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """``(html folder, log)`` of a build with ``make docs``'s options."""
    sources = tmp_path_factory.mktemp("site")
    generated = ("auto_examples", "gen_modules", "_build", "sg_execution_times.rst")
    ignore = shutil.ignore_patterns(*generated)
    for folder in ("docs", "examples"):
        shutil.copytree(ROOT / folder, sources / folder, ignore=ignore)
    (sources / "benchmarks").mkdir()
    shutil.copy(ROOT / "benchmarks" / "results.md", sources / "benchmarks")
    html = sources / "html"
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html"]
    command += ["-d", str(sources / "doctrees"), str(sources / "docs"), str(html)]
    build = subprocess.run(command, capture_output=True, text=True, check=False)
    log = build.stdout + build.stderr
    assert build.returncode == 0, f"sphinx-build failed (exit {build.returncode}):\n{log}"
    return html, log


def test_the_site_builds_without_a_warning(site):
    _html, log = site
    assert "build succeeded" in log, log  # -W: a warning would have failed the build


def documented_names(module_name: str) -> dict[str, object]:
    """What the API page of ``module_name`` must show: its ``__all__``, or else the functions
    and classes it defines under a public name (submodules have their own section)."""
    module = importlib.import_module(module_name)
    if hasattr(module, "__all__"):
        names = {name: getattr(module, name) for name in module.__all__}
    else:
        names = {
            name: value
            for name, value in vars(module).items()
            if not name.startswith("_")
            and (inspect.isfunction(value) or inspect.isclass(value))
            and value.__module__ == module_name
        }
    return {name: value for name, value in names.items() if not inspect.ismodule(value)}


def anchors(html: Path, prefix: str = "tumble") -> set[str]:
    """The ``id``s starting with ``prefix`` of every page of the site."""
    return {
        anchor
        for page in html.rglob("*.html")
        for anchor in re.findall(rf'id="({prefix}[\w.]*)"', page.read_text(encoding="utf-8"))
    }


def test_every_public_name_of_every_documented_module_has_an_entry(site):
    html = site[0]
    found = anchors(html)
    modules = sorted(anchor.removeprefix("module-") for anchor in anchors(html, "module-tumble"))
    assert {"tumble", "tumble.so3", "tumble.rigid", "tumble.structural", "tumble.io"} <= {*modules}
    missing = []
    for module_name in modules:
        if module_name == "tumble":
            continue  # its names are documented where tumble._NAMES says (next test)
        for name, value in documented_names(module_name).items():
            home = f"{getattr(value, '__module__', '')}.{getattr(value, '__qualname__', '')}"
            if f"{module_name}.{name}" not in found and home not in found:
                missing.append(f"{module_name}.{name}")
    assert not missing, f"no entry in the built site for: {missing}"


def test_every_public_module_is_in_the_api_reference(site):
    """Each public module of tumble, and each public module of a package that exports nothing
    itself (``tumble.viz``); the command line is docs/command-line.md's. A module that no
    docs/api/ page names is documented at the end of the API index."""
    expected = set()
    for info in pkgutil.iter_modules(tumble.__path__, "tumble."):
        if info.name.startswith("tumble._") or info.name == "tumble.cli":
            continue
        expected.add(info.name)
        module = importlib.import_module(info.name)
        if info.ispkg and not getattr(module, "__all__", None):
            expected |= {
                sub.name
                for sub in pkgutil.iter_modules(module.__path__, f"{info.name}.")
                if not sub.name.rpartition(".")[2].startswith("_")
            }
    assert "tumble.viz.html" in expected
    documented = {anchor.removeprefix("module-") for anchor in anchors(site[0], "module-tumble")}
    missing = sorted(expected - documented)
    assert not missing, f"not in the API reference: {missing}"


def test_every_name_of_tumble_all_links_to_its_entry(site):
    html = site[0]
    page = (html / "api" / "tumble.html").read_text(encoding="utf-8")
    targets = set(re.findall(r'href="[\w./]*#([\w.-]+)"', page))
    found = anchors(html)
    for name in tumble.__all__:
        if name in tumble._SUBMODULES:
            assert f"module-tumble.{name}" in targets, name
        else:
            target = f"{tumble._NAMES[name]}.{name}"  # where the name is defined
            assert target in found and target in targets, name


def test_every_narrative_code_block_is_rendered_with_its_output(site):
    """Each ```python block of a page and the ```text block after it come out highlighted."""
    html = site[0]
    for name in PAGES:
        source = (ROOT / "docs" / f"{name}.md").read_text(encoding="utf-8")
        page = (html / f"{name}.html").read_text(encoding="utf-8")
        for language in ("python", "text"):
            expected = len(re.findall(rf"^```{language}$", source, re.MULTILINE))
            assert page.count(f'class="highlight-{language} ') == expected, (name, language)


def open_page(browser, html: Path, page: str) -> None:
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get((html / page).as_uri())
    WebDriverWait(browser, WAIT_S).until(
        lambda driver: driver.execute_script("return document.readyState") == "complete",
        message=f"{page} did not load within {WAIT_S} s",
    )


def test_index_shows_the_title_links_every_page_and_the_gallery(site, browser):
    from selenium.webdriver.common.by import By

    html = site[0]
    open_page(browser, html, "index.html")
    assert browser.title.startswith("tumble")
    assert browser.find_element(By.CSS_SELECTOR, "article h1").text.rstrip("#").strip() == "tumble"
    links = {
        link.get_attribute("href").split("#")[0].removeprefix(html.as_uri() + "/")
        for link in browser.find_elements(By.CSS_SELECTOR, "a[href]")
    }
    expected = {f"{name}.html" for name in PAGES if name != "index"}
    assert expected | {"auto_examples/index.html", "api/index.html"} <= links
    gallery = browser.find_elements(By.CSS_SELECTOR, ".sphx-glr-thumbcontainer a")
    assert {f"auto_examples/{name}.html" for name in EXAMPLES} == {
        link.get_attribute("href").removeprefix(html.as_uri() + "/") for link in gallery
    }


def test_api_page_shows_solve_with_its_signature(site, browser):
    from selenium.webdriver.common.by import By

    open_page(browser, site[0], "api/ode.html")
    entry = browser.find_element(By.ID, "tumble.ode.solve")
    signature = inspect.signature(tumble.solve)
    bare = signature.replace(
        parameters=[p.replace(annotation=p.empty) for p in signature.parameters.values()],
        return_annotation=signature.empty,
    )
    assert " ".join(entry.text.split()).startswith(f"tumble.ode.solve{bare}")
    assert browser.title.startswith("tumble.ode")


def sphinx_conf():
    """docs/conf.py as a module."""
    spec = importlib.util.spec_from_file_location("docs_conf", ROOT / "docs" / "conf.py")
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    return conf


def not_run() -> dict[str, str]:
    """docs/conf.py's examples shown without being run (name: why)."""
    return sphinx_conf().NOT_RUN


def test_bars_are_escaped_in_prose_only():
    """``|L|`` (a norm in tumble's docstrings) is not a reST substitution; code keeps its bars."""
    lines = [
        "the momentum |L|² = |Iω|², ``|x|`` and :math:`|a|`",
        "x : float | None",
        ">>> a | b",
        "3 | 4",
        "",
        ".. math::",
        "",
        "   |x| = 1",
        "Run::",
        "",
        "    code | here",
        "after |y|",
    ]
    assert sphinx_conf().escape_bars(lines) == [
        r"the momentum \|L\|² = \|Iω\|², ``|x|`` and :math:`|a|`",
        r"x : float \| None",
        *lines[2:11],
        r"after \|y\|",
    ]


def test_gallery_shows_a_picture_of_every_example_it_runs(site, browser):
    from selenium.webdriver.common.by import By

    open_page(browser, site[0], "auto_examples/index.html")
    thumbnails = browser.find_elements(By.CSS_SELECTOR, ".sphx-glr-thumbcontainer img")
    sources = sorted(Path(image.get_attribute("src")).name for image in thumbnails)
    assert sources == [f"sphx_glr_{name}_thumb.png" for name in EXAMPLES]
    sizes = [browser.execute_script("return arguments[0].naturalWidth", i) for i in thumbnails]
    assert all(width > 100 for width in sizes), sizes  # drawn, not a missing file
    for name in sorted(set(EXAMPLES) - set(not_run())):
        open_page(browser, site[0], f"auto_examples/{name}.html")
        figure = browser.find_element(By.CSS_SELECTOR, f"img[src$='sphx_glr_{name}_001.png']")
        assert browser.execute_script("return arguments[0].naturalWidth", figure) > 300
