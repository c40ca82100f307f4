"""Sphinx configuration of tumble's site: ``make docs`` builds it into ``build/docs/html``.

The narrative is docs/*.md (MyST), the gallery is examples/*.py run by sphinx-gallery (their
matplotlib figures become the pictures), the API reference is autodoc + numpydoc over each
public module (docs/api/). Nothing here reaches the network: no intersphinx.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList
from sphinx.pycode import ModuleAnalyzer
from sphinx.util.nodes import nested_parse_with_titles

import tumble

HERE = Path(__file__).parent

project = "tumble"
author = "the tumble developers"
copyright = "the tumble developers"
release = version = tumble.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "make_images.py"]
# The narrative pages are also read on GitHub: they link `#heading-slugs` and `img/...`.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
# Links from a page to a file of the repository outside docs/ (right on GitHub), and the page
# of the site that shows it.
REPOSITORY_LINKS = {"../benchmarks/results.md": "benchmarks.md"}
default_role = "py:obj"  # `name` in a docstring links to it when it is documented
# numpydoc turns each "References" entry into a citation; an entry the text does not cite is
# usual in tumble's docstrings (the list is the sources), not an error.
suppress_warnings = ["ref.citation"]

# API: numpydoc renders the docstrings; signatures without type hints (the Parameters say it).
autodoc_typehints = "none"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True}
numpydoc_show_class_members = False  # the class body is documented by autodoc itself
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()  # validated by review, not by the build
numpydoc_xref_param_type = False

# The gallery: every example is run once (a second or two each at its own default sizes),
# its matplotlib figures are the pictures and what it prints is shown, except those named
# here, which are shown without being run. sphinx-gallery runs an example without __file__.
NOT_RUN = {
    "flip_map": "a Dask sweep on a local cluster of every core, its TOML found from __file__",
}
sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": rf"/(?!({'|'.join(NOT_RUN)})\.py$)[^/]+\.py$",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "plot_gallery": "True",
    "capture_repr": (),
    "matplotlib_animations": False,
    "write_computation_times": False,
    # which example uses which tumble name (docs/gen_modules/, git-ignored): the index's
    # minigallery of all examples needs it
    "backreferences_dir": "gen_modules/backreferences",
    "doc_module": ("tumble",),
}

html_theme = "pydata_sphinx_theme"
html_title = f"tumble {version}"
html_static_path: list[str] = []
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "auto_examples/index": []}


def _resolve_top_level(app, env, node, contnode):
    """Send ``tumble.simulate`` (a name ``tumble`` re-exports) to ``tumble.rigid.simulate``.

    The package docstring and the pages name things as users import them; autodoc documents
    each object once, where it is defined by its subpackage.
    """
    target = node.get("reftarget", "")
    name = target.removeprefix("tumble.")
    home = tumble._NAMES.get(name)
    if node.get("refdomain") != "py" or home is None or target not in (name, f"tumble.{name}"):
        return None
    domain = env.get_domain("py")
    node["reftarget"] = f"{home}.{name}"
    return domain.resolve_xref(
        env, node["refdoc"], app.builder, node["reftype"], f"{home}.{name}", node, contnode
    )


def _site_links(app, docname, source):
    """Point links to repository files outside docs/ at the site's page for them."""
    for link, page in REPOSITORY_LINKS.items():
        source[0] = source[0].replace(f"]({link})", f"]({page})")


def _pages_joining_the_user_guide(app, docname, source):
    """Add the docs/*.md pages that user-guide.md does not list to the end of its toctree.

    A new page is then part of the site (a page in no toctree is a warning, so an error)
    until someone gives it its place in the list.
    """
    if docname != "user-guide":
        return
    head, fence, tail = source[0].partition("```{toctree}\n")
    block, end, rest = tail.partition("```")
    listed = {line.strip() for line in block.splitlines()}
    extra = sorted({page.stem for page in HERE.glob("*.md")} - listed - {"index", "user-guide"})
    source[0] = head + fence + block + "".join(f"{page}\n" for page in extra) + end + rest


def _example_title(app, docname, source):
    """Give an example whose docstring starts without a reST title one: its first line.

    sphinx-gallery takes that line as the thumbnail's title but copies the docstring as it
    is, and a page without a title gets no link in the gallery's toctree (a warning).
    """
    if not docname.startswith("auto_examples/") or docname == "auto_examples/index":
        return
    label = f".. _sphx_glr_{docname.replace('/', '_')}.py:\n\n"
    head, found, body = source[0].partition(label)
    lines = body.split("\n", 2)
    if not found or len(lines) < 2 or re.fullmatch(r"([=\-~^\"'`#*+])\1+\s*", lines[1]):
        return
    title = lines[0].strip()
    if not lines[1].strip():  # a one-line first paragraph becomes the title
        body = body.split("\n", 1)[1]
    source[0] = head + found + f"{title}\n{'=' * len(title)}\n" + body


def _reread_the_user_guide(app, env, added, changed, removed):
    """A page added or removed changes the user guide's toctree (an incremental build); the
    API index lists the modules without a page, which no page's change announces."""
    return ["user-guide", "api/index"] if added or removed else ["api/index"]


def _constants_without_docstring(module_name: str) -> list[str]:
    """The constants in ``module_name.__all__`` that automodule leaves out.

    autodoc documents a module's constant only when the module itself has the docstring under
    its assignment; a constant re-exported from a submodule (``tumble.ode.TABLEAUX``) has none.
    """
    module = importlib.import_module(module_name)
    documented = ModuleAnalyzer.for_module(module_name).find_attr_docs()
    return [
        name
        for name in getattr(module, "__all__", ())
        if not (inspect.ismodule(value := getattr(module, name)) or callable(value))
        and ("", name) not in documented
    ]


LITERAL_SPAN = re.compile(r"(``.*?``|`[^`]*`)")


def escape_bars(lines: list[str]) -> list[str]:
    """``|x|`` in docstring prose, tumble's plain-text norm, as ``\\|x\\|`` for docutils.

    reStructuredText reads ``|L|`` as a substitution (an error, or text lost). Left alone:
    inline literals and roles, doctests and their output, indented blocks under a directive
    or a ``::`` paragraph (math, code), and table lines.
    """
    escaped, block_indent, doctest = [], None, False
    for line in lines:
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if block_indent is not None and (not stripped or indent > block_indent):
            escaped.append(line)  # inside a literal, math or directive block
            continue
        block_indent = None
        doctest = stripped.startswith((">>>", "...")) or (doctest and bool(stripped))
        if doctest or stripped.startswith(("|", "+-", "+=")) or "|" not in line:
            escaped.append(line)
        else:
            parts = LITERAL_SPAN.split(line)
            escaped.append(
                "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))
            )
        if stripped.startswith(".. ") and "::" in stripped or stripped.endswith("::"):
            block_indent = indent
    return escaped


def _escape_bars(app, what, name, obj, options, lines):
    lines[:] = escape_bars(lines)


def _docstring_from_home(app, what, name, obj, options, lines):
    """A re-exported constant's docstring, read from the submodule that defines it.

    autodoc reads a constant's docstring (the string under its assignment) only from the
    module it documents, so ``tumble.ode.TABLEAUX`` would otherwise be shown without the text
    under ``TABLEAUX = ...`` in tumble/ode/tableaux.py.
    """
    if what != "data":
        return
    inherited = inspect.cleandoc(getattr(obj, "__doc__", None) or "")  # its class's docstring
    if lines and "\n".join(lines).strip() != inherited.strip():
        return
    package, _, attribute = name.rpartition(".")
    module = importlib.import_module(package)
    for info in pkgutil.iter_modules(getattr(module, "__path__", [])):
        docs = ModuleAnalyzer.for_module(f"{package}.{info.name}").find_attr_docs()
        if ("", attribute) in docs:
            lines[:] = list(docs[("", attribute)])
            return
    lines[:] = []


class TumbleConstants(Directive):
    """``.. tumble-constants:: module``: autodata for what :func:`_constants_without_docstring`
    finds, the value shown when it fits on a line."""

    required_arguments = 1

    def run(self):
        module_name = self.arguments[0]
        lines = []
        for name in _constants_without_docstring(module_name):
            lines.append(f".. autodata:: {module_name}.{name}")
            if len(repr(getattr(importlib.import_module(module_name), name))) > 80:
                lines.append("   :no-value:")
            lines.append("")
        container = nodes.container()
        self.state.nested_parse(
            StringList(lines, "tumble-constants"), self.content_offset, container
        )
        return container.children


def public_modules() -> list[str]:
    """tumble's public modules, and those of a package that exports nothing itself (viz).

    The command line (``tumble.cli``) is documented by docs/command-line.md instead.
    """
    found = []
    for info in pkgutil.iter_modules(tumble.__path__, "tumble."):
        if info.name.startswith("tumble._") or info.name == "tumble.cli":
            continue
        found.append(info.name)
        module = importlib.import_module(info.name)
        if info.ispkg and not getattr(module, "__all__", None):
            found += [
                sub.name
                for sub in pkgutil.iter_modules(module.__path__, f"{info.name}.")
                if not sub.name.rpartition(".")[2].startswith("_")
            ]
    return sorted(found)


class OtherModules(Directive):
    """``.. tumble-other-modules::``: a section for each public module no API page names.

    A module added on another branch is then documented (at the end of the API index) until
    it is given its place, instead of missing from the reference.
    """

    def run(self):
        pages = "\n".join(page.read_text() for page in (HERE / "api").glob("*.rst"))
        placed = set(re.findall(r"^\.\. automodule:: ([\w.]+)$", pages, re.MULTILINE))
        lines = []
        for name in [name for name in public_modules() if name not in placed]:
            lines = lines or [".. rubric:: Modules not yet on a page of their own", ""]
            title = f"``{name}``"
            lines += [title, "-" * len(title), "", f".. automodule:: {name}", ""]
            lines += [f".. tumble-constants:: {name}", ""]
        container = nodes.container()
        nested_parse_with_titles(self.state, StringList(lines, "other-modules"), container)
        return container.children


class TumbleNames(Directive):
    """``.. tumble-names::``: a list of ``tumble.__all__``, each linked where it is documented."""

    def run(self):
        lines = []
        for name in tumble.__all__:
            if name in tumble._SUBMODULES:
                lines.append(f"* :mod:`tumble.{name}`")
            else:
                lines.append(f"* :obj:`tumble.{name} <{tumble._NAMES[name]}.{name}>`")
        container = nodes.container()
        self.state.nested_parse(StringList(lines, "tumble-names"), self.content_offset, container)
        return container.children


def setup(app):
    importlib.import_module("tumble.rigid")  # fail early, with the import error, if broken
    app.connect("missing-reference", _resolve_top_level)
    app.connect("source-read", _site_links)
    app.connect("source-read", _pages_joining_the_user_guide)
    app.connect("env-get-outdated", _reread_the_user_guide)
    app.connect("source-read", _example_title)
    # before numpydoc's (priority 500) reformatting of the same lines
    app.connect("autodoc-process-docstring", _docstring_from_home, priority=400)
    app.connect("autodoc-process-docstring", _escape_bars, priority=401)
    app.add_directive("tumble-names", TumbleNames)
    app.add_directive("tumble-constants", TumbleConstants)
    app.add_directive("tumble-other-modules", OtherModules)
