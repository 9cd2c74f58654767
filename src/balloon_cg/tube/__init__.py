"""A tube's branches (docs/tubes.md): the layer after ``analysis`` whose branches live on an interval without poles
(galerkin/interval.py), reading analysis's plain data and numerics. In reading order:

- ``results``: a tube's branch and its located points as plain data, why a trace stopped
- ``stability``: the spectra of the mirror blocks and the unstable directions under pressure, volume and gas control
- ``control``: the loading control's parameter (V, n) on a trace, its folds (LV, LN), the stop at stop_volume
- ``primary``: the primary branch in P from the unstressed tube, its folds and mirror-block branch points
- ``bulge``: the branch switched at an odd branch point (the bulge), through its volume fold
- ``azimuthal``: the m ≥ 1 blocks of a tube's states (cos mφ perturbations), their lowest eigenvalues and unstable
  directions
- ``azimuthal_crossings``: where an m ≥ 1 eigenvalue vanishes along a branch, located
- ``picture``: all of a tube scene's run (``balloon-cg run``)
- ``surface``: the tube over (S, φ), Legendre(S) × Fourier(φ): its energy, residual and exact Jacobian, one point
  switched at a located m ≥ 1 zero, the non-axisymmetric branch traced from it (``[surface] branches``, default
  "none" on a tube)
"""
