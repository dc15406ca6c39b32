"""The report's section, ``report`` of a pipeline YAML: statistical settings and analysis
modes of a report and a ranking (:class:`ReportOptions`). A configuration section like the
others (no heavy imports); the report and the leaderboard read it from here."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal

from sumo_ayss.util.validation import check_choice, check_int, check_number, require

if TYPE_CHECKING:
    import numpy as np

__all__ = ["CROSSPLAY_BLOCKS", "DEFAULT_MODE", "ReportOptions"]

#: The mode of a report and a ranking unless ``report.mode`` says otherwise (a registered
#: mode's name, :data:`sumo_ayss.modes.DEFAULT_MODE`; the configuration imports no mode).
DEFAULT_MODE = "crossplay"

_MODE_NAME = re.compile(r"[a-z][a-z0-9_]*")


# --------------------------------------------------------------------------- options

CROSSPLAY_BLOCKS = ("seed", "opponent")
"""Block units of cross-play's paired test (:data:`sumo_ayss.analysis.crossplay.BLOCKS`)."""


@dataclass(frozen=True)
class ReportOptions:
    """Statistical settings of a report.

    Attributes:
        h_max_m: AYSS headway range is ``[0, h_max_m]`` m (the paper keeps h <= 5 m).
        bin_width_m: Headway bin width of the indicator-vs-headway figure, m.
        index_bins: Equal-width headway bins of the safety index over ``[0, h_max_m]``.
        level: Confidence level of every interval.
        n_boot: Bootstrap replicates per safety index (the same for every VUT).
        welch_alpha: The seed-level Welch p-value must be below this for significance.
        rng_seed: Root seed of the bootstraps; each (case, VUT) gets its own stream.
        mode: Which ranking mode gives the verdicts and the ranking, one of the registered
            modes (:mod:`sumo_ayss.modes`: ``"crossplay"``, the default, ``"exposure"`` or
            ``"paper"``; checked here to be a name, against the registry by the stages,
            :func:`sumo_ayss.modes.check_mode`). Every mode available is computed and
            shown; cross-play needs the case's ``crossplay.csv``.
        crossplay_blocks: Block unit of cross-play's paired test: ``"seed"`` (default,
            training seeds) or ``"opponent"`` (every opponent SPCP its own block).
        premise_reward: Tolerance on the spread of the VUTs' mean episode reward for the
            premise check ("same overall outcome"), reward per episode.
        premise_crash_rate: Tolerance on the spread of crash rates, fraction.
        premise_final_headway_m: Tolerance on the spread of mean final headways, m.
        r157_time_s: Constant term of UN R157's cut-in condition, TTC > v_rel / (2 · 6 m/s²)
            + this [s]: 0.35 (the regulation as its implementations quote it, default) or
            0.45 (esmini's and JRC-FSM's code, + 0.1 s); the report shows both
            (:mod:`sumo_ayss.analysis.r157`).
    """

    SECTION: ClassVar[str] = "report"

    h_max_m: float = 5.0
    bin_width_m: float = 0.25
    index_bins: int = 10
    level: float = 0.95
    n_boot: int = 2000
    welch_alpha: float = 0.05
    rng_seed: int = 0
    mode: str = DEFAULT_MODE
    crossplay_blocks: Literal["seed", "opponent"] = "seed"
    premise_reward: float = 1.0
    premise_crash_rate: float = 0.02
    premise_final_headway_m: float = 2.0
    r157_time_s: float = 0.35

    def __post_init__(self) -> None:
        s = self.SECTION
        check_number(f"{s}.r157_time_s", self.r157_time_s, low=0.0)
        require(
            isinstance(self.mode, str) and _MODE_NAME.fullmatch(self.mode) is not None,
            f"{s}.mode must be a mode's name (lower-case letters, digits and '_'), "
            f"got {self.mode!r}",
        )
        check_choice(f"{s}.crossplay_blocks", self.crossplay_blocks, list(CROSSPLAY_BLOCKS))
        for name in ("premise_reward", "premise_crash_rate", "premise_final_headway_m"):
            value = getattr(self, name)
            require(
                isinstance(value, int | float) and math.isfinite(value) and value >= 0,
                f"{s}.{name} must be a finite number >= 0, got {value!r}",
            )
        check_number(f"{s}.h_max_m", self.h_max_m, low=0.0, low_open=True)
        require(
            0 < self.bin_width_m <= self.h_max_m,
            f"{s}.bin_width_m must be in (0, h_max_m = {self.h_max_m}], got {self.bin_width_m}",
        )
        check_int(f"{s}.index_bins", self.index_bins, low=1)
        check_int(f"{s}.n_boot", self.n_boot, low=1)
        check_int(f"{s}.rng_seed", self.rng_seed, low=0)
        for name in ("level", "welch_alpha"):
            value = getattr(self, name)
            require(0 < value < 1, f"{s}.{name} must be in (0, 1), got {value!r}")

    @property
    def premise_tolerances(self) -> dict[str, float]:
        """Tolerances of the premise check by metric key."""
        return {
            "mean_return": self.premise_reward,
            "crash_rate": self.premise_crash_rate,
            "mean_final_headway_m": self.premise_final_headway_m,
        }

    @property
    def h_range(self) -> tuple[float, float]:
        """``(0, h_max_m)``."""
        return (0.0, self.h_max_m)

    @property
    def figure_edges(self) -> np.ndarray:
        """Headway bin edges of the indicator figure, m."""
        import numpy as np  # lazily: configuration loads this module

        n = max(1, round(self.h_max_m / self.bin_width_m))
        return np.linspace(0.0, self.h_max_m, n + 1)
