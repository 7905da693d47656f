"""The decay core: the averaged equations, the universal curves, the time-varying Sun, the direct integration."""
