"""The cube writer's own chunk filters against HDF5's (storage by round trip)."""

from pathlib import Path

import h5py
import numpy as np
import pytest

from nylonflex.storage.codec import _shuffle_deflate


@pytest.mark.parametrize("dtype", [np.float64, np.int8])
def test_direct_chunks_read_back_through_hdf5_filters(tmp_path, dtype):
    rng = np.random.default_rng(3)
    data = (rng.normal(size=(5, 7, 11)) * 100).astype(dtype)
    chunks = (2, 4, 6)  # partial chunks on every axis
    path = tmp_path / "x.h5"
    with h5py.File(path, "w") as f:
        ds = f.create_dataset("v", data.shape, dtype, chunks=chunks, compression="gzip",
                              compression_opts=1, shuffle=True)
        for i in range(0, 5, 2):
            for j in range(0, 7, 4):
                for k in range(0, 11, 6):
                    block = data[i:i + 2, j:j + 4, k:k + 6]
                    ds.id.write_direct_chunk((i, j, k), _shuffle_deflate(block, chunks))
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["v"][...], data)
        # the dataset declares the filters every reader applies to our chunks
        assert f["v"].compression == "gzip" and f["v"].shuffle


@pytest.mark.parametrize("codec", ["zstd", "lz4", "none"])
def test_every_codec_stores_the_same_cube(tmp_path, codec):
    # the same design space with gzip (the default) and another codec: identical values,
    # and the file says which codec it holds
    from pathlib import Path

    import yaml

    import nylonflex as nf
    from nylonflex.config import parse_config

    raw = yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())
    ref = nf.run_sweep(parse_config({**raw, "compression": "gzip"}), tmp_path / "gzip.h5")
    other = nf.run_sweep(parse_config({**raw, "compression": codec}), tmp_path / f"{codec}.h5")
    for name in ref.data_vars:
        np.testing.assert_array_equal(other[name].values, ref[name].values, err_msg=name)
    assert other.attrs["compression"] == codec and ref.attrs["compression"] == "gzip"
    import h5py

    with h5py.File(tmp_path / f"{codec}.h5") as f:  # h5py reads it (hdf5plugin loaded)
        np.testing.assert_array_equal(f["tip_force_max"][...], ref["tip_force_max"].values)


@pytest.mark.parametrize("codec", ["gzip", "zstd", "none", "lz4"])
def test_a_slab_encoded_away_from_the_file_is_what_the_file_encodes(tmp_path, codec):
    # a Dask worker encodes the slab it computed with the cube's encoder, pickled and sent
    # to it (engine/cluster.py): the same keys and the same bytes as the cube file's own
    # encoding with its thread pool, for slabs of whole chunks (the last one short) and
    # one that is not (its arrays stay plain); lz4 (HDF5 compresses) sends none
    import pickle

    import yaml

    from nylonflex.config import parse_config
    from nylonflex.engine.grid import compute_slab, coords, cube_variables
    from nylonflex.engine.provenance import provenance
    from nylonflex.storage.codec import EncodedSlab
    from nylonflex.storage.cube import CubeFile

    raw = yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())
    cfg = parse_config({**raw, "compression": codec})
    n = cfg.shape[0]
    slabs = [(i, min(i + 2, n)) for i in range(0, n, 2)] + [(1, 2)]
    assert n % 2 and len(slabs) >= 3  # a last chunk shorter than the rest
    cube = CubeFile(tmp_path / "c.h5", coords(cfg), provenance(cfg), 2, codec,
                    cube_variables(cfg), cfg.models, cfg.cooling_names)
    try:
        if codec == "lz4":
            assert cube.remote_encoder() is None
            return
        encoder = pickle.loads(pickle.dumps(cube.remote_encoder()))
        for i0, i1 in slabs:
            arrays = compute_slab(cfg, i0, i1, parallel=False)
            here, there = cube.encode(i0, arrays), encoder(i0, arrays)
            assert isinstance(there, EncodedSlab) and there.arrays.keys() == here.keys()
            assert any(key.endswith(":bytes") for key in here) == (i0 % 2 == 0)
            for key, value in here.items():
                assert there.arrays[key].dtype == value.dtype, key
                np.testing.assert_array_equal(there.arrays[key], value, err_msg=key)
    finally:
        cube.close()


@pytest.mark.parametrize("dtype", [np.float64, np.int8, np.float32])
@pytest.mark.parametrize("codec", ["gzip", "none"])
def test_a_chunk_decodes_to_what_was_encoded(dtype, codec):
    # decode_chunk is encode_chunk's inverse (gzip: deflate of shuffled bytes; a partial
    # block comes back padded with zeros to the chunk's shape), into a new array or a
    # given one
    from nylonflex.storage.codec import CODECS, encode_chunk
    from nylonflex.storage.decode import decode_chunk

    rng = np.random.default_rng(3)
    block = (rng.normal(size=(2, 5, 7)) * 100).astype(dtype)
    chunks = (3, 5, 7)
    raw = encode_chunk(block, chunks, CODECS[codec])
    want = np.zeros(chunks, dtype=dtype)
    want[:2] = block
    if codec == "gzip":
        got = decode_chunk(bytes(raw), chunks, dtype, shuffle=True)
        np.testing.assert_array_equal(got, want)
        into = np.full(chunks, 7, dtype=dtype)
        assert decode_chunk(bytes(raw), chunks, dtype, True, out=into) is into
        np.testing.assert_array_equal(into, want)
    else:
        np.testing.assert_array_equal(np.frombuffer(bytes(raw), dtype).reshape(chunks), want)


def test_a_box_read_by_the_chunks_is_h5pys_read(tmp_path):
    # query --where's reads (storage/light.py) inflate the default codec's chunks
    # themselves: the same values as h5py's read for boxes of ints and slices that start
    # and end inside chunks, over chunks cut short by the axis' end; and another codec, or
    # an incomplete cube's unwritten chunks, are h5py's own read
    import nylonflex as nf
    from nylonflex.config import parse_config
    from nylonflex.storage.decode import read_box

    raw = _reference_raw()
    raw["grid"]["radius"] = {"start": 5, "stop": 25, "num": 13, "units": "mm"}
    for codec in ("gzip", "zstd"):
        path = tmp_path / f"{codec}.h5"
        nf.run_sweep(parse_config({**raw, "compression": codec}), path).close()
        with h5py.File(path, "r") as f:
            for name in ("tip_force_max", "bend_angle", "limit", "radius"):
                d = f[name]
                keys = [tuple(slice(None) for _ in d.shape),
                        (slice(1, 12), *(slice(None) for _ in d.shape[1:])),
                        (3, *(slice(1, None) for _ in d.shape[1:])),
                        (slice(2, 9), *(0 for _ in d.shape[1:]))]
                for key in keys:
                    np.testing.assert_array_equal(read_box(d, key), d[key],
                                                  err_msg=f"{codec} {name} {key}")
    # an incomplete cube: the radii not computed are chunks never written
    with h5py.File(tmp_path / "gzip.h5", "r") as f:
        whole = f["tip_force_max"][...]
    part = tmp_path / "part.h5"
    import shutil

    shutil.copy(tmp_path / "gzip.h5", part)
    with h5py.File(part, "r+") as f:
        f.create_dataset("sparse", shape=whole.shape, dtype="f8", chunks=(2,) + whole.shape[1:],
                         compression="gzip", shuffle=True, fillvalue=np.nan)
        f["sparse"][:4] = whole[:4]
    with h5py.File(part, "r") as f:
        d = f["sparse"]
        got = read_box(d, tuple(slice(None) for _ in d.shape))
        np.testing.assert_array_equal(got[:4], whole[:4])
        assert np.isnan(got[4:]).all()
    # a damaged chunk is HDF5's error, as h5py's read gives it (the CLI names the variable)
    with h5py.File(part, "r") as f:
        info = f["tip_force_max"].id.get_chunk_info(0)
    with open(part, "r+b") as fh:
        fh.seek(info.byte_offset + 8)
        fh.write(b"\xff" * min(64, info.size - 8))
    with h5py.File(part, "r") as f, pytest.raises(OSError):
        read_box(f["tip_force_max"], tuple(slice(None) for _ in f["tip_force_max"].shape))


# ------------------------------------------------------------------ the netCDF-4 layout
def _h5netcdf_cube(path, cfg, codec):
    """The cube's skeleton as h5netcdf writes it (what CubeFile did before issue 17's
    direct writer): the reference layout the h5py writer must reproduce."""
    import h5netcdf

    from nylonflex.engine.grid import coords, cube_variables, plan_slabs
    from nylonflex.storage.codec import CODECS, chunk_shape
    from nylonflex.variables import COORDS, MODEL, slab_done_attrs

    _, chunk = plan_slabs(cfg)
    # cube format 3: the pressure curves over the dimension pressure_point, which has no
    # coordinate variable; pressure is their auxiliary coordinate (CF s. 5)
    disk = {"pressure": "pressure_point"}
    with h5netcdf.File(path, "w") as f:
        sizes = {disk.get(name, name): len(v) for name, v in coords(cfg).items()}
        for name, values in coords(cfg).items():
            f.dimensions[disk.get(name, name)] = len(values)
            f.create_variable(name, (disk.get(name, name),), "f8", data=values).attrs.update(
                COORDS[name].attrs())
        if len(cfg.models) > 1:
            sizes["model"] = f.dimensions["model"] = len(cfg.models)
        if len(cfg.models) > 1:
            f.create_variable("model", ("model",), h5py.string_dtype(),
                              data=np.array(cfg.models, dtype=object)).attrs.update(
                MODEL.attrs())
        for var, dims in cube_variables(cfg).values():
            fill = None if var.dtype == "int8" else np.nan
            dims = tuple(disk.get(d, d) for d in dims)
            aux = {"coordinates": "pressure"} if "pressure_point" in dims else {}
            f.create_variable(var.name, dims, var.dtype, fillvalue=fill,
                              chunks=chunk_shape(dims, sizes, chunk),
                              **CODECS[codec].filters).attrs.update({**var.attrs(), **aux})
        f.create_variable("slab_done", ("radius",), "i1", fillvalue=None).attrs.update(
            slab_done_attrs())
        f.attrs.update({"name": cfg.name, "compression": codec})


def _layout(path) -> dict:
    """Everything of an HDF5 file that makes it netCDF-4 and this cube: every object's
    type, shape, chunks, filters, fill value, creation-order flags and attributes (scale
    references as names; the order of attributes and of reference lists aside)."""
    def attr(ds, key):
        value = ds.attrs[key]
        if key == "DIMENSION_LIST":
            return [ds.file[row[0]].name for row in value]
        if key == "REFERENCE_LIST":
            return sorted((ds.file[r[0]].name, int(r[1])) for r in value)
        a = ds.attrs.get_id(key)
        return (str(a.dtype), a.shape, value if isinstance(value, (str, bytes))
                else repr(np.asarray(value).tolist()))  # repr: NaN equals NaN

    out = {}
    with h5py.File(path, "r") as f:
        gcpl = f["/"].id.get_create_plist()
        out["/"] = (gcpl.get_link_creation_order(), gcpl.get_attr_creation_order(),
                    sorted(k for k in f.attrs if k != "_NCProperties"))
        out["/names"] = list(f)  # links in creation order
        for name, ds in f.items():
            dcpl = ds.id.get_create_plist()
            filters = [dcpl.get_filter(i)[:3] for i in range(dcpl.get_nfilters())]
            fill = np.zeros((), ds.dtype) if ds.dtype.kind != "O" else None
            if fill is not None:
                dcpl.get_fill_value(fill)
            out[name] = {"dtype": str(ds.dtype), "shape": ds.shape, "chunks": ds.chunks,
                         "filters": filters, "layout": dcpl.get_layout(),
                         "fill": None if fill is None else repr(fill.tolist()),
                         "attr_order": dcpl.get_attr_creation_order(),
                         "attrs": {k: attr(ds, k) for k in sorted(ds.attrs)}}
    return out


@pytest.mark.parametrize("case", ["plain", "models_and_supply", "uncertainty"])
@pytest.mark.parametrize("codec", ["zstd", "gzip"])
def test_the_cube_has_h5netcdfs_netcdf4_layout(tmp_path, case, codec):
    # CubeFile writes the netCDF-4 layout with h5py alone (issue 17: h5netcdf's lookups
    # cost 0.1 s a sweep): object for object it is the file h5netcdf writes
    import xarray as xr
    import yaml
    from pathlib import Path

    from nylonflex.config import parse_config
    from nylonflex.engine.grid import coords, cube_variables, plan_slabs
    from nylonflex.storage.cube import CubeFile

    raw = yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())
    raw["compression"] = codec
    if case == "models_and_supply":
        raw.update(model=["paper", "coupled_muscle", "cauchy_moment"],
                   supply={"voltage": 12})
    elif case == "uncertainty":
        raw["uncertainty"] = {"samples": 16, "seed": 1,
                              "parameters": {"silicone.mu": {"rel_sd": 0.1}}}
    cfg = parse_config(raw)
    _, chunk = plan_slabs(cfg)
    ours, theirs = tmp_path / "ours.h5", tmp_path / "theirs.h5"
    CubeFile(ours, coords(cfg), {"name": cfg.name}, chunk, codec, cube_variables(cfg),
             cfg.models).close()
    _h5netcdf_cube(theirs, cfg, codec)
    assert _layout(ours) == _layout(theirs)
    with h5py.File(ours, "r") as f:
        assert f.attrs["_NCProperties"].decode().startswith("version=2,nylonflex=")
    # and netCDF-C and xarray read the same dimensions, variables and attributes
    netCDF4 = pytest.importorskip("netCDF4")
    with netCDF4.Dataset(ours) as a, netCDF4.Dataset(theirs) as b:
        assert {k: len(v) for k, v in a.dimensions.items()} == \
            {k: len(v) for k, v in b.dimensions.items()}
        for name, var in b.variables.items():
            assert a.variables[name].dimensions == var.dimensions, name
            assert a.variables[name].ncattrs() == var.ncattrs(), name
    with xr.open_dataset(ours, engine="h5netcdf") as a, \
            xr.open_dataset(theirs, engine="h5netcdf") as b:
        xr.testing.assert_identical(a, b)


@pytest.mark.parametrize("itemsize", [2, 4, 8])
@pytest.mark.parametrize("n", [0, 1, 7, 8, 9, 64, 1000, 100_000])
def test_shuffle_is_hdf5s_byte_transpose(itemsize, n):
    # the compiled shuffle (the word loop for 8-byte elements, the byte loop otherwise)
    # against NumPy's transpose, including buffers that are not 8-byte aligned
    from nylonflex.kernels.bytes import shuffle_bytes

    rng = np.random.default_rng(n + itemsize)
    for offset in (0, 1):
        buf = rng.integers(0, 256, n * itemsize + offset, dtype=np.uint8)
        src = buf[offset:].reshape(n, itemsize)
        out = np.empty(itemsize * n + offset, np.uint8)[offset:].reshape(itemsize, n)
        shuffle_bytes(src, out)
        np.testing.assert_array_equal(out, src.T)


@pytest.mark.parametrize("codec", ["gzip", "zstd"])
@pytest.mark.parametrize("dtype", ["f8", "f4", "i2", "i1"])
def test_numpy_and_compiled_shuffles_store_the_same_bytes(codec, dtype):
    # a small cube's chunks are shuffled by NumPy (nothing to compile), a large one's by the
    # compiled loops: the stored chunk must be the same either way, padded chunks included
    from nylonflex.storage.codec import CODECS, encode_chunk

    if CODECS[codec].plugin:
        pytest.importorskip("zstandard")
    rng = np.random.default_rng(3)
    block = (rng.random((3, 5, 7)) * 100).astype(dtype)
    for chunks in ((3, 5, 7), (4, 5, 8)):
        assert encode_chunk(block, chunks, CODECS[codec], True) == \
            encode_chunk(block, chunks, CODECS[codec], False)


def test_a_small_cube_compiles_no_shuffle(tmp_path):
    # the README's main job is far below COMPILED_SHUFFLE_BYTES: its writer must not ask
    # for the compiled shuffle (a first compile of 0.4-0.6 s), a large cube's must
    from nylonflex.storage.codec import COMPILED_SHUFFLE_BYTES
    from nylonflex.storage.cube import CubeFile

    coords = {"radius": np.linspace(5e-3, 10e-3, 4), "wall_thickness": [2e-3],
              "length": [0.09], "coil_index": [1.3], "wrap_angle": [0.1],
              "stroke": [0.0, 0.1], "pressure": [0.0, 2e4]}
    cube = CubeFile(tmp_path / "c.h5", coords, {}, radius_chunk=2)
    try:
        assert not cube.encoder.compiled
    finally:
        cube.close()
    big = dict(coords, radius=np.linspace(5e-3, 10e-3, COMPILED_SHUFFLE_BYTES // 8 // 20))
    cube = CubeFile(tmp_path / "big.h5", big, {}, radius_chunk=1024)
    try:
        assert cube.encoder.compiled
    finally:
        cube.close()


# ------------------------------------------------------ readers without a plugin (issue 24)
def _reference_raw():
    from pathlib import Path

    import yaml

    return yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())


def test_the_default_codec_is_plain_deflate_with_shuffle(tmp_path):
    # every HDF5 and netCDF-4 reader decodes deflate (filter 1) after shuffle (filter 2)
    # with no plugin: the dataset declares exactly those two, and zlib itself inflates a
    # stored chunk (RFC 1950 streams, as HDF5's deflate filter reads them)
    import zlib

    import nylonflex as nf
    from nylonflex.config import parse_config

    cfg = parse_config(_reference_raw())
    assert cfg.compression == "gzip"
    path = tmp_path / "cube.h5"
    nf.run_sweep(cfg, path).close()
    with h5py.File(path, "r") as f:
        dset = f["tip_force_max"]
        dcpl = dset.id.get_create_plist()
        ids = [dcpl.get_filter(i)[0] for i in range(dcpl.get_nfilters())]
        assert ids == [h5py.h5z.FILTER_SHUFFLE, h5py.h5z.FILTER_DEFLATE]
        _, raw = dset.id.read_direct_chunk((0,) * dset.ndim)
        n = int(np.prod(dset.chunks))
        unshuffled = np.frombuffer(zlib.decompress(raw), np.uint8).reshape(8, n).T.copy()
        first = unshuffled.view(np.float64).reshape(dset.chunks)
        np.testing.assert_array_equal(first, dset[tuple(slice(0, c) for c in dset.chunks)])


def test_a_zstd_cube_without_the_plugin_says_what_to_install(tmp_path, monkeypatch):
    import nylonflex as nf
    from nylonflex.config import parse_config
    from nylonflex.storage import codec as codec_module
    from nylonflex.storage.codec import MissingPlugin

    path = tmp_path / "zstd.h5"
    nf.run_sweep(parse_config({**_reference_raw(), "compression": "zstd"}), path).close()
    # as in an install without the zstd extra and without HDF5_PLUGIN_PATH
    monkeypatch.setattr(codec_module, "load_filter_plugins", lambda: False)
    monkeypatch.setattr(h5py.h5z, "filter_avail", lambda filter_id: False)
    with pytest.raises(MissingPlugin, match=r"pip install 'nylonflex\[zstd\]'.*HDF5_PLUGIN_PATH"):
        nf.open_cube(path)
    from nylonflex.cli import main

    assert main(["info", str(path)]) == 2  # the environment (issue 46): one line, no traceback


@pytest.mark.parametrize("codec", ["gzip", "zstd", "lz4", "none"])
def test_an_opened_cube_of_every_codec_saves_again_with_either_engine(tmp_path, codec):
    # open_cube's encoding is one xarray's engines can write (a zstd or lz4 filter would
    # be refused: 'Compression filter "zstd" is unavailable' / 'Unsupported value for
    # compression kwarg'); the subset saved reads back identical
    import xarray as xr

    import nylonflex as nf
    from nylonflex.config import parse_config

    path = tmp_path / f"{codec}.h5"
    nf.run_sweep(parse_config({**_reference_raw(), "compression": codec}), path).close()
    engines = ["h5netcdf"]
    try:
        import netCDF4  # noqa: F401

        engines.append("netcdf4")
    except ImportError:
        pass
    with nf.open_cube(path) as ds:
        part = ds.isel(radius=slice(0, 3))
        for engine in engines:
            out = tmp_path / f"{codec}_{engine}.nc"
            part.to_netcdf(out, engine=engine)
            with xr.open_dataset(out, engine=engine) as back:
                xr.testing.assert_identical(back.load(), part.load())
            with h5py.File(out, "r") as f:  # what was written needs no plugin either
                assert f["tip_force_max"].compression in ("gzip", None), engine


def test_the_pressure_curves_lie_over_pressure_point_and_open_over_pressure(tmp_path):
    # cube format 3 (issue 24): compliance-checker asks a dimension *named* pressure for
    # standard_name air_pressure, which the chamber's gauge pressure is not, so the file
    # stores bend_angle and tip_force over pressure_point with pressure their auxiliary
    # coordinate; every reader still finds pressure [Pa], and open_cube gives the
    # registry's dimensions back, for this format and the earlier ones alike
    from pathlib import Path

    import xarray as xr

    import nylonflex as nf
    from nylonflex.config import parse_config

    path = tmp_path / "cube.h5"
    nf.run_sweep(parse_config(_reference_raw()), path).close()
    with xr.open_dataset(path) as raw:  # xarray's default engine, no nylonflex
        assert raw["bend_angle"].dims[-1] == "pressure_point"
        assert raw["pressure"].dims == ("pressure_point",)
        assert "pressure" in raw["tip_force"].coords and raw["pressure"].attrs["units"] == "Pa"
        by_pressure = raw.set_xindex("pressure").sel(pressure=raw["pressure"].values[2])
        with nf.open_cube(path) as ds:
            assert ds["bend_angle"].dims == ("radius", "wall_thickness", "length", "pressure")
            assert "pressure_point" not in ds.dims
            xr.testing.assert_identical(ds.swap_dims(pressure="pressure_point").load(),
                                        raw.load())
            np.testing.assert_array_equal(ds.sel(pressure=ds["pressure"].values[2])
                                          ["tip_force"].values,
                                          by_pressure["tip_force"].values)
    with h5py.File(path, "r") as f:
        assert f["bend_angle"].attrs["coordinates"] == "pressure"
        assert f["bend_angle"].dims[3][0].name == "/pressure_point"
        assert f["pressure_point"].attrs["NAME"].startswith(b"This is a netCDF dimension")
    from nylonflex.storage import cube_summary

    lines = cube_summary(path)  # info: the dimensions open_cube gives, and the file's
    assert any(l.split()[0] == "bend_angle" and "length, pressure)" in l for l in lines)
    assert any(l.split()[0] == "pressure" and "over the dimension pressure_point" in l
               for l in lines)
    old = Path(__file__).parent / "data" / "reference_cube.h5"  # format 1, over pressure
    with nf.open_cube(old) as ds:
        assert ds["bend_angle"].dims[-1] == "pressure" and ds.sel(pressure=0.0).sizes


# ------------------------------------------------------------------ info's flag counts
@pytest.mark.parametrize("dtype", [np.int8, np.uint8])
@pytest.mark.parametrize("piece", [1, 7, 1 << 18])
def test_the_flag_histogram_counts_each_byte_as_a_loop_does(dtype, piece):
    from nylonflex.storage.describe import flag_histogram

    rng = np.random.default_rng(27)
    flags = rng.integers(0, 256, size=(13, 17, 5)).astype(np.uint8).view(dtype)
    slow = np.zeros(256, dtype=np.int64)
    for value in flags.reshape(-1):  # the obviously right reference
        slow[int(np.uint8(value.view(np.uint8)))] += 1
    np.testing.assert_array_equal(flag_histogram(flags, piece=piece), slow)
    with pytest.raises(ValueError, match="one-byte"):
        flag_histogram(flags.astype(np.int16))


def _flag_counts_through_xarray(path):
    """The flagged line's numbers as ``info`` counted them before issue 27: the whole
    validity variable through open_cube (masked radii read as NaN), as int64."""
    import warnings

    from nylonflex.storage import open_cube

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = open_cube(path)
    v = ds["validity"].values
    v = v[~np.isnan(v)].astype(np.int64) if v.dtype.kind == "f" else v.astype(np.int64)
    bits = [int(x) for x in np.atleast_1d(ds["validity"].attrs["flag_masks"])]
    counts = [int(np.sum((v & bit) > 0)) for bit in bits]
    ds.close()
    return int(np.sum(v > 0)), v.size, counts


@pytest.mark.parametrize("incomplete", [False, True])
def test_info_counts_the_flags_xarray_counts(tmp_path, incomplete):
    from pathlib import Path

    import yaml

    import nylonflex as nf
    from nylonflex.config import parse_config
    from nylonflex.storage import cube_summary

    raw = yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())
    path = tmp_path / "cube.h5"
    nf.run_sweep(parse_config(raw), path).close()
    with h5py.File(path, "r+") as f:
        # flags of every kind, negative bytes too, so that each bit has designs to count
        v = f["validity"]
        rng = np.random.default_rng(5)
        v[...] = rng.integers(-128, 128, size=v.shape).astype(np.int8)
        if incomplete:  # a stopped sweep: the second radius not done
            done = f["slab_done"][...]
            done[1] = 0
            f["slab_done"][...] = done
            f.attrs["complete"] = np.int8(0)
    flagged, total, counts = _flag_counts_through_xarray(path)
    line = next(x for x in cube_summary(path) if x.startswith("flagged"))
    names = str(h5py.File(path, "r")["validity"].attrs["flag_meanings"]).split()
    assert line.startswith(f"flagged   {flagged:,} of {total:,} design values")
    assert line.endswith(", ".join(f"{n} {c:,}" for n, c in zip(names, counts)))
    assert ("INCOMPLETE" in "\n".join(cube_summary(path))) == incomplete


def test_a_cube_that_disagrees_with_the_registry_is_refused_on_open(tmp_path, capsys):
    # issue 28: cubes are validated against the one variable table (variables.validate)
    from helpers import write_cube

    import nylonflex as nf
    from nylonflex.cli import main
    from nylonflex.variables import validate

    raw = {"name": "v", "grid": {"radius": {"values": [10, 12], "units": "mm"},
                                 "wall_thickness": {"values": [2], "units": "mm"},
                                 "length": {"values": [70], "units": "mm"},
                                 "coil_index": {"values": [1.3]},
                                 "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}}}
    cube = write_cube(tmp_path, raw)
    validate(nf.open_cube(cube))  # a sweep's own cube passes
    with h5py.File(cube, "r+") as f:
        f["tip_force_max"].attrs["units"] = "mN"
    with pytest.raises(Exception, match=r"tip_force_max is in 'mN'; the registry's unit is 'N'"):
        nf.open_cube(cube)
    assert main(["query", str(cube), "--limit", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the registry's unit is 'N'" in err[0]
    from nylonflex.config import parse_config

    ds = nf.run_sweep(parse_config(raw))
    with pytest.raises(ValueError, match=r"^cube: \w+ has dimensions \('wall_thickness', "
                                         r"'radius'"):
        validate(ds.transpose("wall_thickness", "radius", ...))
