"""Parameter sweeps: one scene, varied over the cartesian product of ``--vary`` specs, members run in parallel.

``balloon-cg sweep SCENE.toml --vary M=0:0.005:21 -o SWEEP.h5`` expands the specs into members (each a Scene
made by ``Scene.with_overrides``), computes them in worker processes (a local ProcessPoolExecutor, or an
existing dask.distributed cluster with ``--scheduler``) and appends each member to one HDF5 file as it finishes.
Only the parent process writes the sweep file.

Sweep file layout (format "balloon-cg-sweep/1")::

    /                   attrs: format, scene_name, scene_toml (base scene, normalised), vary (JSON list of
                               [key, values]), mode, members (total count), package_version, generated_digest,
                               created, command
    /members/<index>/   attrs: overrides (JSON object, dotted key -> value), scene_hash (sha256 of the member
                               scene's normalised TOML), scene_toml, created, worker_pid, wall_time,
                               branch_point_kinds, branch_point_blocks, branch_point_pressures, + the member
                               run file's provenance (package_version, generated_digest, tolerance)
        branches/<name>/          exactly as storage.write_run writes /branches (storage.py)
        snap_throughs/            as in a run file (full analysis only)

A member is first written under a temporary name in /members and then renamed, so an interrupted sweep leaves
only whole members; the file is flushed after each. Re-running the same sweep skips the members whose group
holds the same scene_hash; a different sweep into an existing file needs --force.
"""
import contextlib
import datetime
import hashlib
import io
import itertools
import json
import os
import re
import secrets
import shlex
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np
from tqdm import tqdm

import balloon_cg

from ..model.kernels import generated_digest
from ..scene import Scene, SceneError, parse_scene
from ..io.run_file import _branch_order, _plain, _read_branch, _read_snaps, check_output, write_run

FORMAT = "balloon-cg-sweep/1"
MODES = ("analysis", "no-pear", "primary-only")
_TMP_PREFIX = ".tmp-"


class SweepError(ValueError):
    """A sweep that cannot be run as asked (bad --vary spec, conflicting existing file)."""


class MemberFailure(RuntimeError):
    """Some members raised; the others were written."""


# --- specs and members -------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Member:
    index: int
    overrides: dict  # canonical dotted key -> value (as given to Scene.with_overrides)
    scene: Scene

    @property
    def scene_hash(self) -> str:
        return scene_hash(self.scene)

    @property
    def label(self) -> str:
        return ", ".join(f"{k}={_fmt(v)}" for k, v in self.overrides.items())


def scene_hash(scene: Scene) -> str:
    """sha256 of the scene's normalised TOML (independent of comments and formatting of the source file)."""
    return hashlib.sha256(scene.to_toml().encode("utf-8")).hexdigest()


_INDEXED = re.compile(r"(\w+)\.(\w+)\[(\d+)\]")


def parse_vary(spec: str, scene: Scene) -> tuple[str, list]:
    """``KEY=START:STOP:COUNT`` (COUNT evenly spaced values, ends included) or ``KEY=v1,v2,...`` -> (key, values).

    KEY is a dotted scene key (``field.M``, ``continuation.stop_stretch``, ``field.coils[0].radius``,
    ``material.alpha[0]``) or a bare name found in exactly one table (``M`` -> ``field.M``).
    """
    key, sep, text = spec.partition("=")
    key, text = key.strip(), text.strip()
    if not sep or not key or not text:
        raise SweepError(f"--vary {spec!r}: expected KEY=START:STOP:COUNT or KEY=v1,v2,...")
    key = canonical_key(key, scene)
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise SweepError(f"--vary {spec!r}: a range is START:STOP:COUNT (three fields)")
        try:
            start, stop = (_number(p) for p in parts[:2])
            count = int(parts[2])
        except ValueError:
            raise SweepError(f"--vary {spec!r}: START and STOP must be numbers and COUNT an integer") from None
        if count < 1 or (count == 1 and start != stop):
            raise SweepError(f"--vary {spec!r}: COUNT must be >= 2 (or 1 with START = STOP)")
        values = np.linspace(start, stop, count).tolist()
        if isinstance(start, int) and isinstance(stop, int) and all(float(v).is_integer() for v in values):
            values = [int(v) for v in values]
    else:
        values = [_value(v.strip()) for v in text.split(",")]
        if any(v == "" for v in values):
            raise SweepError(f"--vary {spec!r}: empty value in the list")
    return key, values


def canonical_key(key: str, scene: Scene) -> str:
    """The dotted key for ``key``: bare names are looked up in the scene's tables (must be unique)."""
    if "." in key:
        return key
    data = scene.to_dict()
    tables = [t for t, content in data.items() if key in content]
    if key == "preset":
        tables = ["material"]
    if len(tables) != 1:
        found = f"in tables {', '.join(tables)}" if tables else "in no table"
        raise SweepError(f"--vary {key}: a bare name must name a key of exactly one scene table; "
                         f"{key!r} is {found} (write TABLE.{key})")
    return f"{tables[0]}.{key}"


def expand(scene: Scene, specs: list[str]) -> list[Member]:
    """The members of a sweep: the cartesian product of the specs (first spec outermost), each validated.

    Raises SweepError (a bad spec) or SceneError: one message for every invalid member, before any work.
    """
    if not specs:
        raise SweepError("give at least one --vary KEY=...")
    axes = [parse_vary(s, scene) for s in specs]
    keys = [k for k, _ in axes]
    if len(set(keys)) != len(keys):
        raise SweepError(f"--vary: the same key is varied twice ({', '.join(keys)})")
    members, errors = [], {}
    for index, values in enumerate(itertools.product(*(v for _, v in axes))):
        overrides = dict(zip(keys, values))
        try:
            member_scene = scene.with_overrides(_expand_indexed(overrides, scene))
        except SceneError as e:
            errors.setdefault(str(e), []).append(index)
            continue
        members.append(Member(index, overrides, member_scene))
    if errors:
        total = sum(map(len, errors.values()))
        lines = [f"{msg} (member{'s' if len(idx) > 1 else ''} {_ranges(idx)})" for msg, idx in errors.items()]
        raise SceneError(f"{total} of {total + len(members)} sweep members are invalid: " + "; ".join(lines))
    return members


def _expand_indexed(overrides: dict, scene: Scene) -> dict:
    """``material.alpha[0] = x`` as a whole-list override ``material.alpha = [..., x, ...]`` (what
    Scene.with_overrides accepts); other keys unchanged."""
    out, data = {}, scene.to_dict()
    for key, value in overrides.items():
        match = _INDEXED.fullmatch(key)
        if match is None:
            out[key] = value
            continue
        tab, k, i = match.group(1), match.group(2), int(match.group(3))
        current = out.get(f"{tab}.{k}", data.get(tab, {}).get(k))
        if not isinstance(current, list) or any(isinstance(x, dict) for x in current):
            raise SceneError(f"{key} = {_fmt(value)}: {tab}.{k} is not a list of numbers")
        if i >= len(current):
            raise SceneError(f"{key} = {_fmt(value)}: {tab}.{k} has {len(current)} entries")
        current = list(current)
        current[i] = value
        out[f"{tab}.{k}"] = current
    return out


def _number(text: str):
    text = text.strip()
    try:
        return int(text)
    except ValueError:
        return float(text)


def _value(text: str):
    for parse in (int, float):
        try:
            return parse(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text.strip("\"'")


def _fmt(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _ranges(indices: list[int]) -> str:
    return ", ".join(map(str, indices[:6])) + (", …" if len(indices) > 6 else "")


# --- the worker --------------------------------------------------------------------------------------------

def compute_member(index: int, scene_toml: str, scene_name: str, mode: str) -> dict:
    """Worker side: compute one member and return its run file as bytes (written by storage.write_run) with a
    short summary. Runs in a worker process (local pool or dask worker); picklable in and out."""
    from ..analysis.picture import analyse
    from ..analysis.branch import trace_primary

    # BLAS runs single-threaded in every member: importing balloon_cg limits it (balloon_cg/__init__); with
    # 2 BLAS threads per member on busy cores a member ran 35x slower (benchmarks/sweep.py).
    scene = parse_scene(scene_toml, scene_name)
    start = time.perf_counter()
    if mode == "primary-only":
        branches, snaps, points = [trace_primary(scene)], None, []
    else:
        picture = analyse(scene, pear=(mode == "analysis"))
        branches, snaps, points = picture.branches, picture.snaps, picture.branch_points
    wall = time.perf_counter() - start
    with tempfile.TemporaryDirectory(prefix="balloon-cg-sweep-") as tmp:
        path = write_run(Path(tmp) / "member.h5", scene, branches, snaps=snaps,
                         extra_attrs={"command": f"sweep member {index}"})
        data = path.read_bytes()
    return {
        "index": index,
        "run_file": data,
        "wall_time": wall,
        "pid": os.getpid(),
        "branch_point_kinds": [bp.kind for bp in points],
        "branch_point_blocks": [bp.block for bp in points],
        "branch_point_pressures": [float(bp.X[-1]) for bp in points],
    }


# --- the writer (parent process only) ----------------------------------------------------------------------

@dataclass
class SweepResult:
    path: Path
    members: list
    computed: list = field(default_factory=list)  # indices computed by this call
    skipped: list = field(default_factory=list)  # indices already in the file (same scene_hash)
    failed: dict = field(default_factory=dict)  # index -> error message
    wall_time: float = 0.0


def _root_attrs(scene: Scene, axes: list, mode: str, n: int, command: str | None) -> dict:
    return {
        "format": FORMAT,
        "scene_name": scene.name,
        "scene_toml": scene.to_toml(),
        "vary": json.dumps(axes),
        "mode": mode,
        "members": n,
        "package_version": balloon_cg.__version__,
        "generated_digest": generated_digest(),
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": command if command is not None else shlex.join(sys.argv),
    }


def _open_sweep(path: Path, attrs: dict, members: list[Member], force: bool) -> tuple[h5py.File, set]:
    """Open (or create) the sweep file; returns it and the indices already done. A file holding another sweep is
    an error unless ``force`` (then it is replaced)."""
    if path.exists() and force:
        path.unlink()
    if path.exists():
        try:
            f = h5py.File(path, "a")
        except OSError:
            raise SweepError(f"{path}: exists and is not a readable HDF5 file (use --force to replace it)") from None
        try:
            done = _check_existing(f, path, attrs, members)
        except BaseException:
            f.close()
            raise
        return f, done
    check_output(path, force=False)
    f = h5py.File(path, "w-")
    f.attrs.update(attrs)
    f.create_group("members")
    f.flush()
    return f, set()


def _check_existing(f: h5py.File, path: Path, attrs: dict, members: list[Member]) -> set:
    if f.attrs.get("format") != FORMAT:
        raise SweepError(f"{path}: exists and is not a balloon-cg sweep file (use --force to replace it)")
    for key in ("scene_toml", "vary", "mode", "members"):
        old, new = _plain(f.attrs.get(key)), attrs[key]
        if old != new:
            what = {"scene_toml": f"the base scene differs ({_scene_diff(old, new)})", "vary": f"--vary differs (file: {old}, now: {new})",
                    "mode": f"the mode differs (file: {old}, now: {new})",
                    "members": f"the member count differs (file: {old}, now: {new})"}[key]
            raise SweepError(f"{path}: holds a different sweep: {what}; use --force to replace it")
    group = f.require_group("members")
    for name in [n for n in group if n.startswith(_TMP_PREFIX)]:
        del group[name]  # a member whose write was interrupted before its rename
    expected = {str(m.index): m for m in members}
    done = set()
    for name in group:
        m = expected.get(name)
        if m is None:
            raise SweepError(f"{path}: member {name} is not a member of this sweep; use --force to replace the file")
        stored = _plain(group[name].attrs.get("scene_hash"))
        if stored != m.scene_hash:
            raise SweepError(f"{path}: member {name} ({m.label}) was computed for another scene "
                             f"(scene_hash {str(stored)[:12]}… in the file, {m.scene_hash[:12]}… now); "
                             "use --force to replace the file")
        done.add(m.index)
    return done


def _scene_diff(old: str, new: str) -> str:
    """The dotted keys whose values differ between two normalised scene TOML texts."""
    def flat(data, prefix=""):
        out = {}
        for k, v in data.items():
            if isinstance(v, dict):
                out |= flat(v, f"{prefix}{k}.")
            else:
                out[f"{prefix}{k}"] = v
        return out

    try:
        a, b = flat(tomllib.loads(old)), flat(tomllib.loads(new))
    except (tomllib.TOMLDecodeError, TypeError):
        return "unreadable scene in the file"
    keys = [k for k in dict.fromkeys([*a, *b]) if a.get(k) != b.get(k)]
    return ", ".join(f"{k}: {a.get(k)} in the file, {b.get(k)} now" for k in keys) or "formatting only"


def _append_member(f: h5py.File, member: Member, result: dict) -> None:
    """Write one member under a temporary name, rename it to /members/<index>, flush."""
    group = f["members"]
    tmp = f"{_TMP_PREFIX}{member.index}-{secrets.token_hex(4)}"
    with h5py.File(io.BytesIO(result["run_file"]), "r") as run:
        g = group.create_group(tmp)
        try:
            for key in ("package_version", "generated_digest", "tolerance", "created"):
                g.attrs[key] = run.attrs[key]
            g.attrs.update({
                "overrides": json.dumps(member.overrides),
                "scene_hash": member.scene_hash,
                "scene_toml": member.scene.to_toml(),
                "worker_pid": result["pid"],
                "wall_time": result["wall_time"],
                "branch_point_pressures": np.array(result["branch_point_pressures"], dtype=float),
            })
            for key in ("branch_point_kinds", "branch_point_blocks"):
                g.attrs.create(key, np.array(result[key], dtype=object), dtype=h5py.string_dtype())
            run.copy(run["branches"], g, "branches")
            if "snap_throughs" in run:
                run.copy(run["snap_throughs"], g, "snap_throughs")
        except BaseException:
            del group[tmp]
            raise
    group.move(tmp, str(member.index))
    f.flush()


def run_sweep(scene: Scene, specs: list[str], out_path, *, mode: str = "analysis", workers: int | None = None,
              scheduler: str | None = None, force: bool = False, progress: bool = False,
              command: str | None = None, members: list[Member] | None = None) -> SweepResult:
    """Expand ``specs`` over ``scene``, compute the members not yet in ``out_path`` and append them.

    ``workers``: local processes (default: all cores; 1 computes in this process); ``scheduler``: address of a
    dask.distributed scheduler to send the members to instead. Failed members are reported in the result (the
    others are written); an interrupted sweep keeps the members written so far.
    """
    if mode not in MODES:
        raise SweepError(f"mode {mode!r}: must be one of {', '.join(MODES)}")
    start = time.perf_counter()
    members = expand(scene, specs) if members is None else members
    axes = [list(parse_vary(s, scene)) for s in specs]
    path = Path(out_path)
    f, done = _open_sweep(path, _root_attrs(scene, axes, mode, len(members), command), members, force)
    result = SweepResult(path, members, skipped=sorted(done))
    todo = [m for m in members if m.index not in done]
    by_index = {m.index: m for m in members}
    try:
        with tqdm(total=len(members), initial=len(done), desc="sweep", unit=" members",
                  disable=not progress, file=sys.stderr) as bar:
            with contextlib.closing(_compute(todo, mode, workers, scheduler)) as outcomes:
                for index, outcome in outcomes:
                    if isinstance(outcome, BaseException):
                        result.failed[index] = f"{type(outcome).__name__}: {outcome}"
                    else:
                        _append_member(f, by_index[index], outcome)
                        result.computed.append(index)
                    bar.update()
    finally:
        f.close()
    result.wall_time = time.perf_counter() - start
    return result


def _compute(todo: list[Member], mode: str, workers: int | None, scheduler: str | None):
    """Yield (index, result dict or exception) as members finish."""
    if not todo:
        return
    jobs = [(m.index, m.scene.to_toml(), m.scene.name, mode) for m in todo]
    if scheduler is not None:
        yield from _compute_dask(jobs, scheduler)
        return
    workers = (os.cpu_count() or 1) if workers is None else workers
    if workers <= 1 or len(jobs) == 1:
        for job in jobs:
            try:
                yield job[0], compute_member(*job)
            except Exception as e:  # noqa: BLE001 - reported per member
                yield job[0], e
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed

    pool = ProcessPoolExecutor(max_workers=min(workers, len(jobs)))
    try:
        futures = {pool.submit(compute_member, *job): job[0] for job in jobs}
        for future in as_completed(futures):
            error = future.exception()
            yield futures[future], error if error is not None else future.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _compute_dask(jobs, scheduler: str):
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise SweepError("--scheduler needs the 'distributed' package (pip install 'balloon-cg[sweep]')") from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as e:
        raise SweepError(f"--scheduler {scheduler}: cannot connect ({e})") from None
    try:
        futures = {client.submit(compute_member, *job, pure=False): job[0] for job in jobs}
        for future in as_completed(futures):
            index = futures[future]
            if future.status == "error":
                yield index, future.exception()
            else:
                yield index, future.result()
            future.release()
    finally:
        client.close()


# --- reading and summary -----------------------------------------------------------------------------------

def read_sweep(path) -> dict:
    """{'path', 'attrs', 'members': {index: {'overrides', 'scene_hash', 'attrs', 'branches': {name: branch}}}}.

    Branches are dicts as read by storage.read_run.
    """
    path = Path(path)
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise SweepError(f"{path}: not a balloon-cg sweep file")
        out = {"path": str(path), "attrs": {k: _plain(v) for k, v in f.attrs.items()}, "members": {}}
        for name in sorted((n for n in f["members"] if not n.startswith(_TMP_PREFIX)), key=int):
            g = f["members"][name]
            attrs = {k: (v.tolist() if isinstance(v, np.ndarray) else _plain(v)) for k, v in g.attrs.items()}
            out["members"][int(name)] = {
                "overrides": json.loads(attrs["overrides"]),
                "scene_hash": attrs["scene_hash"],
                "attrs": attrs,
                "branches": {b: _read_branch(g["branches"][b]) for b in _branch_order(g["branches"])},
                "snap_throughs": _read_snaps(g.get("snap_throughs")),
            }
    return out


def format_summary(result: SweepResult) -> str:
    """Members, time, and per member the pear branch points (pressures) read back from the sweep file."""
    sweep = read_sweep(result.path)
    mode = sweep["attrs"]["mode"]
    lines = [
        f"sweep file     {result.path}",
        f"members        {len(result.members)}: {len(result.computed)} computed, {len(result.skipped)} already in "
        f"the file, {len(result.failed)} failed",
        f"time           {result.wall_time:.2f} s",
        f"mode           {mode}",
        "",
    ]
    w = max([len("overrides")] + [len(m.label) for m in result.members])
    header = f"{'member':>6}  {'overrides':<{w}}  {'points':>6}  {'pear BPs':>8}  pear branch point pressures"
    lines.append(header)
    for m in result.members:
        if m.index in result.failed:
            lines.append(f"{m.index:>6}  {m.label:<{w}}  failed: {result.failed[m.index]}")
            continue
        stored = sweep["members"].get(m.index)
        if stored is None:
            lines.append(f"{m.index:>6}  {m.label:<{w}}  not computed")
            continue
        a = stored["attrs"]
        n_points = len(stored["branches"]["primary"]["pressure"])
        pears = [p for p, block in zip(a.get("branch_point_pressures", []), a.get("branch_point_blocks", []))
                 if block == "odd_held"]
        count = "n/a" if mode == "primary-only" else str(len(pears))
        pressures = ", ".join(f"{p:.6g}" for p in pears) if pears else ("-" if mode != "primary-only" else "")
        lines.append(f"{m.index:>6}  {m.label:<{w}}  {n_points:>6}  {count:>8}  {pressures}")
    return "\n".join(lines)
