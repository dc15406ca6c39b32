"""The report's sections, each composed from an analysis into :mod:`..blocks`."""
