"""Branches and what is read off them. In reading order:

- ``results``: Branch, SpecialPoint, stops and their codes (plain data, typed decisions)
- ``resolution``: the resolution policy (error target, degree growth, storage-loss rule)
- ``problem``: a branch's discrete problem as a continuation system, solvers rebuilt from results
- ``wires``: the membrane's gap to the coil wires and the basis map that resolves it
- ``tracer``: adaptive legs of pseudo-arclength continuation; ``assembly``: legs -> one Branch
- ``primary``: the primary branch; ``switching``: the pear branches leaving a branch point
- ``stability``, ``azimuthal``: the second variation (axisymmetric and m ≥ 1 modes)
- ``bifurcation``: detection, location and classification of branch points
- ``second_parameter``: a second parameter by its scene key (M, a material parameter, α1, …);
  ``codim2``: two-parameter continuation of pear pitchforks in it (critical M, critical α1, critical Jm)
- ``picture``: all of it for one scene (``analyse``)
- ``verdict``: is a result complete, and if not, what it lacks (the contract of docs/numerics.md §4a)
"""
