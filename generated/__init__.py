"""Kernels emitted by codegen/ (make regenerate). Never edit by hand.

CLASSES maps module name -> (Ogden exponents or None for runtime exponents, the names of its energy terms
beyond the elastic one), ENERGY_CLASSES module name -> (canonical strain-energy formula, its terms); a scene
class without a committed module is generated on demand (model/kernel_cache.py). The layout constants are
those of every class module (codegen/build.py: layout). SURFACE_CLASSES maps class name -> its surface module
(MODEL.md §8, codegen/surface.py), whose row layouts are the SURFACE_ constants.
"""
GENERAL_TERMS = 3
STATE = ('lam2', 'v', 'eta', 'w')
HESSIAN_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))
PERTURBATION = ('R', 'R1', 'Z', 'Z1', 'T', 'T1')
AZIMUTHAL_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5), (1, 1), (1, 2), (1, 3), (1, 4), (1, 5), (2, 2), (2, 3), (2, 4), (2, 5), (3, 3), (3, 4), (3, 5), (4, 4), (4, 5), (5, 5))
FIELD_ROWS = ('Q', 'Q_r', 'Q_z', 'Q_rr', 'Q_rz', 'Q_zz')
CLASSES = {
    'ogden_spom1': ((1.3, 4.0, -2.0), ('pressure',)),
    'ogden_spom1_field': ((1.3, 4.0, -2.0), ('pressure', 'magnetic')),
    'ogden_spom2': ((1.73, 4.0, -2.0), ('pressure',)),
    'ogden_spom2_field': ((1.73, 4.0, -2.0), ('pressure', 'magnetic')),
    'ogden_fpom1': ((1.3, -2.0), ('pressure',)),
    'ogden_fpom1_field': ((1.3, -2.0), ('pressure', 'magnetic')),
    'ogden_fpom2': ((1.73, -2.0), ('pressure',)),
    'ogden_fpom2_field': ((1.73, -2.0), ('pressure', 'magnetic')),
    'ogden_tpom1': ((1.3,), ('pressure',)),
    'ogden_tpom1_field': ((1.3,), ('pressure', 'magnetic')),
    'ogden_tpom2': ((1.98,), ('pressure',)),
    'ogden_tpom2_field': ((1.98,), ('pressure', 'magnetic')),
    'ogden_neo_hookean': ((2.0,), ('pressure',)),
    'ogden_neo_hookean_field': ((2.0,), ('pressure', 'magnetic')),
    'ogden_mooney_rivlin': ((2.0, -2.0), ('pressure',)),
    'ogden_mooney_rivlin_field': ((2.0, -2.0), ('pressure', 'magnetic')),
    'ogden_general_field': (None, ('pressure', 'magnetic')),
}
ENERGY_CLASSES = {
    'rivlin': ('C10 * (I1 - 3) + C01 * (I2 - 3) + C20 * (I1 - 3) ** 2 + C11 * (I1 - 3) * (I2 - 3) + C02 * (I2 - 3) ** 2 + C30 * (I1 - 3) ** 3', ('pressure',)),
    'rivlin_field': ('C10 * (I1 - 3) + C01 * (I2 - 3) + C20 * (I1 - 3) ** 2 + C11 * (I1 - 3) * (I2 - 3) + C02 * (I2 - 3) ** 2 + C30 * (I1 - 3) ** 3', ('pressure', 'magnetic')),
    'gent': ('-(mu * Jm / 2) * log(1 - (I1 - 3) / Jm)', ('pressure',)),
    'gent_field': ('-(mu * Jm / 2) * log(1 - (I1 - 3) / Jm)', ('pressure', 'magnetic')),
    'gent_gent': ('-(mu * Jm / 2) * log(1 - (I1 - 3) / Jm) + C2 * log(I2 / 3)', ('pressure',)),
    'gent_gent_field': ('-(mu * Jm / 2) * log(1 - (I1 - 3) / Jm) + C2 * log(I2 / 3)', ('pressure', 'magnetic')),
    'arruda_boyce': ('mu * (I1 - 3) / 6 - mu * N * log((3 * N - I1) / (3 * N - 3))', ('pressure',)),
    'arruda_boyce_field': ('mu * (I1 - 3) / 6 - mu * N * log((3 * N - I1) / (3 * N - 3))', ('pressure', 'magnetic')),
}
SURFACE_STATE = ('x', 'y', 'z', 'xt', 'yt', 'zt', 'xp', 'yp', 'zp')
SURFACE_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5), (0, 6), (0, 7), (0, 8), (1, 1), (1, 2), (1, 3), (1, 4), (1, 5), (1, 6), (1, 7), (1, 8), (2, 2), (2, 3), (2, 4), (2, 5), (2, 6), (2, 7), (2, 8), (3, 3), (3, 4), (3, 5), (3, 6), (3, 7), (3, 8), (4, 4), (4, 5), (4, 6), (4, 7), (4, 8), (5, 5), (5, 6), (5, 7), (5, 8), (6, 6), (6, 7), (6, 8), (7, 7), (7, 8), (8, 8))
SURFACE_FIELD_ROWS = ('Q', 'Q_x', 'Q_y', 'Q_z', 'Q_xx', 'Q_xy', 'Q_xz', 'Q_yy', 'Q_yz', 'Q_zz')
SURFACE_CLASSES = {
    'ogden_spom1': 'surface_ogden_spom1',
    'ogden_spom1_field': 'surface_ogden_spom1_field',
    'ogden_spom2': 'surface_ogden_spom2',
    'ogden_spom2_field': 'surface_ogden_spom2_field',
    'ogden_fpom1': 'surface_ogden_fpom1',
    'ogden_fpom1_field': 'surface_ogden_fpom1_field',
    'ogden_fpom2': 'surface_ogden_fpom2',
    'ogden_fpom2_field': 'surface_ogden_fpom2_field',
    'ogden_tpom1': 'surface_ogden_tpom1',
    'ogden_tpom1_field': 'surface_ogden_tpom1_field',
    'ogden_tpom2': 'surface_ogden_tpom2',
    'ogden_tpom2_field': 'surface_ogden_tpom2_field',
    'ogden_neo_hookean': 'surface_ogden_neo_hookean',
    'ogden_neo_hookean_field': 'surface_ogden_neo_hookean_field',
    'ogden_mooney_rivlin': 'surface_ogden_mooney_rivlin',
    'ogden_mooney_rivlin_field': 'surface_ogden_mooney_rivlin_field',
    'ogden_general_field': 'surface_ogden_general_field',
    'rivlin': 'surface_rivlin',
    'rivlin_field': 'surface_rivlin_field',
    'gent': 'surface_gent',
    'gent_field': 'surface_gent_field',
    'gent_gent': 'surface_gent_gent',
    'gent_gent_field': 'surface_gent_gent_field',
    'arruda_boyce': 'surface_arruda_boyce',
    'arruda_boyce_field': 'surface_arruda_boyce_field',
}
