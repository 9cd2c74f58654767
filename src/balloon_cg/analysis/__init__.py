"""Branches and what is read off them, one subpackage per question:

- ``results``: Branch, SpecialPoint, stops and their codes (plain data, typed decisions), shared by every room
- ``branches``: how a branch is traced (its discrete problem, the resolution policy, the wires, the adaptive tracer
  and the assembly of its legs, the primary branch, the control parameter, user events, the ends a branch reaches)
- ``stability``: is a state stable (the second variation's axisymmetric and m ≥ 1 blocks, the brute-force m = 1
  check, the crossings followed along a branch)
- ``points``: where the special points are (branch points located on extended systems and classified, the m ≥ 1
  points, stability changes under every control, the free balloon's pitchforks)
- ``switching``: which branches are born there (the pear branches, their mirror images, the pear branch a broken
  symmetry disconnects, the energy landscape near a pitchfork)
- ``critical``: how special points move with a second parameter (pitchfork and fold curves, their meetings)
- ``surface``: the non-axisymmetric branches, traced on the whole surface (the surface layer's discretisation)
- ``picture``: all of it for one scene (``analyse``); ``timing``: seconds per phase
- ``verdict``: is a result complete, and if not, what it lacks (the contract of docs/numerics.md §4a)
"""
