"""The site's own Sphinx extension: what keeps the documentation true to the code.

- ``model-constants``: documents every public constant of :mod:`asymslide.model` from its ``#:`` comment in the
  module that defines it (a constant without one is a warning, so ``make docs`` fails).
- ``equation-index``: the paper's equation labels (as docs/physics.md and the docstrings cite them, "Eq. S-dz"),
  where docs/physics.md uses each and which public functions implement it.
- A check at start-up that every public function, class and method of the model and the atlas layer has a
  docstring (a missing one is a warning: the build fails).
- Links made when a page is written: "§12.3" on the physics page and the equation index, and
  "docs/physics.md §12.3" anywhere, go to that section; "Eq. S-dz" anywhere but the equation index goes to its entry
  there; a literal ``model.spectrum`` (on the guide's pages also ``VERDICT_STATUS``) goes to its API entry.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import pkgutil
import re
import types
from collections.abc import Iterator
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

LOG = logging.getLogger(__name__)
PHYSICS = "physics"  # the physics page's docname
EQUATIONS = "equations"  # the equation index's docname
#: "Eq. S-dz", "Eqs. Gx_LSA": the paper's LaTeX labels as the project cites them
#: (two labels of the paper hold a space or parentheses: "delta f RSF" (+ "_SM"), "B(q)C(q)")
EQ_LABEL = re.compile(r"\bEqs?\. ((?:S-)?(?:delta f RSF(?:_SM)?|B\(q\)C\(q\)|[A-Za-z0-9_]+(?:[-_][A-Za-z0-9]+)*))")
#: "§12", "§12.3", "§14.7" (on the physics page); elsewhere only after "physics.md "
SECTION = re.compile(r"§(\d+(?:\.\d+)?)")
PHYSICS_SECTION = re.compile(r"(?:docs/)?physics\.md §(\d+(?:\.\d+)?)")
MODEL_NAME = re.compile(r"^(?:asymslide\.)?model\.([A-Za-z_][A-Za-z0-9_]*)(?:\(\))?$")
#: a constant's or a class's bare name (``VERDICT_STATUS``, ``SlidingReason``), linked on the guide's pages
BARE_NAME = re.compile(r"^([A-Z][A-Z0-9_]+|[A-Z][a-z]+[A-Za-z]*)$")


def _is_constant(obj: object) -> bool:
    return not (inspect.isroutine(obj) or inspect.isclass(obj) or isinstance(obj, types.ModuleType) or callable(obj))


def _submodules(package: types.ModuleType) -> Iterator[types.ModuleType]:
    yield package
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        if "._" not in info.name:
            yield importlib.import_module(info.name)


def _constant_docs() -> dict[str, tuple[str, list[str]]]:
    """Every module-level ``#:`` comment of the model's (public) modules: name -> (module, lines)."""
    model = importlib.import_module("asymslide.model")
    found: dict[str, tuple[str, list[str]]] = {}
    for module in _submodules(model):
        for (owner, name), lines in ModuleAnalyzer.for_module(module.__name__).find_attr_docs().items():
            if owner == "" and any(line.strip() for line in lines):
                found.setdefault(name, (module.__name__, list(lines)))
    return found


class ModelConstants(SphinxDirective):
    """Every public constant of asymslide.model, documented from the ``#:`` comment where it is defined."""

    def run(self) -> list[nodes.Node]:
        model = importlib.import_module("asymslide.model")
        docs = _constant_docs()
        rst: list[str] = []
        for name in model.__all__:
            value = getattr(model, name)
            if not _is_constant(value):
                continue
            if name not in docs:
                LOG.warning("asymslide.model.%s has no #: comment where it is defined", name,
                            location=self.get_location())
                continue
            module, lines = docs[name]
            rst += [f".. py:data:: {name}", "   :module: asymslide.model"]
            if type(value).__module__ == "builtins":
                rst.append(f"   :type: {type(value).__name__}")
            shown = repr(value)
            if len(shown) <= 70 and "\n" not in shown:
                rst.append(f"   :value: {shown}")
            rst += ["", *(f"   {line}" for line in lines), "", f"   Defined in ``{module}``.", ""]
        container = nodes.container()
        self.state.nested_parse(StringList(rst, source="asymslide.model constants"), self.content_offset, container)
        return container.children


def _public_callables() -> Iterator[tuple[str, object]]:
    """The model's ``__all__``, every public name an atlas module or the notebook helper defines, with their public
    methods."""
    model = importlib.import_module("asymslide.model")
    named = [(f"asymslide.model.{n}", getattr(model, n)) for n in model.__all__]
    notebook = importlib.import_module("asymslide.app.notebook")
    modules = [*_submodules(importlib.import_module("asymslide.atlas")), notebook]
    for module in modules:
        named += [(f"{module.__name__}.{n}", obj) for n, obj in vars(module).items()
                  if not n.startswith("_") and getattr(obj, "__module__", None) == module.__name__]
    for qualname, obj in named:
        if inspect.isclass(obj):
            yield qualname, obj
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member) or isinstance(member, property)):
                    yield f"{qualname}.{attr}", getattr(obj, attr) if inspect.isfunction(member) else member
        elif inspect.isfunction(obj):
            yield qualname, obj


def check_docstrings(app: Sphinx) -> None:  # noqa: ARG001 (Sphinx's signature)
    """Warn (the build fails) for each public function, class or method of the model, the atlas layer and the notebook
    helper without a docstring."""
    for qualname, obj in _public_callables():
        if not (inspect.getdoc(obj) or "").strip():  # a method may inherit its base class's docstring
            LOG.warning("%s has no docstring (every public function of the model and the atlas layer needs one)",
                        qualname)


@functools.cache  # read once per build, for the equation index and every page's links
def _physics_labels(srcdir: Path) -> dict[str, list[str]]:
    """Each equation label cited by docs/physics.md -> the sections ("§3", "§12.3") that cite it, in order."""
    where: dict[str, list[str]] = {}
    section = ""
    for line in (srcdir / f"{PHYSICS}.md").read_text(encoding="utf-8").splitlines():
        heading = re.match(r"#{2,3} §(\d+(?:\.\d+)?)", line)
        if heading:
            section = heading.group(1)
        for label in EQ_LABEL.findall(line):
            if section and f"§{section}" not in where.setdefault(label, []):
                where[label].append(f"§{section}")
    return where


@functools.cache  # read once per build, for the equation index and every page's links
def _implementers() -> dict[str, list[str]]:
    """Each equation label -> the public model functions and classes whose docstring cites it."""
    model = importlib.import_module("asymslide.model")
    found: dict[str, list[str]] = {}
    for name in model.__all__:
        obj = getattr(model, name)
        if inspect.isroutine(obj) or inspect.isclass(obj):
            for label in dict.fromkeys(EQ_LABEL.findall(inspect.getdoc(obj) or "")):
                found.setdefault(label, []).append(name)
    return found


@functools.cache
def _known_labels(srcdir: Path) -> frozenset[str]:
    """Every label the equation index lists: cited by docs/physics.md or by a docstring."""
    return frozenset(_physics_labels(srcdir)) | frozenset(_implementers())


def label_id(label: str) -> str:
    """The HTML id of a label's entry on the equation index."""
    return nodes.make_id(f"eq-{label}")


class EquationIndex(SphinxDirective):
    """The paper's equation labels: where docs/physics.md cites each, and the functions that implement it."""

    def run(self) -> list[nodes.Node]:
        where = _physics_labels(Path(self.env.srcdir))
        implemented = _implementers()
        labels = sorted(set(where) | set(implemented), key=lambda s: (s.startswith("S-"), s.lower()))
        rows = [".. list-table::", "   :header-rows: 1", "   :widths: 20 30 50", "",
                "   * - Label", "     - Used in the physics reference", "     - Implemented by"]
        for label in labels:
            functions = ", ".join(f":py:obj:`~asymslide.model.{n}`" for n in implemented.get(label, [])) or "—"
            sections = ", ".join(where.get(label, [])) or "—"
            rows += [f"   * - .. _{label_id(label)}:", "", f"       Eq. {label}", f"     - {sections}",
                     f"     - {functions}"]
        container = nodes.container()
        self.state.nested_parse(StringList(rows, source="equation index"), self.content_offset, container)
        return container.children


def _section_ids(app: Sphinx, docname: str, doctree: nodes.document) -> None:
    """Remember the physics page's section ids by their number ("12.3" -> "id"), for the links."""
    if docname != PHYSICS:
        return
    ids: dict[str, str] = {}
    for section in doctree.findall(nodes.section):
        title = section.next_node(nodes.title).astext()
        match = re.match(r"§(\d+(?:\.\d+)?)", title)
        if match and section["ids"]:
            ids[match.group(1)] = section["ids"][0]
    app.env.asymslide_physics_sections = ids  # type: ignore[attr-defined]


def _skip(node: nodes.Node) -> bool:
    """Text that is already a link, code, math or a title is left as it is."""
    parent = node.parent
    while parent is not None:
        if isinstance(parent, nodes.reference | nodes.literal | nodes.literal_block | nodes.math | nodes.math_block
                      | nodes.title | nodes.raw | nodes.FixedTextElement):
            return True
        parent = parent.parent
    return False


def _uri(app: Sphinx, fromdoc: str, todoc: str, anchor: str) -> str:
    page = "" if fromdoc == todoc else app.builder.get_relative_uri(fromdoc, todoc)
    return f"{page}#{anchor}"


def _target_uri(app: Sphinx, docname: str, match: re.Match[str], labels: set[str],
                sections: dict[str, str]) -> str | None:
    """Where a matched "§12.3" or "Eq. S-dz" links to (None: nowhere, it stays text)."""
    key = match.group(1)
    if match.re is EQ_LABEL:
        return _uri(app, docname, EQUATIONS, label_id(key)) if key in labels else None
    return _uri(app, docname, PHYSICS, sections[key]) if key in sections else None


def _link_text(app: Sphinx, docname: str, doctree: nodes.document) -> None:
    """§ numbers and equation labels become links (see the module's docstring)."""
    sections: dict[str, str] = getattr(app.env, "asymslide_physics_sections", {})
    labels = _known_labels(Path(app.srcdir))
    patterns = {PHYSICS: [SECTION, EQ_LABEL], EQUATIONS: [SECTION]}.get(docname, [PHYSICS_SECTION, EQ_LABEL])
    for text in list(doctree.findall(nodes.Text)):
        if _skip(text):
            continue
        source = str(text)
        pieces: list[nodes.Node] = []
        position = 0
        matches = sorted((m for pattern in patterns for m in pattern.finditer(source)), key=lambda m: m.start())
        for match in matches:
            uri = _target_uri(app, docname, match, labels, sections)
            if match.start() < position or uri is None:
                continue
            pieces.append(nodes.Text(source[position:match.start()]))
            pieces.append(nodes.reference("", match.group(0), refuri=uri, internal=True))
            position = match.end()
        if pieces:
            pieces.append(nodes.Text(source[position:]))
            text.parent.replace(text, pieces)


def _link_model_names(app: Sphinx, docname: str, doctree: nodes.document) -> None:
    """A literal ``model.spectrum`` in a page (not in a code block) links to the function's API entry; on the guide's
    pages also a bare constant or class of the model (``VERDICT_STATUS``, ``SlidingReason``)."""
    objects = app.env.get_domain("py").objects
    for literal in list(doctree.findall(nodes.literal)):
        if isinstance(literal.parent, nodes.reference) or _skip(literal.parent):
            continue
        match = MODEL_NAME.match(literal.astext())
        if match is None and docname.startswith("guide/"):
            match = BARE_NAME.match(literal.astext())
        target = objects.get(f"asymslide.model.{match.group(1)}") if match else None
        if target is None:
            continue
        reference = nodes.reference("", "", internal=True,
                                    refuri=_uri(app, docname, target.docname, target.node_id))
        literal.replace_self(reference)
        reference.append(literal)


def _links(app: Sphinx, doctree: nodes.document, docname: str) -> None:
    _link_text(app, docname, doctree)
    _link_model_names(app, docname, doctree)


def _shorthand(app: Sphinx, env, node, contnode):  # noqa: ARG001 (Sphinx's signature)
    """The docstrings cite the project's modules as ``:func:`model.growth_chunk``` or ``:data:`plan.DEFAULT_KH```:
    resolve them as ``asymslide.model.growth_chunk`` or ``asymslide.atlas.plan.DEFAULT_KH`` (a target that does not
    exist there stays unresolved: a warning, so the build fails)."""
    target = node.get("reftarget", "")
    if node.get("refdomain") != "py":
        return None
    domain = env.get_domain("py")
    for prefix in ("asymslide.", "asymslide.atlas."):
        found = domain.resolve_xref(env, node["refdoc"], app.builder, node["reftype"], prefix + target, node,
                                    contnode)
        if found is not None:
            return found
    return None


class _Anchors(HTMLParser):
    """The ids of one HTML page and its links (href of a, link; src of img, script)."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        """Collect the tag's id (and name) and its link."""
        values = dict(attrs)
        self.ids.update(v for k, v in values.items() if k in ("id", "name") and v)
        link = values.get("href") if tag in ("a", "link") else values.get("src") if tag in ("img", "script") else None
        if link:
            self.links.append(link)


def broken_links(outdir: Path) -> list[str]:
    """Every internal link of the built site whose page or anchor does not exist ("page.html: target")."""
    pages: dict[Path, _Anchors] = {}
    for page in sorted(outdir.rglob("*.html")):
        if "_static" in page.relative_to(outdir).parts:
            continue  # the theme's template fragments, not pages
        parser = _Anchors()
        parser.feed(page.read_text(encoding="utf-8", errors="replace"))
        pages[page.resolve()] = parser
    broken = []
    for page, parser in pages.items():
        for link in parser.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:")):
                continue  # external: not checked (the build machine may have no network)
            target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
            anchor = unquote(parts.fragment)
            if not target.exists():
                broken.append(f"{page.relative_to(outdir.resolve())}: {link} (no such file)")
            elif anchor and target in pages and anchor not in pages[target].ids:
                broken.append(f"{page.relative_to(outdir.resolve())}: {link} (no such anchor)")
    return broken


def check_links(app: Sphinx, error: Exception | None) -> None:
    """After an HTML build: warn (the build fails) for each broken internal link."""
    if error is None and app.builder.format == "html":
        for broken in broken_links(Path(app.outdir)):
            LOG.warning("broken internal link: %s", broken)


def setup(app: Sphinx) -> dict[str, object]:
    """Register the directives, the docstring check and the links."""
    app.add_directive("model-constants", ModelConstants)
    app.add_directive("equation-index", EquationIndex)
    app.connect("builder-inited", check_docstrings)
    app.connect("doctree-read", lambda a, doctree: _section_ids(a, a.env.docname, doctree))
    app.connect("doctree-resolved", _links)
    app.connect("missing-reference", _shorthand)
    app.connect("build-finished", check_links)
    return {"parallel_read_safe": False, "parallel_write_safe": True}
