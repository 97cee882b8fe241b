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
