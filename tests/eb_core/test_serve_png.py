"""The wire PNG codec: lossless, standard (Pillow reads it), and the fallback for other PNGs."""

import io

import numpy as np
import pytest
from PIL import Image

from eb_core.serve.png import decode_png, encode_png


@pytest.mark.parametrize("shape", [(7, 5, 3), (64, 48, 3), (1, 1, 3)])
def test_round_trip_is_lossless_and_standard(shape):
    rng = np.random.default_rng(sum(shape))
    im = rng.integers(0, 256, size=shape, dtype=np.uint8)
    im[:, : shape[1] // 2] = 200  # flat regions and noise, wrap-around in the Sub filter
    data = encode_png(im)
    assert np.array_equal(decode_png(data), im)
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(data)).convert("RGB")), im)


def test_other_pngs_decode_through_pillow():
    im = np.random.default_rng(0).integers(0, 256, size=(9, 11, 3), dtype=np.uint8)
    buf = io.BytesIO()
    Image.fromarray(im).save(buf, format="PNG", compress_level=6)
    assert np.array_equal(decode_png(buf.getvalue()), im)
    grey = encode_png(im[:, :, 0])
    assert np.array_equal(decode_png(grey)[:, :, 0], im[:, :, 0])
    with pytest.raises(ValueError, match="needs an"):
        encode_png(np.zeros((2, 2, 5), np.uint8))
