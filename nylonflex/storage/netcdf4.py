"""A netCDF-4 file written through h5py alone, in the layout h5netcdf and netCDF-C write.

The cube needs only fixed-size dimensions, each with its coordinate variable or (cube
format 3's ``pressure_point``) an auxiliary coordinate over it, and variables over them.
h5netcdf writes those with about 1,300 group and dataset lookups for a cube's forty
variables (0.1 s of a 1.3 s sweep, with the GIL held); this module makes the
same HDF5 objects with one call each. What makes an HDF5 file netCDF-4 (NetCDF User Guide,
"NetCDF-4 Format"; h5netcdf 1.x writes the same):

- the root group tracks the creation order of its links and attributes, and so does every
  variable (``track_order``);
- a dimension is the dimension scale of its coordinate variable (``CLASS``/``NAME``), with
  its ``_Netcdf4Dimid`` (0, 1, ... in order of creation); a dimension with no coordinate
  variable is a scale of its own, an empty ``>f4`` dataset of its name whose ``NAME`` says
  "This is a netCDF dimension but not a netCDF variable." and its length;
- every variable has its dimensions' scales attached (``DIMENSION_LIST``) and their ids in
  ``_Netcdf4Coordinates``, and, as netCDF-C writes it, the first one's id in
  ``_Netcdf4Dimid``;
- a fill value is also the attribute ``_FillValue`` (a one-element array), and numeric
  scalar attributes are one-element arrays;
- the root has ``_NCProperties`` (``version=2,...``), written at :meth:`NetCDF4File.close`.

Readers: xarray (h5netcdf or netCDF4 engine), netCDF4-python, netCDF-C tools, h5py
(tests/test_storage.py checks the file against h5netcdf's and reads it with netCDF4).
"""

from __future__ import annotations

import numpy as np

from .. import __version__

__all__ = ["HIDDEN_ATTRS", "NOT_A_VARIABLE", "STORED_DIMS", "NetCDF4File", "read_layout",
           "stored_dims"]

#: Axes a cube stores as an auxiliary coordinate over a dimension of another name (cube
#: format 3): {axis: its dimension in the file}. compliance-checker (cf:1.8, s. 5.1) asks a
#: dimension *named* ``pressure`` for ``standard_name = air_pressure``, which the chamber's
#: gauge pressure is not (CF's air_pressure is the absolute pressure of the air). So the
#: curves ``bend_angle`` and ``tip_force`` lie over ``pressure_point`` in the file, with
#: ``coordinates = "pressure"``: every reader still finds the variable ``pressure`` [Pa],
#: and :func:`nylonflex.open_cube` makes it the dimension again (``ds.sel(pressure=...)``).
STORED_DIMS = {"pressure": "pressure_point"}


def stored_dims(dims) -> tuple:
    """A variable's dimensions as the file names them (:data:`STORED_DIMS`)."""
    return tuple(STORED_DIMS.get(d, d) for d in dims)


#: Attributes the netCDF-4 layout itself uses; a variable's own attributes may not.
HIDDEN_ATTRS = frozenset(("REFERENCE_LIST", "CLASS", "DIMENSION_LIST", "NAME",
                          "_Netcdf4Dimid", "_Netcdf4Coordinates", "_nc3_strict",
                          "_NCProperties"))
#: The start of the ``NAME`` of a dimension scale that is no variable (netCDF-C's words; the
#: dimension's length follows, in 10 characters).
NOT_A_VARIABLE = "This is a netCDF dimension but not a netCDF variable."


def _set_attrs(attrs, values: dict):
    """Write ``values`` into h5py ``attrs`` as netCDF-4 stores them (numeric scalars as
    one-element arrays, strings as variable-length UTF-8)."""
    for key, value in values.items():
        if key in HIDDEN_ATTRS:
            raise ValueError(f"attribute {key!r}: the name is reserved by netCDF-4")
        if np.isscalar(value) and not isinstance(value, (str, bytes)):
            value = np.atleast_1d(value)
        attrs[key] = value


class NetCDF4File:
    """A new netCDF-4 file (``path`` is created or truncated) written with h5py.

    Parameters
    ----------
    path : path
        The file [-]; HDF5's own file locking is off (the caller holds the writer's lock).

    Attributes
    ----------
    h5 : h5py.File
        The open file.
    datasets : dict
        ``{name: h5py.Dataset}`` of every variable, coordinates included, in creation order.
    dims : dict
        ``{name: dimension names}`` of every variable.
    """

    def __init__(self, path):
        import h5py

        self.h5 = h5py.File(path, "w", track_order=True, locking=False)
        self.close_failed = False
        #: the file's descriptor (HDF5's sec2 driver), read once while every id is sound
        self.fd = self.h5.id.get_vfd_handle()
        self.datasets: dict = {}
        self.dims: dict = {}
        self._dimid: dict = {}
        self._scales: dict = {}  # each dimension's scale: its coordinate variable or its own

    def set_attrs(self, values: dict, name: str | None = None):
        """Write attributes of the root group, or of variable ``name``."""
        _set_attrs(self.h5.attrs if name is None else self.datasets[name].attrs, values)

    def coordinate(self, name: str, values, attrs: dict, dtype=None):
        """The dimension ``name`` of ``len(values)`` and its coordinate variable."""
        ds = self.h5.create_dataset(name, data=values, dtype=dtype, track_order=True)
        dimid = len(self._dimid)
        ds.attrs["_Netcdf4Dimid"] = np.int32(dimid)
        ds.make_scale(name)
        ds.attrs["_Netcdf4Coordinates"] = np.array([dimid], np.int32)
        _set_attrs(ds.attrs, attrs)
        self._dimid[name] = dimid
        self._scales[name] = ds
        self.datasets[name], self.dims[name] = ds, (name,)
        return ds

    def dimension(self, name: str, size: int):
        """The dimension ``name`` of ``size``, with no coordinate variable: netCDF-4's scale
        of its own, as netCDF-C and h5netcdf write it (``pressure_point``, over which the
        auxiliary coordinate ``pressure`` lies)."""
        ds = self.h5.create_dataset(name, (size,), ">f4", track_order=True)
        dimid = len(self._dimid)
        ds.attrs["_Netcdf4Dimid"] = np.int32(dimid)
        ds.make_scale(NOT_A_VARIABLE + f"{size:10}")
        self._dimid[name] = dimid
        self._scales[name] = ds
        return ds

    def variable(self, name: str, dims: tuple, dtype, attrs: dict, *, fillvalue=None,
                 chunks=None, data=None, **filters):
        """A variable over the dimensions ``dims`` (made by :meth:`coordinate` or
        :meth:`dimension`), holding ``data`` if given.

        ``fillvalue`` None leaves HDF5's default (zero) and writes no ``_FillValue``;
        ``filters`` are h5py's dataset options (compression, compression_opts, shuffle).
        """
        shape = tuple(self._scales[d].shape[0] for d in dims)
        ds = self.h5.create_dataset(name, shape, dtype, data=data, chunks=chunks,
                                    fillvalue=fillvalue, track_order=True, **filters)
        for axis, dim in enumerate(dims):
            ds.dims[axis].attach_scale(self._scales[dim])
        if dims:
            ids = np.array([self._dimid[d] for d in dims], np.int32)
            ds.attrs["_Netcdf4Coordinates"] = ids
            ds.attrs["_Netcdf4Dimid"] = ids[0]
        if fillvalue is not None:
            ds.attrs["_FillValue"] = np.atleast_1d(ds.dtype.type(fillvalue))
        _set_attrs(ds.attrs, attrs)
        self.datasets[name], self.dims[name] = ds, tuple(dims)
        return ds

    def close(self):
        """Write ``_NCProperties`` and close the file.

        Everything is flushed first, while a failure (a full disk) leaves every HDF5 id
        intact; a close that still fails partway sets :attr:`close_failed` and keeps the
        file's Python objects alive for good (:data:`_PARKED`): HDF5 has freed some of
        their ids already, and closing or freeing them again crashed the process.
        """
        import h5py

        text = (f"version=2,nylonflex={__version__},hdf5={h5py.version.hdf5_version},"
                f"h5py={h5py.__version__}")
        self.h5.attrs["_NCProperties"] = np.array(
            text, dtype=h5py.string_dtype(encoding="ascii", length=len(text)))
        self.h5.flush()
        try:
            self.h5.close()
        except BaseException:
            self.close_failed = True
            _PARKED.append(self)
            raise


def read_layout(h5) -> tuple[dict, dict]:
    """The dimensions of a netCDF-4 file open in h5py, and each variable's, as h5netcdf
    reads them: ``({dimension: size}, {variable: (dimension, ...)})`` in file order
    (coordinate variables included, a dimension's own scale not).

    From the ids netCDF-4 stores (``_Netcdf4Dimid`` of each scale, ``_Netcdf4Coordinates``
    of each variable): an attribute read a dataset, where h5netcdf follows every dimension
    scale's references (40 ms of ``info`` on a sweep's cube). A variable without the ids (a
    file another writer made) is read through its attached scales.
    """
    import h5py

    sizes, dimid, found = {}, {}, {}
    for name, obj in h5.items():
        if not isinstance(obj, h5py.Dataset):
            continue
        attrs = obj.attrs
        if attrs.get("CLASS") == b"DIMENSION_SCALE":
            sizes[name] = int(obj.shape[0])
            if "_Netcdf4Dimid" in attrs:
                dimid[int(np.asarray(attrs["_Netcdf4Dimid"]).reshape(-1)[0])] = name
            if str(_text(attrs.get("NAME", b""))).startswith(NOT_A_VARIABLE):
                continue  # a dimension, not a variable
        ids = attrs.get("_Netcdf4Coordinates")
        found[name] = ids if ids is not None else obj
    dims = {}
    for name, ids in found.items():
        if isinstance(ids, h5py.Dataset) or any(int(i) not in dimid for i in ids):
            scales = h5[name].dims
            dims[name] = tuple(scales[k].values()[0].name.lstrip("/")
                               for k in range(len(scales)))
        else:
            dims[name] = tuple(dimid[int(i)] for i in ids)
    return sizes, dims


def _text(value):
    return value.decode() if isinstance(value, bytes) else value


#: Files whose close failed partway (a full disk): kept, never freed (see
#: :meth:`NetCDF4File.close`).
_PARKED: list = []
