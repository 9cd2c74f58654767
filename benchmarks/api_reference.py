"""Renders docs/api_reference.md from the docstrings of the public API (``balloon_cg.__all__``): ``make api-docs``
(not a benchmark: benchmarks/ holds the repository's scripts that run against the installed package).

The docstrings are numpy style (Parameters, Returns, Raises, Examples; parsed by docstring_parser, in the ``test``
extra); every public name gets a section with its signature, and a class its public methods and properties.
A constant is described by its ``#:`` comment. ``python benchmarks/api_reference.py --check`` exits 1 when the page
is stale (tests/test_api_reference.py: as generated kernels, the page is never edited by hand).
"""
import inspect
import re
import sys
from pathlib import Path

import docstring_parser

import balloon_cg

PAGE = Path(__file__).resolve().parents[1] / "docs" / "api_reference.md"
HEADER = ("# API reference\n\nGenerated from the docstrings of `balloon_cg`'s public names by `make api-docs` "
          "(benchmarks/api_reference.py); do not edit it by hand. The guide, with an example: [api.md](api.md).\n")


def render() -> str:
    """The whole page: a section per public name, and per public member of a class."""
    sections = [HEADER]
    for name in balloon_cg.__all__:
        if name == "__version__":
            continue
        obj = getattr(balloon_cg, name)
        sections.append(section(name, obj, 2))
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            sections += [section(f"{name}.{member}", value, 3) for member, value in members(obj)]
    return "\n".join(sections)


def members(cls) -> list:
    """The documented public methods and properties ``cls`` defines, in source order."""
    found = []
    for name, value in vars(cls).items():
        function = value.fget if isinstance(value, property) else getattr(value, "__func__", value)
        if not name.startswith("_") and callable(function) and function.__doc__:
            found.append((name, value))
    return found


def section(title: str, obj, level: int) -> str:
    """A heading with the signature, then the docstring rendered."""
    if isinstance(obj, property):
        heading, doc = f"`{title}` (property)", obj.fget.__doc__
    elif inspect.isclass(obj):  # made by the functions that return one: no constructor signature
        heading, doc = f"class `{title}`", inspect.getdoc(obj)
    elif callable(getattr(obj, "__func__", obj)):
        target = getattr(obj, "__func__", obj)
        kind = "classmethod " if isinstance(obj, classmethod) else ""
        heading, doc = f"{kind}`{title}{signature(target, method=level > 2)}`", inspect.getdoc(target)
    else:
        heading, doc = f"`{title}` (constant)", constant_comment(title)
    return f"{'#' * level} {heading}\n\n{markdown(doc or '')}\n"


def signature(function, method: bool = False) -> str:
    """The signature as written (a method's without self or cls), balloon_cg's types by their own names."""
    found = inspect.signature(function)
    if method:
        found = found.replace(parameters=list(found.parameters.values())[1:])
    text = re.sub(r"\bballoon_cg\.[\w.]+\.(\w+)", r"\1", str(found))
    return re.sub(r"-> '(\w+)'", r"-> \1", text)  # a forward reference


def constant_comment(name: str) -> str:
    """The ``#:`` comment lines above ``NAME =`` in the module that defines the constant."""
    module = sys.modules[balloon_cg._API[name]]
    lines = inspect.getsource(module).splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"{name} ="))
    comment = []
    for line in reversed(lines[:start]):
        if not line.startswith("#:"):
            break
        comment.insert(0, line.removeprefix("#:").strip())
    return " ".join(comment)


def markdown(doc: str) -> str:
    """A numpy-style docstring as Markdown: the description, then Parameters, Returns, Raises, Examples."""
    parsed = docstring_parser.parse(inspect.cleandoc(doc), docstring_parser.DocstringStyle.NUMPYDOC)
    blocks = [text(parsed.description)] if parsed.description else []
    if parsed.params:
        blocks.append("**Parameters**\n\n" + "\n".join(parameter(p) for p in parsed.params))
    returns = [r for r in parsed.many_returns if not r.is_generator]
    if returns:
        blocks.append("**Returns**\n\n" + "\n".join(
            f"- {text(r.type_name or '')}{': ' if r.type_name and r.description else ''}{text(r.description or '')}"
            for r in returns))
    if parsed.raises:
        blocks.append("**Raises**\n\n" + "\n".join(f"- `{r.type_name}`: {text(r.description or '')}"
                                                   for r in parsed.raises))
    for example in parsed.examples:
        code = "\n".join(line.removeprefix(">>> ").removeprefix("... ").removeprefix(">>>").removeprefix("...")
                         for line in f"{example.snippet or ''}\n{example.description or ''}".splitlines()
                         if line.startswith((">>>", "...")))
        blocks.append("**Example**\n\n```python\n" + code + "\n```")
    return "\n\n".join(blocks)


def parameter(p) -> str:
    """'- `name` (type, optional): description'."""
    kind = f" ({text(p.type_name)}{', optional' if p.is_optional else ''})" if p.type_name else ""
    return f"- `{p.arg_name}`{kind}: {text(p.description or '')}"


def text(value: str) -> str:
    """reStructuredText's ``literal`` as Markdown's `literal`, lines joined into paragraphs."""
    paragraphs = re.split(r"\n\s*\n", value.strip())
    return "\n\n".join(" ".join(line.strip() for line in p.splitlines()) for p in paragraphs).replace("``", "`")


def main(argv) -> int:
    page = render()
    if "--check" in argv:
        if not PAGE.exists() or PAGE.read_text(encoding="utf-8") != page:
            print(f"{PAGE} is stale: run make api-docs", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(page, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
