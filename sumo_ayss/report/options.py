"""The report's options: a configuration section, :mod:`sumo_ayss.config.report`; its names
are re-exported here."""

from __future__ import annotations

from sumo_ayss.config.report import CROSSPLAY_BLOCKS, DEFAULT_MODE, MODES, ReportOptions

__all__ = ["CROSSPLAY_BLOCKS", "DEFAULT_MODE", "MODES", "ReportOptions"]
