"""Files in and out: measurement and scenario readers, output directories, result writers, FMU
packaging. Third-party readers (pyarrow, scipy.io, h5py, asammdf) are imported lazily."""
