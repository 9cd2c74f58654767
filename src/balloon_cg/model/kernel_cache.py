"""On-demand kernels for a scene class that is not committed in generated/: a user formula, or any material with
the dielectric term (a committed class's Ogden exponents or a strain energy, with or without a field), or any class
on a reference shape other than the sphere (a spheroid, a tube).

The module is generated at first use by the same generator as generated/ (codegen/, shipped as
balloon_cg.codegen; it needs SymPy, the ``codegen`` extra) into a content-keyed cache folder, and imported from
there by every later run. The key is the SHA-256 of

    (canonical formula and parameter names, or 'ogden' and the exponents (None: runtime exponents), the names of
     the energy terms beyond the elastic one, surface kernels or not, codegen.GENERATOR_VERSION, the generator's
     source digest (codegen.generator_digest), SymPy version, and a reference shape other than the sphere:
     scene.Geometry),

so an edited formula, a new generator or another SymPy gives a new module; parameter values (material
parameters, the voltage) are kernel arguments and never enter the key. The text is written to a temporary file in the cache folder and moved into
place with ``os.replace`` (atomic on one file system), under an exclusive lock on ``.NAME.lock`` beside it: of
concurrent processes missing the same class (sweep workers, test workers) one generates it and the others wait for
it and import the module it wrote; each finds either no module or a complete one.

Generation runs in a child process (``python -m balloon_cg.model.kernel_cache``) under a time budget
(GENERATION_TIMEOUT seconds, $BALLOON_CG_CODEGEN_TIMEOUT to change it) and a memory bound (GENERATION_MEMORY
bytes of address space), and the module it prints is at most MAX_MODULE_CHARS long: a formula within
scene/formula's bounds that still outgrows them is refused with one line naming it (SceneError, exit 2), and
SIGINT or SIGTERM stops the generation at once (KeyboardInterrupt, exit 130; the child is killed, and dies with
its parent). The cached file ends with a line holding the SHA-256 of the
module text above it (``# content-sha256 HEX``); a file whose digest does not match (truncated, empty, garbled)
is regenerated with a KernelCacheWarning before it is imported.

This is the only runtime module that imports SymPy or codegen (tests/test_layers.py).
"""
import contextlib
import ctypes
import hashlib
import importlib.metadata
import importlib.util
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

from .. import codegen
from ..scene import formula as formula_module
from ..scene.tables import Shape
from ..scene.validation import SceneError

CACHE_ENV = "BALLOON_CG_KERNEL_CACHE"
TIMEOUT_ENV = "BALLOON_CG_CODEGEN_TIMEOUT"
GENERATION_TIMEOUT = 600.0  # seconds (a user formula at the bounds of scene/formula takes about a minute)
GENERATION_MEMORY = 2 * 1024**3  # bytes of address space of the generating process
MAX_MODULE_CHARS = 2_000_000  # a generated module's text (the largest committed one: 85 kB)
DIGEST_MARK = "# content-sha256 "
SPHERE = Shape.SPHERE.value  # the reference shape of every committed class (codegen/meridian.py: MERIDIANS)


class KernelCacheWarning(UserWarning):
    """A cached kernel module was damaged (its content digest does not match) and is generated again."""


def cache_dir() -> Path:
    """$BALLOON_CG_KERNEL_CACHE, else $XDG_CACHE_HOME/balloon-cg/kernels (XDG_CACHE_HOME defaulting to ~/.cache)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "balloon-cg" / "kernels"


def _sympy_version() -> str:
    try:
        return importlib.metadata.version("sympy")
    except importlib.metadata.PackageNotFoundError:
        raise SceneError("kernels: a user formula or the [electric] term needs its kernels generated once, which "
                         "needs SymPy: pip install 'balloon-cg[codegen]'") from None


@dataclass(frozen=True)
class Exponents:
    """An Ogden material's class as plain data: the exponents of a committed class as the strings it was generated
    from (its INPUTS 'alphas'), or None for the general class (runtime exponents)."""

    alphas: tuple | None


def _identity(material) -> tuple:
    """What the class is generated from: a scene/formula.Formula or Exponents."""
    if isinstance(material, Exponents):
        return ("ogden", material.alphas)
    return (material.text, tuple(material.parameters))


def class_key(material, terms: tuple, surface: bool = False, shape: str = SPHERE) -> str:
    """The cache key of the class of ``material`` (scene/formula.Formula or Exponents) with the energy terms
    ``terms`` (names, model/kernels.py: scene_terms) on the reference ``shape`` (codegen/meridian.py: MERIDIANS);
    ``surface``: its surface kernels (MODEL.md §8) instead of the axisymmetric ones."""
    text = repr((*_identity(material), tuple(terms), bool(surface), codegen.GENERATOR_VERSION,
                 codegen.generator_digest(), _sympy_version(), *(() if shape == SPHERE else (shape,))))
    return hashlib.sha256(text.encode()).hexdigest()


def module_name(material, terms: tuple, surface: bool = False, shape: str = SPHERE) -> str:
    """kind (surface_, ogden or energy), the terms other than the pressure, a shape other than the sphere, the
    key's first 32 digits."""
    kind = ("surface_" if surface else "") + ("ogden" if isinstance(material, Exponents) else "energy")
    extra = "".join(f"_{name}" for name in terms if name != "pressure") + ("" if shape == SPHERE else f"_{shape}")
    return f"{kind}{extra}_{class_key(material, terms, surface, shape)[:32]}"


def module_path(material, terms: tuple, surface: bool = False, shape: str = SPHERE) -> Path:
    return cache_dir() / f"{module_name(material, terms, surface, shape)}.py"


def generate(material, terms: tuple, timings: dict | None = None, surface: bool = False, shape: str = SPHERE) -> str:
    """The module text of the class, or of its surface kernels (stage timings in seconds into ``timings``: see
    codegen/build.py)."""
    _sympy_version()
    from ..codegen import build, classes
    from ..codegen.functional import SceneClass
    from ..codegen.meridian import MERIDIANS
    from ..codegen.terms.elastic import Elastic

    if isinstance(material, Exponents):
        elastic = Elastic(material.alphas)
    else:
        elastic = classes.strain_energy(material.text, material.parameters)
    cls = SceneClass(module_name(material, terms, surface, shape), elastic, classes.terms(terms), MERIDIANS[shape])
    return (build.surface_module if surface else build.class_module)(cls, timings)


def load(material, terms: tuple, timings: dict | None = None, surface: bool = False, shape: str = SPHERE):
    """The kernel module of the class (``surface``: its surface kernels; ``shape``: its reference meridian),
    generated (bounded_generate) and written atomically into the cache first if missing or damaged; imported once
    per process (as ``sys.modules[module_name]``)."""
    path = module_path(material, terms, surface, shape)
    if path.stem in sys.modules:
        return sys.modules[path.stem]
    if _damage(path) is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        with _generation_lock(path):
            damage = _damage(path)  # again: another process may have written it while this one waited
            if damage is not None:
                if damage != "missing":
                    warnings.warn(f"{path}: damaged cached kernel module ({damage}); generating it again",
                                  KernelCacheWarning, stacklevel=2)
                text = bounded_generate(material, terms, timings, surface, shape)
                start = time.perf_counter()
                with tempfile.NamedTemporaryFile("w", dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp",
                                                 delete=False, encoding="utf-8") as handle:
                    handle.write(sealed(text))
                os.replace(handle.name, path)
                if timings is not None:
                    timings["write"] = time.perf_counter() - start
    start = time.perf_counter()
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules[path.stem] = module
    if timings is not None:
        timings["import"] = time.perf_counter() - start
    return module


@contextlib.contextmanager
def _generation_lock(path: Path):
    """An exclusive advisory lock (flock) on ``.STEM.lock`` beside ``path`` for the duration: processes missing the
    same module generate it once, the others wait and import what the first wrote (without it each would spend the
    generation's minute and replace the file under the others, whose numba cache then misses: test workers, sweep
    workers). The holder removes the lock file before releasing it, so that nothing is left beside the modules; a
    process that opened it before then still waits for the release and finds the module written (one that opens a
    new lock file finds it written before locking), and after a failed generation two waiting processes may both
    generate, each writing atomically. Released when the holder exits, however it exits; where flock is missing
    (not POSIX), no lock."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    lock = path.parent / f".{path.stem}.lock"
    with open(lock, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            lock.unlink(missing_ok=True)
            fcntl.flock(handle, fcntl.LOCK_UN)


def sealed(text: str) -> str:
    """The module text with its content digest as the last line (what the cache holds)."""
    text = text if text.endswith("\n") else text + "\n"
    return f"{text}{DIGEST_MARK}{hashlib.sha256(text.encode('utf-8')).hexdigest()}\n"


def _damage(path: Path) -> str | None:
    """None when ``path`` is a whole cached module (its last line is the digest of the text above it), else what
    is wrong ('missing', 'no digest line', 'digest mismatch', …)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return "missing"
    except OSError as e:
        return f"unreadable: {e.strerror or e}"
    body, mark, tail = data.rpartition(DIGEST_MARK.encode())
    if not mark or not body.endswith(b"\n") or not tail.endswith(b"\n"):
        return "empty" if not data else "no digest line (truncated?)"
    if hashlib.sha256(body).hexdigest().encode() != tail.strip():
        return "digest mismatch (garbled?)"
    return None


def bounded_generate(material, terms: tuple, timings: dict | None = None, surface: bool = False,
                     shape: str = SPHERE) -> str:
    """``generate`` in a child process under the time budget and memory bound (SceneError naming the formula
    when one is hit); SIGINT or SIGTERM here raises KeyboardInterrupt after killing the child."""
    _sympy_version()
    request = {"terms": list(terms), "surface": bool(surface), "shape": shape,
               **({"alphas": material.alphas} if isinstance(material, Exponents) else
                  {"formula": material.text, "parameters": list(material.parameters)})}
    budget = _budget()
    what = (f"material.energy = {material.text!r}" if not isinstance(material, Exponents) else
            f"the Ogden class with exponents {material.alphas}")
    child = None
    try:
        with _signals_raise() as arm:  # installed before the child exists: no signal falls between the two
            child = subprocess.Popen([sys.executable, "-m", __name__], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True)  # no preexec_fn: unsafe in a threaded worker
            arm()
            out, err = child.communicate(json.dumps(request), timeout=budget)
    except subprocess.TimeoutExpired:
        raise SceneError(f"{what}: its kernels were not generated within {budget:g} s (the time budget, "
                         f"${TIMEOUT_ENV} raises it); simplify the formula") from None
    finally:
        if child is not None and child.poll() is None:
            child.kill()
            child.wait()
    if child.returncode == _OUT_OF_MEMORY:
        raise SceneError(f"{what}: generating its kernels needs more than {GENERATION_MEMORY / 1024**3:g} GiB "
                         "(the memory bound); simplify the formula")
    if child.returncode != 0:
        lines = err.strip().splitlines()
        raise RuntimeError(f"kernel generation failed for {what}: {lines[-1] if lines else child.returncode}")
    reply = json.loads(out)
    if timings is not None:
        timings.update(reply["timings"])
    return checked_size(reply["text"], what)


def checked_size(text: str, what: str) -> str:
    """``text`` if the module is at most MAX_MODULE_CHARS long (the size of the expanded derivatives, after CSE:
    numba's compile time grows with it), else SceneError naming ``what``."""
    if len(text) > MAX_MODULE_CHARS:
        raise SceneError(f"{what}: its kernels would be {len(text) / 1e6:.3g} MB of code; at most "
                         f"{MAX_MODULE_CHARS / 1e6:g} MB (the committed classes are below 0.1 MB); simplify the "
                         "formula")
    return text


_OUT_OF_MEMORY = 75


def _budget() -> float:
    text = os.environ.get(TIMEOUT_ENV)
    if not text:
        return GENERATION_TIMEOUT
    try:
        budget = float(text)
    except ValueError:
        budget = -1.0
    if not 0 < budget < float("inf"):
        raise SceneError(f"${TIMEOUT_ENV} = {text!r}: must be a number of seconds > 0")
    return budget


def _child_limits() -> None:
    """In the generating child, first thing: the memory bound, and death with its parent (Linux)."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (GENERATION_MEMORY, GENERATION_MEMORY))
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG


@contextlib.contextmanager
def _signals_raise():
    """SIGINT and SIGTERM raise KeyboardInterrupt for the duration (main thread only), from the moment the yielded
    ``arm()`` is called; a signal before it (while the child is spawned, so that it is never left unkilled) is
    held and raised by ``arm()``."""
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    state = {"armed": False, "held": False}

    def stop(signum, frame):
        if not state["armed"]:
            state["held"] = True
            return
        raise KeyboardInterrupt

    def arm():
        state["armed"] = True
        if state["held"]:
            raise KeyboardInterrupt

    previous = {s: signal.signal(s, stop) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield arm
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def _child_main() -> int:
    """The generating child: the request (JSON) on stdin, {'text', 'timings'} (JSON) on stdout."""
    _child_limits()
    request = json.loads(sys.stdin.read())
    if "alphas" in request:
        alphas = request["alphas"]
        material = Exponents(None if alphas is None else tuple(alphas))
    else:
        material = formula_module.parse_formula(request["formula"], tuple(request["parameters"]))
    timings = {}
    try:
        text = generate(material, tuple(request["terms"]), timings, request["surface"], request["shape"])
    except MemoryError:
        return _OUT_OF_MEMORY
    json.dump({"text": text, "timings": timings}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(_child_main())
