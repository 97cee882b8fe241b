"""The cube writer's own chunk filters against HDF5's (storage by round trip)."""

import h5py
import numpy as np
import pytest

from nylonflex.storage.cube import _shuffle_deflate


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
