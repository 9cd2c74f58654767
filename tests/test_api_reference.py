"""docs/api_reference.md is generated from the docstrings of the public API (benchmarks/api_reference.py, make api-docs)
and never stale; the public functions and methods document their parameters and what they return, numpy style,
and every public class shows an example."""
import importlib.util
import inspect
from pathlib import Path

import pytest

import balloon_cg

docstring_parser = pytest.importorskip("docstring_parser")
SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "api_reference.py"


def generator():
    spec = importlib.util.spec_from_file_location("api_reference", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def parsed(obj):
    return docstring_parser.parse(inspect.getdoc(obj), docstring_parser.DocstringStyle.NUMPYDOC)


def public():
    return {name: getattr(balloon_cg, name) for name in balloon_cg.__all__ if name != "__version__"}


def test_the_api_page_is_generated_from_the_docstrings():
    page = generator().render()
    assert page == generator().PAGE.read_text(encoding="utf-8"), "docs/api_reference.md is stale: make api-docs"
    for name, obj in public().items():
        assert f"`{name}" in page
    assert "**Parameters**" in page and "**Returns**" in page and "**Raises**" in page and "```python" in page


def test_functions_and_methods_document_their_parameters_and_returns():
    documented = 0
    for name, obj in public().items():
        functions = [(name, obj)] if inspect.isfunction(obj) else []
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            functions += [(f"{name}.{member}", getattr(value, "__func__", value))
                          for member, value in generator().members(obj) if not isinstance(value, property)]
        for label, function in functions:
            parameters = [p for p in inspect.signature(function).parameters if p not in ("self", "cls")]
            doc = parsed(function)
            assert [p.arg_name for p in doc.params] == parameters, label
            if parameters or inspect.isfunction(obj):
                assert doc.many_returns, f"{label}: no Returns section"
            documented += 1
    assert documented >= 20


def test_every_public_class_has_an_example():
    for name, obj in public().items():
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            assert parsed(obj).examples, name
