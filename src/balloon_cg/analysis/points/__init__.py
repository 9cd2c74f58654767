"""Where the special points are: branch points detected, located on extended systems and classified, the m ≥ 1 points, stability changes under every control, the free balloon's pitchforks."""
