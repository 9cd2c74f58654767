"""Sweeps on disk: a store of one file per member, and one consolidated sweep file rebuilt from it.

``-o SWEEP.h5`` keeps the sweep in two places (docs/hdf5.md, *Sweep files*)::

    SWEEP.h5.members/              the store (the authority)
        sweep.h5                   attrs: the sweep's root attributes (below), written once, atomically
        000003.h5                  member 3: attrs as /members/3 below, groups branches/, snap_throughs/
    SWEEP.h5                       the consolidated view (format "balloon-cg-sweep/3"): a copy of the store

    /                   attrs: format, scene_name, scene_toml (base scene, normalised), vary (JSON list of
                               [key, values]), mode, members (total count), store (the store folder's name),
                               title, + provenance (io.hdf5: with Conventions and history)
    /members/<index>/   attrs: format ("balloon-cg-sweep-member/1"), overrides (JSON object, dotted key -> value),
                               scene_hash (sha256 of the member scene's normalised TOML), scene_toml, tolerance,
                               created, package_version, generated_digest, worker_pid, wall_time,
                               branch_point_kinds, branch_point_classifications, branch_point_blocks,
                               branch_point_pressures, [branch_point_voltages: a voltage continuation], complete,
                               incomplete_gaps, incomplete_branches,
                               incomplete_messages (as a run file's root: analysis.verdict)
        branches/<name>/          exactly as a run file's /branches (io.run_file)
        snap_throughs/            as in a run file (full analysis only)

Every file is written by io.hdf5.atomic_file (a temporary file renamed over the target), so a SIGKILL at any
instant leaves whole files and ``.NAME.<hex>.tmp`` debris, which the next owner (io.lock) removes. A member
file exists only once its member is complete; the view is rebuilt from the store while a sweep call runs (each
member copied in as it is stored: ``rebuilding``), renamed over the sweep file when the call ends, and is never
the only copy (a view without a store is imported back into one). ``--force`` computes into
``SWEEP.h5.members-new/`` and swaps it in (``commit_replacement``) only once every member is there; a swap cut
short is rolled forward by the next call. Format ``balloon-cg-sweep/1`` files (one HDF5 file, members appended
in place) are read as before, and a resumed sweep imports their members into a store.
"""
import contextlib
import json
import re
import shutil
import tomllib
from pathlib import Path

import h5py
import numpy as np

from ..analysis.verdict import Gap
from ..numerics import interrupt
from .hdf5 import atomic_file, checksummed, copy_attrs, copy_tree, plain, provenance, write_strings
from .output import store_path
from .lock import remove_debris
from .run_file import VERDICT_KINDS, read_branches, read_special, verdict_attrs, write_branches
from .legacy import current
from .layout import FileError, carries_checksums, check_data, check_input, reading, require_attrs
from .schema import FINITE
from .tube_file import read_tube, tube_row, write_tube
from ..scene.tables import Shape

FORMAT = "balloon-cg-sweep/3"
FORMATS = ("balloon-cg-sweep/1", "balloon-cg-sweep/2", FORMAT)  # readable; /1 is the single-file layout of earlier
#                                     versions, /2 names the meridian's ends north and south (io/legacy.py)
MEMBER_FORMAT = "balloon-cg-sweep-member/2"
MANIFEST = "sweep.h5"
ROOT_KEYS = ("scene_name", "scene_toml", "vary", "mode", "members")
MEMBER_KEYS = ("overrides", "scene_hash", "scene_toml")
# every attribute a member is written with: required where its datasets carry checksums (written by this version)
WRITTEN_MEMBER = {"format": "str", "tolerance": "float", "worker_pid": "int", "wall_time": "float",
                  "branch_point_pressures": "float[]", "branch_point_kinds": "str[]",
                  "branch_point_classifications": "str[]", "branch_point_blocks": "str[]", "package_version": "str",
                  "generated_digest": "str", "created": "str", "Conventions": "str", "history": "str"} | VERDICT_KINDS
WRITTEN_ROOT = {key: "str" for key in ("format", "scene_name", "scene_toml", "vary", "mode", "store", "title",
                                       "package_version", "generated_digest", "created", "command", "Conventions",
                                       "history")} | {"members": "int"}  # the view's, where its members carry checksums
_MEMBER = re.compile(r"(\d{6})\.h5")
_OLD_TMP_PREFIX = ".tmp-"  # /1 files: a member group whose write was cut before its rename


class SweepError(ValueError):
    """A sweep that cannot be run as asked (bad --vary spec, conflicting existing sweep)."""


class SweepFileError(FileError):
    """A sweep file or store that cannot be read (not a sweep, damaged: names the file and what is missing)."""


def staging_path(path) -> Path:
    path = Path(path)
    return path.with_name(f"{path.name}.members-new")


def _retired_path(path) -> Path:
    path = Path(path)
    return path.with_name(f"{path.name}.members-old")


def root_attrs(scene, axes: list, mode: str, n: int, command: str | None) -> dict:
    """Root attributes of a sweep: the base scene, the varied keys and values, the mode, provenance."""
    return {"format": FORMAT, "scene_name": scene.name, "scene_toml": scene.to_toml(), "vary": json.dumps(axes),
            "mode": mode, "members": n, "title": f"balloon-cg sweep of scene {scene.name}", **provenance(command)}


# --- the store ---------------------------------------------------------------------------------------------

def member_file(directory: Path, index: int) -> Path:
    """The file of member ``index`` in the store ``directory``."""
    return directory / f"{index:06d}.h5"


class Store:
    """The member files of one sweep in one folder; ``done`` maps member index -> its file."""

    def __init__(self, directory: Path, done: dict):
        self.directory = directory
        self.done = done

    def member_file(self, index: int) -> Path:
        return member_file(self.directory, index)

    def write_member(self, member, result) -> None:
        """Write one computed member (app.sweep.MemberResult, or TubeMemberResult: ``write_tube_member``) to its own
        file, atomically."""
        if member.scene.geometry.shape == Shape.TUBE:
            self.write_tube_member(member, result)
            return
        path = self.member_file(member.index)
        primary = result.branches[0]
        points = [primary.params_at(bp.X) for bp in result.branch_points]
        with atomic_file(path, force=True) as f:
            attrs = provenance()
            del attrs["command"]
            f.attrs.update(attrs | {
                "format": MEMBER_FORMAT,
                "tolerance": member.scene.solver.tol,
                "overrides": json.dumps(member.overrides),
                "scene_hash": member.scene_hash,
                "scene_toml": member.scene.to_toml(),
                "worker_pid": result.pid,
                "wall_time": result.wall_time,
                "branch_point_pressures": np.array([p.P for p in points], dtype=float),
            })
            if primary.parameter == "voltage":
                f.attrs["branch_point_voltages"] = np.array([p.voltage for p in points], dtype=float)
            text = h5py.string_dtype()
            for key, values in (("branch_point_kinds", [bp.kind.value for bp in result.branch_points]),
                                ("branch_point_classifications",
                                 [bp.classification.value for bp in result.branch_points]),
                                ("branch_point_blocks", [bp.block.value for bp in result.branch_points])):
                f.attrs.create(key, np.array(values, dtype=object), dtype=text)
            f.attrs.update(verdict_attrs(found=result.incomplete))
            write_branches(f, member.scene, result.branches, result.snaps)
        self.done[member.index] = path

    def write_tube_member(self, member, result) -> None:
        """A tube member (app.sweep.TubeMemberResult): the tube run file's content and verdict (io.tube_file.write_tube:
        complete unless a signal stopped it, or a branch did not start or stopped unresolved) and its branch points
        beside the member attributes."""
        path = self.member_file(member.index)
        picture = result.picture
        points = picture.branches["primary"].branch_points()
        with atomic_file(path, force=True) as f:
            write_tube(f, member.scene, picture)
            attrs = provenance()
            del attrs["command"]
            text = h5py.string_dtype()
            f.attrs.update(attrs | {
                "format": MEMBER_FORMAT, "tolerance": member.scene.solver.tol,
                "overrides": json.dumps(member.overrides), "scene_hash": member.scene_hash,
                "scene_toml": member.scene.to_toml(), "worker_pid": result.pid, "wall_time": result.wall_time,
                "branch_point_pressures": np.array([p.pressure for p in points], dtype=float)})
            for key, values in (("branch_point_kinds", [p.kind.value for p in points]),
                                ("branch_point_classifications", ["" for _ in points]),
                                ("branch_point_blocks", [p.block.value for p in points])):
                f.attrs.create(key, np.array(values, dtype=object), dtype=text)
        self.done[member.index] = path


def open_store(path, attrs: dict, members: list, force: bool) -> Store:
    """The store to compute ``members`` into (call while owning ``path``, io.lock.claim), with the members
    already complete in it. Rolls forward a replacement cut short, imports a store-less sweep file, removes
    debris. ``force``: the staging store of a replacement (a new one, or the one an earlier --force left).
    A different sweep in the way is a SweepError (naming what differs) unless ``force``."""
    path = Path(path)
    _finish_replacement(path)
    if force:
        directory = staging_path(path)
        if (directory / MANIFEST).is_file():
            with contextlib.suppress(SweepError, SweepFileError):
                return _open_existing(directory, attrs, members, path)
        shutil.rmtree(directory, ignore_errors=True)  # another replacement's leftovers: start again
        return _create(directory, attrs)
    directory = store_path(path)
    if directory.is_dir() and (directory / MANIFEST).is_file():
        return _open_existing(directory, attrs, members, path)
    if path.exists():
        return _import(path, directory, attrs, members)
    shutil.rmtree(directory, ignore_errors=True)  # a store cut short before its manifest: nothing in it
    return _create(directory, attrs)


def _create(directory: Path, attrs: dict) -> Store:
    directory.mkdir()
    with atomic_file(directory / MANIFEST) as f:
        f.attrs.update({k: v for k, v in attrs.items() if k != "format"} | {"format": FORMAT})
    return Store(directory, {})


def _open_existing(directory: Path, attrs: dict, members: list, path: Path) -> Store:
    """The store ``directory`` of the sweep file ``path`` (named in the error when it holds another sweep)."""
    manifest = directory / MANIFEST
    with _open(manifest) as f:
        _check_same_sweep(f.attrs, manifest, attrs, path)
    expected = {m.index: m for m in members}
    done = {}
    for item in sorted(directory.iterdir()):
        if item.name == MANIFEST:
            continue
        match = _MEMBER.fullmatch(item.name)
        if match is None:
            continue
        index = int(match.group(1))
        m = expected.get(index)
        if m is None:
            raise SweepError(f"{item}: member {index} is not a member of this sweep; use --force to replace it")
        try:
            with _open(item) as f:
                require_attrs(f.attrs, item, MEMBER_KEYS)
                stored, cut = plain(f.attrs["scene_hash"]), interrupted(f.attrs)
        except SweepFileError:
            item.unlink()  # not a whole member (atomic writes leave none such): computed again
            continue
        if stored != m.scene_hash:
            raise SweepError(f"{item}: member {index} ({m.label}) was computed for another scene "
                             f"(scene_hash {str(stored)[:12]}… in the file, {m.scene_hash[:12]}… now); "
                             "use --force to replace it")
        if not cut:  # a member a signal cut short is computed again (its file is replaced when it is)
            done[index] = item
    for name in [MANIFEST, *(f"{i:06d}.h5" for i in expected)]:
        remove_debris(directory / name)
    return Store(directory, done)


def interrupted(attrs) -> bool:
    """Whether a member's attributes say a signal cut its computation short (analysis.verdict's ``interrupted``
    gap): what it holds is not the member."""
    return Gap.INTERRUPTED.value in [plain(gap) for gap in attrs.get("incomplete_gaps", [])]


def _import(path: Path, directory: Path, attrs: dict, members: list) -> Store:
    """A sweep file without its store (format /1, or a view whose store was removed): its whole members are
    copied into a new store."""
    with _open(path) as f:
        fmt = plain(f.attrs.get("format"))
        if fmt not in FORMATS:
            raise SweepError(f"{path}: exists and is not a balloon-cg sweep file (use --force to replace it)")
        _check_same_sweep(f.attrs, path, attrs)
        store = _create(directory, attrs)
        expected = {str(m.index): m for m in members}
        for name, group in f["members"].items():
            m = expected.get(name)
            if name.startswith(_OLD_TMP_PREFIX) or m is None:
                continue
            if plain(group.attrs.get("scene_hash")) != m.scene_hash:
                raise SweepError(f"{path}: member {name} ({m.label}) was computed for another scene; "
                                 "use --force to replace the file")
            if interrupted(group.attrs):
                continue  # cut short by a signal: computed again
            target = store.member_file(m.index)
            with atomic_file(target, force=True) as out:
                copy_tree(group, out)
                out.attrs["format"] = MEMBER_FORMAT
            store.done[m.index] = target
    return store


def _check_same_sweep(stored, path: Path, attrs: dict, sweep: Path | None = None) -> None:
    """SweepError unless the attributes ``stored`` (read from ``path``) are those of the sweep ``attrs``; the
    message names ``sweep`` (the user's sweep file; default ``path``)."""
    require_attrs(stored, path, ROOT_KEYS, error=SweepFileError)
    for key in ("scene_toml", "vary", "mode", "members"):
        old, new = plain(stored.get(key)), attrs[key]
        if old != new:
            what = {"scene_toml": f"the base scene differs ({_scene_diff(old, new)})",
                    "vary": f"--vary differs (file: {old}, now: {new})",
                    "mode": f"the mode differs (file: {old}, now: {new})",
                    "members": f"the member count differs (file: {old}, now: {new})"}[key]
            raise SweepError(f"{sweep or path}: holds a different sweep: {what}; use --force to replace it")


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


# --- the consolidated view ---------------------------------------------------------------------------------

def consolidate(path, directory: Path) -> None:
    """Rebuild the sweep file ``path`` from the store ``directory`` whole (atomically replacing it)."""
    with rebuilding(path, directory):
        pass


class _Dropped(Exception):
    """A view left unfinished on purpose (``rebuilding``: not ``kept``)."""


@contextlib.contextmanager
def rebuilding(path, directory: Path, trusted=frozenset(), kept: bool = True):
    """``with rebuilding(path, directory) as view:`` the sweep file ``path`` rebuilt from the store ``directory``
    while the block runs: the members stored before it are copied first (an exception meanwhile leaves the old file as
    it was), each member the block stores is added as it comes (``View.add``), and when the block ends, also by an
    exception (an interrupt), the view catches up with the store, gets its table and is renamed over ``path``: ending
    a sweep costs the table and at most one member's copy, not a copy of every member (~0.2 s of CPU per two-coil
    member). ``trusted``: the indices of members already checked (``open_store``), copied without checking again.
    ``kept`` False: the view is dropped unless the block sets ``view.kept`` (a --force sweep's view replaces the old
    file only once the new store is swapped in)."""
    failure = None
    with interrupt.Held() as held:
        try:
            with atomic_file(path, force=True, keep_store=True) as f:
                with interrupt.Held() as early:  # the stored members' copy: a signal raised after it, not in h5py
                    early.start()
                    view = View(f, path, directory, trusted)
                view.kept = kept
                try:
                    yield view
                except BaseException as e:  # noqa: BLE001 - the view is finished first, then it is raised again
                    failure = e
                held.start()  # a signal from here on: the view is finished all the same (a second: dropped)
                if not view.kept:
                    raise _Dropped
                view.finish()
        except _Dropped:
            pass
    if failure is not None:
        raise failure


class View:
    """A sweep file being rebuilt (``rebuilding``): the manifest's attributes, the members copied from the store one by
    one (a member's row of the table noted as it is copied), the table written by ``finish``."""

    def __init__(self, f, path, directory: Path, trusted=frozenset()):
        self.file, self.directory, self.trusted = f, directory, set(trusted)
        self.rows, self.finished, self.kept = {}, False, True
        with _open(directory / MANIFEST) as manifest:
            copy_attrs(manifest, f)
        f.attrs["format"] = FORMAT
        f.attrs["store"] = store_path(path).name
        f.create_group("members")
        self.catch_up()

    def add(self, index: int) -> None:
        """Copy the member ``index`` this process has just written to the store (not checked again: its check was
        ~40 % of a copy)."""
        self.trusted.add(index)
        self._copy(index)

    def catch_up(self) -> None:
        """Copy every member file of the store not yet in the view (one whose copy was cut short: again); each is
        checked as it is read (``_open``) unless ``trusted``."""
        for item in sorted(self.directory.iterdir()):
            match = _MEMBER.fullmatch(item.name)
            if match is not None and int(match.group(1)) not in self.rows:
                self._copy(int(match.group(1)))

    def _copy(self, index: int) -> None:
        members, item = self.file["members"], member_file(self.directory, index)
        if str(index) in members:  # a copy cut short
            del members[str(index)]
        with _open(item, check=index not in self.trusted) as member:
            copy_tree(member, members.create_group(str(index)))
            self.rows[index] = _stored_row(member, item)

    def finish(self) -> None:
        """Catch up with the store and write the table (once)."""
        if self.finished:
            return
        self.catch_up()
        write_table(self.file, self.rows, [key for key, _ in json.loads(plain(self.file.attrs["vary"]))])
        self.finished = True


PEAR_BLOCK = "odd_held"  # the pear-shaped (m = 0, odd) instability of a held balloon


def member_row(overrides: dict, complete: bool, special: list[dict]) -> dict:
    """One member's line of the sweep table: the varied keys, ``complete``, the primary branch's first fold
    (``P_LP``, ``lam2_LP``), the critical pressures of the pear-shaped instability (``P_cr1`` ≥ ``P_cr2``: the branch
    points of the odd held block) and every branch point in stored order (``P_BP1``, ``block_BP1``,
    ``classification_BP1``, ``m_BP1``, …), from its primary branch's ``special`` points (read_special dicts)."""
    folds = [s for s in special if s["kind"] == "LP"]
    branch_points = [s for s in special if s["kind"] == "BP"]
    critical = sorted((s["pressure"] for s in branch_points if s["block"] == PEAR_BLOCK), reverse=True)
    row = dict(overrides) | {"complete": bool(complete), "P_LP": folds[0]["pressure"] if folds else np.nan,
                             "lam2_LP": folds[0]["lam2_top"] if folds else np.nan}
    row |= {f"P_cr{k}": critical[k - 1] if len(critical) >= k else np.nan for k in (1, 2)}
    for k, s in enumerate(branch_points, 1):
        row |= {f"P_BP{k}": s["pressure"], f"block_BP{k}": s["block"],
                f"classification_BP{k}": s["classification"], f"m_BP{k}": int(s["m"])}
    return row


def _stored_row(member, where) -> dict:
    """``member_row`` of a member file (or group) as written by Store.write_member (a tube's: ``tube_row``)."""
    require_attrs(member.attrs, where, MEMBER_KEYS, error=SweepFileError)
    if is_tube(member):
        return (json.loads(plain(member.attrs["overrides"])) | {"complete": bool(member.attrs.get("complete", False))}
                | tube_row(read_tube(member, where)))
    special = member.get("branches/primary/special_points")
    return member_row(json.loads(plain(member.attrs["overrides"])), bool(member.attrs.get("complete", False)),
                      read_special(special) if special is not None else [])


#: the table's columns: (units, long_name) of the quantities; the branch point columns per k
TABLE_COLUMNS = {"complete": ("", "member complete (analysis.verdict)"),
                 "P_LP": ("1", "pressure P at the first fold (LP) of the primary branch"),
                 "lam2_LP": ("1", "λ2(0) at the first fold (LP) of the primary branch"),
                 "P_cr": ("1", "critical pressure of the pear-shaped instability (odd held branch point)"),
                 "P_BP": ("1", "pressure P at the branch point of the primary branch"),
                 "block_BP": ("", "stability block of the branch point"),
                 "classification_BP": ("", "classification of the branch point"),
                 "m_BP": ("", "azimuthal wave number of the branch point (−1: none)"),
                 "P_max": ("1", "pressure maximum of the uniform tube (the primary branch's first LP)"),
                 "P_onset": ("1", "pressure at the onset of bulging (the primary branch's first odd BP)"),
                 "V_onset": ("1", "V/V0 at the onset of bulging"),
                 "P_LV": ("1", "pressure at the bulge branch's volume fold (its first LV)"),
                 "V_LV": ("1", "V/V0 at the bulge branch's volume fold"),
                 "P_M": ("1", "Maxwell's pressure of the uniform closed tube (NaN: none)")}


def write_table(f, rows: dict, keys: list) -> None:
    """The sweep's table at the root of the view ``f``: dimension ``member`` (the stored members' indices), each
    varied key a coordinate along it (CF ``coordinates`` of every column: xarray opens the root as one Dataset,
    a row per member), and the columns of ``member_row`` (missing: NaN, "" or −1)."""
    member = checksummed(f, "member", np.array(sorted(rows), dtype=np.int64))
    member.make_scale("member")
    member.attrs.update({"long_name": "member index", "description": "the member's index in the sweep (/members)"})
    ordered = [rows[i] for i in sorted(rows)]
    for name in dict.fromkeys(name for row in ordered for name in row):
        values = [row.get(name) for row in ordered]
        present = [v for v in values if v is not None]
        if all(isinstance(v, str) for v in present):
            write_strings(f, name, ["" if v is None else v for v in values])
        elif all(isinstance(v, (bool, np.bool_)) for v in present):
            checksummed(f, name, np.array([bool(v) for v in values], dtype=np.int8))
        elif name.startswith("m_BP"):
            checksummed(f, name, np.array([-1 if v is None else v for v in values], dtype=np.int64))
        else:
            checksummed(f, name, np.array([np.nan if v is None else v for v in values], dtype=float))
        dataset = f[name]
        dataset.dims[0].attach_scale(member)
        units, long_name = TABLE_COLUMNS.get(re.sub(r"\d+$", "", name), ("", f"varied scene key {name}"))
        dataset.attrs.update({"long_name": long_name, "description": f"{long_name}, per member (docs/hdf5.md)"}
                             | ({"units": units} if units else {}))
        if name not in keys:
            dataset.attrs["coordinates"] = " ".join(keys)


def commit_replacement(path) -> None:
    """Swap the complete staging store of a --force sweep in for the old store (the caller then rebuilds the view).
    Cut short at any instant, the next open_store rolls it forward (the old sweep stays readable until the view
    moves)."""
    path = Path(path)
    old, new, retired = store_path(path), staging_path(path), _retired_path(path)
    shutil.rmtree(retired, ignore_errors=True)
    if old.exists():
        old.rename(retired)
    new.rename(old)
    shutil.rmtree(retired, ignore_errors=True)


def _finish_replacement(path: Path) -> None:
    retired = _retired_path(path)
    if not retired.exists():
        return
    if not store_path(path).exists():
        staging_path(path).rename(store_path(path))  # cut between the two renames of commit_replacement
        consolidate(path, store_path(path))
    shutil.rmtree(retired)


# --- reading -----------------------------------------------------------------------------------------------

@contextlib.contextmanager
def _open(path, check: bool = True):
    """The sweep, manifest or member file ``path`` open for reading, its data checked first (``check_data``; not
    with ``check``=False: a member file this process has just written)."""
    check_input(path, SweepFileError)
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise
    except (OSError, RuntimeError):
        raise SweepFileError(path, "not a readable HDF5 file (damaged or not HDF5)") from None
    with f, reading(path, SweepFileError), current(f) as named:
        if check:
            check_data(named, path, SweepFileError, FINITE)
        yield named


def read_sweep(path) -> dict:
    """{'path', 'attrs', 'members': {index: {'overrides', 'scene_hash', 'attrs', 'branches': {name: branch}}}}
    from a sweep file (the view, or a format /1 file). Branches are dicts as read by io.run_file.read_run.
    Raises SweepFileError naming the file and what is missing."""
    path = Path(path)
    with _open(path) as f:
        if plain(f.attrs.get("format")) not in FORMATS:
            raise SweepFileError(path, f"not a balloon-cg sweep file (format {plain(f.attrs.get('format'))!r}, "
                                       f"expected one of {', '.join(FORMATS)})")
        require_attrs(f.attrs, path, ROOT_KEYS, error=SweepFileError)
        if plain(f.attrs.get("format")) == FORMAT and carries_checksums(f):
            require_attrs(f.attrs, path, WRITTEN_ROOT, WRITTEN_ROOT, error=SweepFileError)
            _check_table(f, path)
        if not isinstance(f.get("members"), h5py.Group):
            raise SweepFileError(path, "no /members group")
        out = {"path": str(path), "attrs": {k: plain(v) for k, v in f.attrs.items()}, "members": {}}
        names = [n for n in f["members"] if not n.startswith(_OLD_TMP_PREFIX)]
        for name in sorted(names, key=lambda n: int(n) if n.isdigit() else -1):
            if not name.isdigit():
                raise SweepFileError(path, f"member group /members/{name} is not named by an index")
            out["members"][int(name)] = _read_member(f["members"][name], f"{path}: /members/{name}")
    return out


TABLE_SCALE_ATTRS = ("CLASS", "NAME", "REFERENCE_LIST", "long_name", "description")  # /member, the dimension
TABLE_COLUMN_ATTRS = ("DIMENSION_LIST", "long_name", "description")  # every column along it


def _check_table(f, path) -> None:
    """The root table (``write_table``) of a view written with checksums: the dimension ``member`` and every column
    with the attributes that make it one (its scale, its long name and description); SweepFileError naming the
    dataset and the attribute missing."""
    if not isinstance(f.get("member"), h5py.Dataset):
        raise SweepFileError(path, "no /member dataset (the table's dimension)")
    columns = [n for n, item in f.items() if n != "member" and isinstance(item, h5py.Dataset)]
    keys = {k for n in columns for k in plain(f[n].attrs.get("coordinates", "")).split()}
    for name, wanted in [("member", TABLE_SCALE_ATTRS)] + [(n, _column_attrs(n, keys)) for n in columns]:
        missing = [key for key in wanted if key not in f[name].attrs]
        if missing:
            raise SweepFileError(path, f"/{name} lacks the attribute {missing[0]}")


def _column_attrs(name: str, keys: set) -> tuple:
    """The attributes a table column carries (``write_table``): units where its quantity has some, the varied keys
    as CF coordinates where it is not one of them."""
    units = TABLE_COLUMNS.get(re.sub(r"\d+$", "", name), ("",))[0]
    return TABLE_COLUMN_ATTRS + (("units",) if units else ()) + (("coordinates",) if keys and name not in keys else ())


def read_store(directory) -> dict:
    """The members of a store folder, as read_sweep's 'members'."""
    directory = Path(directory)
    out = {}
    for item in sorted(directory.iterdir()):
        match = _MEMBER.fullmatch(item.name)
        if match is not None:
            with _open(item) as f:
                out[int(match.group(1))] = _read_member(f, str(item))
    return out


def _read_member(group, where: str) -> dict:
    require_attrs(group.attrs, where, MEMBER_KEYS, error=SweepFileError)
    if carries_checksums(group):
        require_attrs(group.attrs, where, WRITTEN_MEMBER, WRITTEN_MEMBER, error=SweepFileError)
    if isinstance(group.get("branches"), h5py.Group) and "primary" not in group["branches"]:
        raise SweepFileError(where, "missing branch primary (every member traces it)")
    attrs = {k: (v.tolist() if isinstance(v, np.ndarray) else plain(v)) for k, v in group.attrs.items()}
    try:
        overrides = json.loads(attrs["overrides"])
    except (TypeError, json.JSONDecodeError):
        raise SweepFileError(where, "attribute overrides is not a JSON object") from None
    if is_tube(group):  # a tube's member: the tube run's branches and onset (io.tube_file.read_tube)
        tube = read_tube(group, where)
        return {"overrides": overrides, "scene_hash": attrs["scene_hash"], "attrs": attrs | tube["attrs"],
                "branches": tube["branches"], "onset": tube["onset"]}
    return {"overrides": overrides, "scene_hash": attrs["scene_hash"], "attrs": attrs,
            **read_branches(group, where, SweepFileError)}


def is_tube(member) -> bool:
    """Whether a member file or group holds a tube's run (io.tube_file.write_tube: its ``shape`` attribute)."""
    return plain(member.attrs.get("shape")) == Shape.TUBE.value


def incomplete_members(path) -> list[int]:
    """Indices of the members of a sweep file whose results are incomplete (from their ``complete``
    attribute; nothing else is read, and the data is not checked: `sweep` asks of the view it has just written,
    where a check read every member's datasets again, ~20 % of a sweep of cheap members)."""
    with _open(path, check=False) as f:
        return sorted(int(name) for name, g in f["members"].items()
                      if not name.startswith(_OLD_TMP_PREFIX) and not bool(g.attrs.get("complete", False)))
