"""The model layer: generated kernels bound to a scene class, the reference meridian, the coil field, sphere and
uniform-tube closed forms, shooting."""
