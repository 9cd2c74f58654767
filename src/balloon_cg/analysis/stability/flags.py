"""The six stability flags (held or free balloon; pressure, volume or gas control) and the eigenvalues reported per
block: shared by the m = 0 blocks' discretisations (axisymmetric.py on Legendre series, banded.py on elements)."""

LOWEST = 3  # eigenvalues reported per block
FLAGS = ("stable_pressure", "stable_volume", "stable_pressure_free", "stable_volume_free", "stable_gas",
         "stable_gas_free")  # Assessment's order
HELD, HELD_VOLUME, FREE, FREE_VOLUME, HELD_GAS, FREE_GAS = range(len(FLAGS))
EVERY_FLAG = tuple(range(len(FLAGS)))
HELD_FLAGS, FREE_FLAGS = (HELD, HELD_VOLUME, HELD_GAS), (FREE, FREE_VOLUME, FREE_GAS)
