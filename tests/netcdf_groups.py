"""Every group of a stored file opened alone with xarray (h5netcdf), as a user opens a run, sweep or curve file's
``profiles``, ``stability`` or ``special_points/state``."""
import h5py


def uncoordinated(path) -> list:
    """(group, dimension) for every dimension of every group of ``path`` (the root included) that the group, opened
    alone with xarray, has no coordinate of."""
    import xarray as xr

    groups = ["/"]
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, item: groups.append(name) if isinstance(item, h5py.Group) else None)
    found = []
    for group in groups:
        with xr.open_dataset(path, engine="h5netcdf", group=group) as ds:
            found += [(group, str(d)) for d in ds.dims if d not in ds.coords]
    return found
