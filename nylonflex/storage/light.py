"""A cube read through h5py alone, for the scan of ``nylonflex query --where`` (issue 49).

Importing xarray and pandas costs about 0.8 CPU-s and ``open_dataset`` about 0.5 s more:
more than a selective scan of a 2 M-design cube reads (about 0.35 s). :func:`open_light`
opens a cube with the checks and the warning of :func:`~nylonflex.storage.reader.open_cube`
(:func:`~nylonflex.storage.reader.checked_attrs`, the registry's
:func:`~nylonflex.variables.validate`) and gives a :class:`LightCube`: what the scan reads
of an xarray Dataset, and :meth:`LightCube.read`, a variable over an index box decoded as
xarray decodes it (a ``_FillValue`` or ``missing_value`` reads as NaN; an incomplete
cube's radii not computed read as NaN, as ``open_cube`` masks them).

A cube the view does not decode opens as None, for xarray's reader: a cube of several
models or cooling sets (string dimensions), or one with a variable packed or typed
through attributes (``scale_factor``, ``add_offset``, ``_Unsigned``, ``dtype``, a time's
``units``), which nylonflex never writes.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..variables import CATEGORIES, is_complete
from .decode import deflate_only, read_box
from .netcdf4 import HIDDEN_ATTRS, STORED_DIMS, read_layout
from .reader import MASKED, _attr, checked_attrs, incomplete_warning, validated

__all__ = ["LightCube", "LightVariable", "open_light"]

#: Attributes by which xarray would decode a variable into other values or another dtype
#: (CF packing, unsigned integers, booleans, calendars): a cube with one opens in xarray.
_CODED = ("scale_factor", "add_offset", "_Unsigned", "dtype", "calendar")


class LightVariable:
    """One variable of a :class:`LightCube`: what the registry's
    :func:`~nylonflex.variables.validate` and the query's scan read of an xarray variable.

    Attributes
    ----------
    name : str
    dims : tuple of str
        Its dimensions as :func:`~nylonflex.storage.reader.open_cube` has them
        (``pressure``, not the file's ``pressure_point``).
    dtype : numpy.dtype
        As xarray decodes it: a whole-number variable with a fill value, or masked on an
        incomplete cube, reads as float.
    attrs : dict
        Its attributes, text as str and one-element arrays as numbers.
    """

    def __init__(self, cube, name, dims, dtype, attrs):
        self._cube, self.name, self.dims, self.dtype, self.attrs = cube, name, dims, dtype, attrs
        #: the values read as NaN (``_FillValue``, ``missing_value``; a NaN fill needs none)
        self.fills = _fills(attrs)

    @property
    def values(self) -> np.ndarray:
        """The whole variable, float64 [SI], decoded (:meth:`LightCube.read`)."""
        return self._cube.read(self.name)


class LightCube:
    """A read-only view of a one-model cube file through h5py (:func:`open_light`).

    Attributes
    ----------
    path : pathlib.Path
    attrs : dict
        The global attributes, as :func:`~nylonflex.storage.reader.cube_attrs` decodes them
        (less the netCDF-4 layout's own, ``_NCProperties``, as xarray leaves it out).
    variables : dict of str to LightVariable
        Every netCDF variable (coordinates included; a dimension without one is none).
    sizes : dict of str to int
        Each dimension's length, by the names ``open_cube`` gives them.
    dims : tuple of str
        The dimensions.
    done : numpy.ndarray of bool or None
        An incomplete cube's radii computed (the rest read as NaN); None when complete.
    plain : bool
        Every variable decodes here (no string dimension, nothing packed or typed through
        attributes): else the cube is for xarray's reader.
    """

    def __init__(self, path, attrs: dict):
        import h5py

        self.path, self.done = Path(path), None
        self.attrs = {k: v for k, v in attrs.items() if k not in HIDDEN_ATTRS}
        self._f = h5py.File(self.path, "r")
        raw = {}  # name: (file dims, h5py dataset, attrs)
        for name, dims in read_layout(self._f)[1].items():
            obj = self._f[name]
            raw[name] = (dims, obj, {k: _attr(obj.attrs[k]) for k in obj.attrs
                                     if k not in HIDDEN_ATTRS})
        coords = {c for _, _, a in raw.values() for c in str(a.get("coordinates", "")).split()}
        # cube format 3: pressure over pressure_point in the file, over pressure here
        rename = {dim: name for name, dim in STORED_DIMS.items()
                  if name in coords and raw.get(name, ((),))[0] == (dim,)}
        self.variables, self.sizes = {}, {}
        for name, (dims, dset, var_attrs) in raw.items():
            dims = tuple(rename.get(d, d) for d in dims)
            self.sizes.update(zip(dims, dset.shape))
            dtype = _as_float(dset.dtype) if _has_fill(var_attrs) else dset.dtype
            self.variables[name] = LightVariable(self, name, dims, dtype, var_attrs)
        self.dims = tuple(self.sizes)
        self._datasets: dict = {}
        self.plain = not any(c in self.sizes for c in CATEGORIES) and \
            not any(_coded(v.attrs) for v in self.variables.values())

    def __contains__(self, name) -> bool:
        return name in self.variables

    def __getitem__(self, name) -> LightVariable:
        return self.variables[name]

    def read(self, name: str, index: dict | None = None, dims=None) -> np.ndarray:
        """Variable ``name`` over an index box, float64 [SI], decoded as xarray decodes it.

        Parameters
        ----------
        name : str
            A variable of the cube.
        index : dict, optional
            ``{dimension: int or slice}``; a dimension not named is read whole, one given
            an int is dropped.
        dims : sequence of str, optional
            The order of the result's axes (default: the variable's own).

        Returns
        -------
        numpy.ndarray
            float64; a fill value, and on an incomplete cube a radius not computed, NaN.
        """
        var, index = self.variables[name], index or {}
        key = tuple(index.get(d, slice(None)) for d in var.dims)
        kept = [d for d, k in zip(var.dims, key) if isinstance(k, slice)]
        dset, deflate = self._dataset(name)
        x = np.asarray(read_box(dset, key, deflate), dtype=np.float64)
        for fill in var.fills:
            x[x == fill] = np.nan
        if self.done is not None and name in MASKED and "radius" in var.dims:
            skip = ~self.done[index.get("radius", slice(None))]
            if "radius" in kept:
                x[(slice(None),) * kept.index("radius") + (skip,)] = np.nan
            elif skip:
                x[...] = np.nan
        return x if dims is None else x.transpose([kept.index(d) for d in dims])

    def _dataset(self, name: str):
        """Variable ``name``'s h5py dataset and whether its chunks are deflate alone
        (:func:`~nylonflex.storage.decode.deflate_only`), looked up once per variable."""
        found = self._datasets.get(name)
        if found is None:
            dset = self._f[name]
            found = self._datasets[name] = (dset, deflate_only(dset))
        return found

    def mask(self, done):
        """Read the radii not ``done`` (bool over ``radius``) as NaN in every variable of
        :data:`~nylonflex.storage.reader.MASKED` over ``radius``, as ``open_cube`` does
        with an incomplete cube (a flag then reads as float)."""
        self.done = np.asarray(done, dtype=bool)
        for var in self.variables.values():
            if var.name in MASKED and "radius" in var.dims:
                var.dtype = _as_float(var.dtype)

    def close(self):
        """Close the file."""
        self._f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def open_light(path, *, quiet: bool = False) -> LightCube | None:
    """Open a cube written by ``nylonflex sweep`` through h5py alone (:class:`LightCube`),
    with the checks of :func:`~nylonflex.storage.reader.open_cube`; None where the cube
    needs xarray's reader (:attr:`LightCube.plain`).

    An incomplete cube opens with ``open_cube``'s warning, its radii not computed read as
    NaN.

    Raises
    ------
    InputError
        The path is missing, not HDF5, not a nylonflex cube, or disagrees with the registry
        (the words of ``open_cube``).
    """
    attrs = checked_attrs(path)
    path = Path(path)
    cube = LightCube(path, attrs)
    if not cube.plain:
        cube.close()
        return None
    validated(cube, path)
    if not is_complete(attrs):
        cube.mask(cube["slab_done"].values.astype(bool))
        if not quiet:
            warnings.warn(incomplete_warning(path, cube.done), stacklevel=2)
    return cube


def _as_float(dtype) -> np.dtype:
    """The dtype xarray gives a variable that can hold NaN: a float as it is, an int8 as
    float32, a wider integer as float64."""
    return np.result_type(dtype, np.float32)


def _has_fill(attrs) -> bool:
    return "_FillValue" in attrs or "missing_value" in attrs


def _fills(attrs) -> list[float]:
    """The numbers a variable's ``_FillValue`` and ``missing_value`` name (NaN left out:
    it reads as NaN already)."""
    out = []
    for key in ("_FillValue", "missing_value"):
        value = attrs.get(key)
        if isinstance(value, (int, float, np.number)) and not np.isnan(value):
            out.append(float(value))
    return out


def _coded(attrs) -> bool:
    """Whether xarray would decode a variable with these attributes by more than its fill
    values (:data:`_CODED`, a time's ``units`` "... since ...")."""
    odd_fill = any(k in attrs and not isinstance(attrs[k], (int, float, np.number))
                   for k in ("_FillValue", "missing_value"))  # several, or text
    return odd_fill or any(k in attrs for k in _CODED) or \
        " since " in str(attrs.get("units", ""))
