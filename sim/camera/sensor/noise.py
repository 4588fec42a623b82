"""Shot and read noise of the pixels, from the datasheet's signal-to-noise figures.

The OV7670's key specifications give a signal-to-noise ratio of 46 dB and a dynamic range of
52 dB. For a pixel limited by shot noise at full well the SNR is ``sqrt(N_full)``, so
``N_full = 10**(46/10)`` = 39811 electrons; the dynamic range is ``N_full / read_noise``, so the
read noise is ``N_full / 10**(52/20)`` = 100 electrons. A pixel that collected the fraction
``q`` of a full well (``q * N_full`` electrons, Poisson) reads, as a fraction of full scale,

    q + sqrt(q / N_full + (read / N_full)**2) * z,      z ~ N(0, 1)

(the Gaussian approximation of the Poisson count, exact in mean and variance), before the
analogue gains, which amplify signal and noise alike.
"""

import functools
import statistics

import numpy as np

__all__ = ["PixelNoise", "noise_sigma", "well_and_read_noise"]


def well_and_read_noise(snr_db, dynamic_range_db):
    """``(full_well_electrons, read_noise_electrons)`` from the datasheet's SNR and range."""
    full = 10 ** (snr_db / 10)
    return full, full / 10 ** (dynamic_range_db / 20)


def noise_sigma(q, full_well, read_noise):
    """Standard deviation (fraction of full scale) of a pixel at signal ``q`` (same unit)."""
    return np.sqrt(np.asarray(q) / full_well + (read_noise / full_well) ** 2)


@functools.lru_cache(maxsize=1)
def _normal_quantiles():
    """65536 equally likely quantiles of N(0, 1), float32 (|z| < 4.4)."""
    inv_cdf = statistics.NormalDist().inv_cdf
    return np.array([inv_cdf((i + 0.5) / 65536) for i in range(65536)], dtype=np.float32)


class PixelNoise:
    """Adds shot and read noise to a mosaic in place, drawing from a numpy ``Generator``.

    Normal deviates come from 16 raw random bits each, picking one of 65536 equally likely
    quantiles of N(0, 1) (exact to 1/65536 in probability, tails beyond 4.3 sigma cut), which is
    several times faster than ``standard_normal``; the same generator state gives the same noise.
    """

    def __init__(self, shape, snr_db, dynamic_range_db, rng):
        if not isinstance(rng, np.random.Generator):
            raise TypeError(
                "the sensor's noise needs rng=numpy.random.Generator "
                "(e.g. np.random.default_rng(seed))"
            )
        self.full_well, self.read_noise = well_and_read_noise(snr_db, dynamic_range_db)
        self.rng = rng
        self._table = _normal_quantiles()
        n = int(np.prod(shape))
        self._words = -(-n // 4)  # 64-bit raw words, four deviates each
        self._n = n
        self._z = np.empty(shape, dtype=np.float32)
        self._sigma = np.empty(shape, dtype=np.float32)

    def add(self, q):
        """``q`` (float32, fraction of full scale, clipped at 0 first) plus its noise, in place."""
        np.maximum(q, 0, out=q)
        idx = self.rng.bit_generator.random_raw(self._words).view(np.uint16)[: self._n]
        self._table.take(idx.reshape(q.shape), out=self._z)
        s = self._sigma
        np.multiply(q, np.float32(1 / self.full_well), out=s)
        s += np.float32((self.read_noise / self.full_well) ** 2)
        np.sqrt(s, out=s)
        s *= self._z
        q += s
        return q
