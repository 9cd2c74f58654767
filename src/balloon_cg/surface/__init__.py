"""The membrane on the whole sphere (MODEL.md §8): the Cartesian displacement in real spherical harmonics
(``basis``), the scene's energy, residual and Hessian on it (``equilibrium``), the gauge that removes the exact zero
modes (``gauge``), the continuation system (``system``), axisymmetric states and azimuthal modes embedded
(``embedding``), stability per symmetry sector (``stability``) and the measures of a state (``measures``)."""
