"""The model layer: generated kernels bound to a scene class, the coil field, sphere closed forms, shooting."""
