"""Kernels emitted by codegen/ (make regenerate). Never edit by hand.

CLASSES maps module name -> (Ogden exponents or None for runtime exponents, has field).
"""
GENERAL_TERMS = 3
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
