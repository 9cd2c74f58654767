"""The label of the point a stored branch leaves from: the one name of that point in the file (``continue`` takes
it, ``inspect`` lists it, legends name the branch by it: ``pear from 3``).

A branch stores its parent's branch point by number (``parent_branch_point``, docs/hdf5.md), numbered as the
analysis numbers them: an axisymmetric branch (a pear branch) among the parent's m = 0 branch points, the free
balloon's after the others (``analysis.picture``: the held numbering does not depend on them); a non-axisymmetric
branch among all the parent's branch points in stored order (``Branch.branch_points``). The two numberings differ
where a branch has m ≥ 1 points before a pear point; the label does not.
"""


def parent_label(run: dict, name: str) -> int | None:
    """The label of the branch point branch ``name`` of a read run (``io.run_file.read_run``) leaves from; None
    for a branch without a parent (the primary branch) or whose parent point is not in the file."""
    return _label_of(run, name, "parent_branch_point")


def rejoin_label(run: dict, name: str) -> int | None:
    """The label of the parent's branch point where pear branch ``name`` rejoins it (``rejoins_branch_point``, in
    the numbering of ``parent_branch_point``); None where it does not rejoin or the point is not in the file."""
    return _label_of(run, name, "rejoins_branch_point")


def _label_of(run: dict, name: str, attribute: str) -> int | None:
    """The label of the parent's branch point numbered by the branch's ``attribute`` (module docstring)."""
    attrs = run["branches"][name]["attrs"]
    parent = attrs.get("parent_branch")
    if not parent or parent not in run["branches"] or attribute not in attrs:
        return None
    points = [s for s in run["branches"][parent]["special_points"] if s["kind"] == "BP"]
    if not non_axisymmetric(attrs):
        points = sorted((s for s in points if s["m"] == 0), key=lambda s: s["block"] == "odd_free")
    n = int(attrs[attribute])
    return int(points[n]["label"]) if 0 <= n < len(points) else None


def non_axisymmetric(attrs) -> bool:
    """Whether a stored branch's attributes are a non-axisymmetric branch's: the sphere's (its basis'
    surface_degree) or one over a meridian (its ``orders``, io/tube_surface_file.py; post/meridian_branches.py)."""
    return "surface_degree" in attrs or "orders" in attrs
