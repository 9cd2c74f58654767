"""HDF5 files (run, sweep, curve): one atomic writer, provenance, readers."""
