"""Kernels emitted by codegen/ (make regenerate). Never edit by hand.

CLASSES maps module name -> (Ogden exponents or None for runtime exponents, has field); the layout
constants are those of every class module (codegen/build.py: layout).
"""
GENERAL_TERMS = 3
STATE = ('lam2', 'v', 'eta', 'w')
HESSIAN_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))
PERTURBATION = ('R', 'R1', 'Z', 'Z1', 'T', 'T1')
AZIMUTHAL_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5), (1, 1), (1, 2), (1, 3), (1, 4), (1, 5), (2, 2), (2, 3), (2, 4), (2, 5), (3, 3), (3, 4), (3, 5), (4, 4), (4, 5), (5, 5))
FIELD_ROWS = ('Q', 'Q_r', 'Q_z', 'Q_rr', 'Q_rz', 'Q_zz')
CLASSES = {
    'ogden_spom1': ((1.3, 4.0, -2.0), False),
    'ogden_spom1_field': ((1.3, 4.0, -2.0), True),
    'ogden_spom2': ((1.73, 4.0, -2.0), False),
    'ogden_spom2_field': ((1.73, 4.0, -2.0), True),
    'ogden_fpom1': ((1.3, -2.0), False),
    'ogden_fpom1_field': ((1.3, -2.0), True),
    'ogden_fpom2': ((1.73, -2.0), False),
    'ogden_fpom2_field': ((1.73, -2.0), True),
    'ogden_tpom1': ((1.3,), False),
    'ogden_tpom1_field': ((1.3,), True),
    'ogden_tpom2': ((1.98,), False),
    'ogden_tpom2_field': ((1.98,), True),
    'ogden_neo_hookean': ((2.0,), False),
    'ogden_neo_hookean_field': ((2.0,), True),
    'ogden_mooney_rivlin': ((2.0, -2.0), False),
    'ogden_mooney_rivlin_field': ((2.0, -2.0), True),
    'ogden_general_field': (None, True),
}
