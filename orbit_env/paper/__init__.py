"""The 1957 paper reproduced: Table II against this package, and Fig. 2."""
