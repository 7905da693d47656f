"""The density multiplier's own special functions and differences against scipy's and numpy's."""

import numpy as np
from scipy.special import i0e, i1e

from orbit_env.decay.density_multiplier import BESSEL_SERIES_X, RATIO_GRID_M, scaled_bessel_i0_i1, uniform_gradient


def test_scaled_bessel_functions_equal_scipys() -> None:
    # Across both methods and their seam (the quadrature below BESSEL_SERIES_X, the series above), from circular
    # orbits (x = 0) to x = 1e5 (a e / H of a GTO over a 10 km scale height is ~ 1e3). Tolerance 4e-15 relative to
    # e^-x I0, the size of the orbit average the two enter (I1 is multiplied by 2e < 2 and added to I0): a few
    # roundings of float64 (scipy's own Chebyshev sums are good to ~1e-16).
    x = np.concatenate(
        [
            [0.0, BESSEL_SERIES_X * (1 - 1e-12), BESSEL_SERIES_X, BESSEL_SERIES_X * (1 + 1e-12)],
            np.linspace(0.0, 200.0, 20001),
            np.geomspace(1e-9, 1e5, 2000),
        ]
    )
    i0, i1 = scaled_bessel_i0_i1(x)
    reference0, reference1 = i0e(x), i1e(x)
    assert np.max(np.abs(i0 - reference0) / reference0) < 4e-15
    assert np.max(np.abs(i1 - reference1) / reference0) < 4e-15
    assert i0.shape == i1.shape == x.shape


def test_scaled_bessel_functions_keep_the_shape_of_their_argument() -> None:
    x = np.array([[0.5, 40.0], [3.0, 1e4]])
    i0, i1 = scaled_bessel_i0_i1(x)
    assert i0.shape == i1.shape == (2, 2)
    np.testing.assert_allclose(i0, i0e(x), rtol=4e-15)
    circular = scaled_bessel_i0_i1(0.0)  # x = 0: I0 = 1, I1 = 0 (to the rounding of the cosines' sum)
    assert float(circular[0]) == 1.0 and abs(float(circular[1])) < 1e-16


def test_uniform_gradient_is_numpys_bit_for_bit() -> None:
    # The dated decay's ratio slope takes it in place of np.gradient: its results must not move at all.
    rows = np.random.default_rng(3).normal(size=(4, RATIO_GRID_M.size))
    np.testing.assert_array_equal(uniform_gradient(rows, RATIO_GRID_M), np.gradient(rows, RATIO_GRID_M, axis=1))
    np.testing.assert_array_equal(uniform_gradient(rows[0], RATIO_GRID_M), np.gradient(rows[0], RATIO_GRID_M))
