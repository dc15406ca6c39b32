"""Running policies on scenario sets: candidate evaluation, outcome tables, Monte Carlo AYSS."""
