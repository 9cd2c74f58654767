"""The one line on a terminal's stderr before a generated kernel module is compiled for the first time."""
import importlib
import io

from balloon_cg.app.cli import main
from balloon_cg.model import compile_notice


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_compiled_before_reads_numba_s_cache(capsys):
    module = importlib.import_module("balloon_cg.generated.ogden_spom1")
    assert main(["solve", "spom1", "--pole-stretch", "1.5", "--json"]) == 0  # compiled now, if never before
    capsys.readouterr()
    assert compile_notice.compiled_before(module)


def test_first_use_is_announced_once_and_only_on_a_terminal(monkeypatch):
    module = importlib.import_module("balloon_cg.generated.ogden_tpom1")
    monkeypatch.setattr(compile_notice, "_announced", set())
    monkeypatch.setattr(compile_notice, "compiled_before", lambda m: False)
    monkeypatch.setattr("sys.stderr", io.StringIO())  # a pipe or a log: nothing
    compile_notice.announce_first_use(module)
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    compile_notice.announce_first_use(module)
    compile_notice.announce_first_use(module)
    assert terminal.getvalue() == ("balloon-cg: compiling the numba kernels ogden_tpom1 on first use (up to a "
                                   "minute; cached for later runs)\n")
    monkeypatch.setattr(compile_notice, "_announced", set())
    monkeypatch.setattr(compile_notice, "compiled_before", lambda m: True)
    compile_notice.announce_first_use(module)  # compiled before: silent
    assert terminal.getvalue().count("\n") == 1


def test_first_use_is_announced_in_a_notebook(monkeypatch):
    """A Jupyter kernel's stderr is no terminal, but the notebook shows it: the notice is written there too (not in
    plain IPython, whose stderr is the terminal's anyway)."""
    import sys
    import types

    module = importlib.import_module("balloon_cg.generated.ogden_tpom1")
    monkeypatch.setattr(compile_notice, "_announced", set())
    monkeypatch.setattr(compile_notice, "compiled_before", lambda m: False)
    kernel = types.SimpleNamespace(config={"IPKernelApp": {"connection_file": "kernel.json"}})
    monkeypatch.setitem(sys.modules, "IPython", types.SimpleNamespace(get_ipython=lambda: kernel))
    notebook = io.StringIO()  # ipykernel's stream: not a terminal
    monkeypatch.setattr("sys.stderr", notebook)
    compile_notice.announce_first_use(module)
    assert notebook.getvalue().startswith("balloon-cg: compiling the numba kernels ogden_tpom1 on first use")
    monkeypatch.setattr(compile_notice, "_announced", set())
    kernel.config = {"TerminalIPythonApp": {}}
    compile_notice.announce_first_use(module)
    assert notebook.getvalue().count("\n") == 1
