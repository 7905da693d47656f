"""Physics below the decay: orbit geometry, atmospheres, free-molecular drag, oblateness (SI units, pure functions)."""
