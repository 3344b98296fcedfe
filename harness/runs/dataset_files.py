"""Writing and reading result Datasets.

``.zarr`` folders are written with zarr, ``.csv`` files as a table of the data (without
the attributes); any other name as NetCDF, through h5netcdf
(NetCDF-4) when h5py is installed, else through scipy (NetCDF-3, where 64-bit
integers are stored as 32-bit: counts in this harness stay far below 2**31).
Files are written to a temporary name and renamed, so a reader never sees half a file.
"""
from __future__ import annotations

import importlib.util
import os
import shutil
import warnings
from pathlib import Path

import xarray as xr


def netcdf_engine() -> str:
    return "h5netcdf" if importlib.util.find_spec("h5py") else "scipy"


def save_dataset(ds: xr.Dataset, path: str | os.PathLike) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    staging = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    if path.suffix == ".zarr":
        shutil.rmtree(staging, ignore_errors=True)
        with warnings.catch_warnings():
            # Fixed-width text (the regime names) has no Zarr v3 data-type spec yet; xarray
            # and zarr-python read it back fine.
            warnings.filterwarnings("ignore", message=".*does not have a Zarr V3 specification")
            ds.to_zarr(staging, mode="w", consolidated=False)
        if path.exists():
            shutil.rmtree(path)
        os.replace(staging, path)
    elif path.suffix == ".csv":
        # The data as a table (one row per time or grid point); the settings, which are
        # the Dataset's attributes, travel in .nc and .zarr only.
        ds.to_dataframe().to_csv(staging)
        os.replace(staging, path)
    else:
        ds.to_netcdf(staging, engine=netcdf_engine())
        os.replace(staging, path)
    return path


def load_dataset(path: str | os.PathLike) -> xr.Dataset:
    path = Path(path)
    if path.suffix == ".zarr":
        return xr.open_zarr(path, consolidated=False).load()
    return xr.load_dataset(path, engine=netcdf_engine())
