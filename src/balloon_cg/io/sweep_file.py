"""Sweep files (HDF5, format "balloon-cg-sweep/1"): one member group per computed scene of a sweep.

Layout::

    /                   attrs: format, scene_name, scene_toml (base scene, normalised), vary (JSON list of
                               [key, values]), mode, members (total count), + provenance (io.hdf5)
    /members/<index>/   attrs: overrides (JSON object, dotted key -> value), scene_hash (sha256 of the member
                               scene's normalised TOML), scene_toml, tolerance, created, package_version,
                               generated_digest, worker_pid, wall_time, branch_point_kinds,
                               branch_point_classifications, branch_point_blocks, branch_point_pressures,
                               complete, incomplete_gaps, incomplete_branches, incomplete_messages (as a run
                               file's root: analysis.verdict)
        branches/<name>/          exactly as a run file's /branches (io.run_file)
        snap_throughs/            as in a run file (full analysis only)

A member is first written under a temporary name in /members and then renamed, so an interrupted sweep leaves
only whole members; the file is flushed after each. Only the parent process of a sweep writes its file.
"""
import json
import secrets
import tomllib
from pathlib import Path

import h5py
import numpy as np

from .hdf5 import check_output, plain, provenance
from .run_file import read_branches, verdict_attrs, write_branches

FORMAT = "balloon-cg-sweep/1"
_TMP_PREFIX = ".tmp-"


class SweepError(ValueError):
    """A sweep that cannot be run as asked (bad --vary spec, conflicting existing file)."""


def root_attrs(scene, axes: list, mode: str, n: int, command: str | None) -> dict:
    """Root attributes of a sweep file: the base scene, the varied keys and values, the mode, provenance."""
    return {"format": FORMAT, "scene_name": scene.name, "scene_toml": scene.to_toml(), "vary": json.dumps(axes),
            "mode": mode, "members": n, **provenance(command)}


def open_sweep(path: Path, attrs: dict, members: list, force: bool) -> tuple[h5py.File, set]:
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


def _check_existing(f: h5py.File, path: Path, attrs: dict, members: list) -> set:
    if f.attrs.get("format") != FORMAT:
        raise SweepError(f"{path}: exists and is not a balloon-cg sweep file (use --force to replace it)")
    for key in ("scene_toml", "vary", "mode", "members"):
        old, new = plain(f.attrs.get(key)), attrs[key]
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
        stored = plain(group[name].attrs.get("scene_hash"))
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


def append_member(f: h5py.File, member, result) -> None:
    """Write one computed member (app.sweep.MemberResult) under a temporary name, rename it to
    /members/<index>, flush."""
    group = f["members"]
    tmp = f"{_TMP_PREFIX}{member.index}-{secrets.token_hex(4)}"
    g = group.create_group(tmp)
    try:
        attrs = provenance()
        del attrs["command"]
        g.attrs.update(attrs | {
            "tolerance": member.scene.solver.tol,
            "overrides": json.dumps(member.overrides),
            "scene_hash": member.scene_hash,
            "scene_toml": member.scene.to_toml(),
            "worker_pid": result.pid,
            "wall_time": result.wall_time,
            "branch_point_pressures": np.array([float(bp.X[-1]) for bp in result.branch_points], dtype=float),
        })
        text = h5py.string_dtype()
        for key, values in (("branch_point_kinds", [bp.kind.value for bp in result.branch_points]),
                            ("branch_point_classifications", [bp.classification.value for bp in result.branch_points]),
                            ("branch_point_blocks", [bp.block.value for bp in result.branch_points])):
            g.attrs.create(key, np.array(values, dtype=object), dtype=text)
        g.attrs.update(verdict_attrs(found=result.incomplete))
        write_branches(g, member.scene, result.branches, result.snaps)
    except BaseException:
        del group[tmp]
        raise
    group.move(tmp, str(member.index))
    f.flush()


def read_sweep(path) -> dict:
    """{'path', 'attrs', 'members': {index: {'overrides', 'scene_hash', 'attrs', 'branches': {name: branch}}}}.

    Branches are dicts as read by io.run_file.read_run.
    """
    path = Path(path)
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise SweepError(f"{path}: not a balloon-cg sweep file")
        out = {"path": str(path), "attrs": {k: plain(v) for k, v in f.attrs.items()}, "members": {}}
        for name in sorted((n for n in f["members"] if not n.startswith(_TMP_PREFIX)), key=int):
            g = f["members"][name]
            attrs = {k: (v.tolist() if isinstance(v, np.ndarray) else plain(v)) for k, v in g.attrs.items()}
            out["members"][int(name)] = {"overrides": json.loads(attrs["overrides"]), "scene_hash": attrs["scene_hash"],
                                         "attrs": attrs, **read_branches(g)}
    return out


def incomplete_members(path) -> list[int]:
    """Indices of the whole members of a sweep file whose results are incomplete (from their ``complete``
    attribute; nothing else is read)."""
    with h5py.File(path, "r") as f:
        return sorted(int(name) for name, g in f["members"].items()
                      if not name.startswith(_TMP_PREFIX) and not bool(g.attrs.get("complete", False)))
